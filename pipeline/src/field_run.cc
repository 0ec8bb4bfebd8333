#include "imufit/pipeline/field_run.h"

#include <algorithm>

#include "imufit/io/log_samples.h"
#include "imufit/io/run_header.h"
#include "imufit/io/sha256.h"
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
  return field;
}

}  // namespace

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
                           const std::string& serial, bool allow_serial_mismatch) {
  FieldRunResult result;
  Sha256 digest;
  LogSamples log = ReadLogSamples(samples_path, LogOptions{input.Format(), input.ulog_instance}, &digest);
  std::vector<Sample>& samples = log.samples;
  result.samples_read = static_cast<long long>(samples.size());
  result.samples_sha256 = digest.HexDigest();
  result.read_notes = log.notes;
  const UnitSerial unit =
      ResolveSerial({SerialSource{SerialSource::Kind::kStated, "--serial", serial, "", 0, 0},
                     SamplesHeaderSerial(samples_path, log.serial)},
                    allow_serial_mismatch);
  result.serial = unit.serial;
  result.serial_warnings = unit.warnings;
  result.fit = FitField(samples, options);
  if (!result.fit.IsSolutionUsable()) return result;
  Calibration calibration = FieldCalibration(result.fit, options);
  calibration.serial = result.serial;
  calibration.software = software;
  FitRecord& record = *calibration.fit;
  record.samples = samples_path;
  record.samples_sha256 = result.samples_sha256;
  record.samples_read = result.samples_read;
  const RunHeader header = RunHeaderOf(samples_path, log.header_comments);
  for (const auto& [value, key] : {std::pair{&header.acquired_utc, &record.acquired_utc},
                                   {&header.model, &record.unit_model},
                                   {&header.firmware, &record.unit_firmware},
                                   {&header.ambient, &record.ambient}}) {
    if (!value->empty()) *key = *value;
  }
  result.calibration = std::move(calibration);
  return result;
}

}  // namespace imufit
