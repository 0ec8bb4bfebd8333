#include "imufit/pipeline/field_run.h"

#include <algorithm>
#include <iterator>
#include <limits>

#include "imufit/io/error.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/run_header.h"
#include "imufit/io/sha256.h"
#include "imufit/model/check.h"
#include "imufit/pipeline/unit_serial.h"

namespace imufit {
namespace {

// The session's own figures, the `fit: field:` block.
FieldRecord FieldFigures(const FieldFitSummary& fit, const FieldFitOptions& options) {
  FieldRecord field;
  field.poses = static_cast<int>(fit.poses.size());
  field.turns = static_cast<int>(fit.turns.size());
  field.gravity_mps2 = options.GravityMps2();
  field.accel_norm_rms_mps2 = fit.accel_norm_rms_mps2;
  field.gyro_static_rms_radps = fit.gyro_static_rms_radps;
  field.gravity_direction_rms_rad = fit.direction_rms_rad;
  field.reduced_chi2 = fit.reduced_chi2;
  // The noise of the rests (accelerometer, gyro) and the turns as multiples of the log's white noise.
  field.noise_scale_accel_rests = fit.noise_scale[0];
  field.noise_scale_gyro_rests = fit.noise_scale[1];
  field.noise_scale_turns = fit.noise_scale[2];
  int saturated = 0;
  for (const FieldTurn& turn : fit.turns) saturated += turn.saturated ? 1 : 0;
  field.saturated_turns = saturated;
  // Where gravity came from: the certificate's U includes its uncertainty (factory/field_budget.cc).
  if (options.latitude_deg) {
    field.gravity_source = std::string(kGravityFromLatitude);
    field.latitude_deg = *options.latitude_deg;
    field.height_m = options.height_m;
  } else {
    // The default, 9.80665, is standard gravity whoever typed it (as FieldFitOptions::Validate
    // takes it): the site unknown, its uncertainty the widest (conservative).
    field.gravity_source =
        std::string(options.gravity_mps2 == kStandardGravityMps2 ? kGravityStandard : kGravityStated);
  }
  return field;
}

// Several sessions: each one's file and share, and how its biases compare with the joint fit.
void SessionFigures(const FieldRunResult& result, FieldRecord* field) {
  field->session_samples.emplace();
  field->session_samples_sha256.emplace();
  field->session_samples_read.emplace();
  field->session_poses.emplace();
  field->session_turns.emplace();
  field->session_temp_min_c.emplace();
  field->session_temp_max_c.emplace();
  std::vector<double> gyro_chi2;
  std::vector<double> accel_chi2;
  bool tested = true;
  for (size_t s = 0; s < result.sessions.size(); ++s) {
    const FieldSessionShare& share = result.fit.sessions[s];
    field->session_samples->push_back(result.sessions[s].path);
    field->session_samples_sha256->push_back(result.sessions[s].samples_sha256);
    field->session_samples_read->push_back(static_cast<int>(
        std::min<long long>(result.sessions[s].samples_read, std::numeric_limits<int>::max())));
    field->session_poses->push_back(share.poses);
    field->session_turns->push_back(share.turns);
    field->session_temp_min_c->push_back(share.temp_range_c[0]);
    field->session_temp_max_c->push_back(share.temp_range_c[1]);
    tested = tested && share.gyro_bias.tested && share.accel_bias.tested;
    gyro_chi2.push_back(share.gyro_bias.chi2);
    accel_chi2.push_back(share.accel_bias.chi2);
  }
  field->session_biases_tested = tested;
  if (!tested) return;
  field->session_gyro_bias_chi2 = gyro_chi2;
  field->session_accel_bias_chi2 = accel_chi2;
}

}  // namespace

bool AppliesToAFieldFit(const std::string& key) {
  static const char* const kKeys[] = {"temp_c",
                                      "time_unit",
                                      "delimiter",
                                      "decimal_comma",
                                      "column",
                                      "allow_serial_mismatch",
                                      "fit_g_sensitivity",
                                      "segment_window_s",
                                      "segment_noise_quantile",
                                      "segment_threshold_factor",
                                      "min_steady_s"};
  return std::find(std::begin(kKeys), std::end(kKeys), key) != std::end(kKeys);
}

Calibration FieldCalibration(const FieldFitSummary& fit, const FieldFitOptions& options) {
  Calibration calibration;
  calibration.created_utc = UtcNow();
  calibration.fit_temp_range_c = fit.temp_range_c;
  calibration.model = fit.model;
  calibration.sigma = fit.sigma;
  FitRecord record;
  record.iterations = fit.iterations;
  record.termination = fit.termination;
  record.gyro_residual_rms_radps = fit.gyro_static_rms_radps;
  record.accel_residual_rms_mps2 = fit.accel_norm_rms_mps2;
  record.gyro_temp_order = std::max(options.bias_temp_order, options.scale_temp_order);
  record.accel_temp_order = record.gyro_temp_order;
  record.g_sensitivity_fitted = options.fit_g_sensitivity;
  record.fitted = std::vector<std::string>{"gyro.bias",  "gyro.scale",  "gyro.misalignment",
                                           "accel.bias", "accel.scale", "accel.misalignment"};
  if (options.fit_g_sensitivity) record.fitted->insert(record.fitted->begin() + 3, "gyro.g_sensitivity");
  record.held = std::vector<std::string>{};
  if (!options.fit_g_sensitivity) {
    record.held->push_back("gyro.g_sensitivity");
    record.held_values = "scale 1, others 0";
  }
  record.field = FieldFigures(fit, options);
  calibration.fit = record;
  calibration.body_frame = kBodyFrameAccelerometerXy;
  return calibration;
}

FieldRunResult FieldFitRun(const std::string& samples_path, const SamplesInput& input,
                           const FieldFitOptions& options, const std::string& software,
                           const std::string& serial, bool allow_serial_mismatch, const LogTopics& topics) {
  return FieldFitSessionsRun({samples_path}, {input}, options, software, serial, allow_serial_mismatch,
                             topics);
}

FieldRunResult FieldFitSessionsRun(const std::vector<std::string>& samples_paths,
                                   const std::vector<SamplesInput>& inputs, const FieldFitOptions& options,
                                   const std::string& software, const std::string& serial,
                                   bool allow_serial_mismatch, const LogTopics& topics) {
  IMUFIT_CHECK(!samples_paths.empty() && inputs.size() == samples_paths.size(), "an input for every session");
  FieldRunResult result;
  std::vector<std::vector<Sample>> sessions(samples_paths.size());
  std::vector<SerialSource> serials = {
      SerialSource{SerialSource::Kind::kStated, "--serial", serial, "", 0, 0}};
  RunHeader header;  // the first session's, as far as it goes for all
  for (size_t s = 0; s < samples_paths.size(); ++s) {
    Sha256 digest;
    LogSamples log = ReadLogSamples(
        samples_paths[s], {inputs[s].Format(), topics.topic, topics.temp_topic, inputs[s].ulog_instance},
        &digest);
    sessions[s] = std::move(log.samples);
    result.read_notes.insert(result.read_notes.end(), log.notes.begin(), log.notes.end());
    if (s == 0) {
      result.format = log.format;
      result.topic = log.topic;
      result.temp_topic = log.temp_topic;
      header = RunHeaderOf(samples_paths[s], log.header_comments);
    }
    result.sessions.push_back(
        {samples_paths[s], static_cast<long long>(sessions[s].size()), digest.HexDigest()});
    result.samples_read += result.sessions.back().samples_read;
    const SerialSource source = SamplesHeaderSerial(samples_paths[s], log.serial);
    for (const SerialSource& other : serials) {  // two headers naming two units
      if (other.kind != SerialSource::Kind::kHeader || other.serial.empty() || source.serial.empty() ||
          other.serial == source.serial || allow_serial_mismatch) {
        continue;
      }
      throw InputError(
          source.file, source.line, source.column,
          "serial " + QuoteForMessage(source.serial) + ", but " + other.name + " names " +
              QuoteForMessage(other.serial) +
              ": the sessions of a joint fit are of one unit (--allow-mismatch fits them anyway)");
    }
    serials.push_back(source);
  }
  result.samples_sha256 = result.sessions.front().samples_sha256;
  const UnitSerial unit = ResolveSerial(serials, allow_serial_mismatch);
  result.serial = unit.serial;
  result.serial_warnings = unit.warnings;
  const bool several = sessions.size() > 1;
  result.fit =
      several ? FitFieldSessions(sessions, options, samples_paths) : FitField(sessions.front(), options);
  if (!result.fit.IsSolutionUsable()) return result;
  Calibration calibration = FieldCalibration(result.fit, options);
  calibration.serial = result.serial;
  calibration.software = software;
  FitRecord& record = *calibration.fit;
  record.samples_read = result.samples_read;
  if (several) {
    SessionFigures(result, &*record.field);
  } else {
    record.samples = samples_paths.front();
    record.samples_sha256 = result.samples_sha256;
  }
  // Per session when several: what one file's header says of its run, the unit's only from the first.
  for (const auto& [value, key] : {std::pair{&header.acquired_utc, &record.acquired_utc},
                                   {&header.model, &record.unit_model},
                                   {&header.firmware, &record.unit_firmware},
                                   {&header.ambient, &record.ambient}}) {
    const bool of_the_run = key == &record.acquired_utc || key == &record.ambient;
    if (!value->empty() && !(several && of_the_run)) *key = *value;
  }
  result.calibration = std::move(calibration);
  return result;
}

}  // namespace imufit
