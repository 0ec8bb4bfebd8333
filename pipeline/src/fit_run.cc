#include "imufit/pipeline/fit_run.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <set>

#include "imufit/base/text.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/consistency.h"
#include "imufit/pipeline/unit_serial.h"
#include "imufit/run/channel_check.h"
#include "imufit/run/label_check.h"

namespace imufit {
namespace {

// The calibration's `fit:` block (io/fit_record.h), without the files' hashes.
// ---------------------------------------------------------------- the fit options of the record

// The FitOptions members a calibration's `fit:` record states, each described once: how RecordOf()
// writes it and how FitOptionsOfRecord() reads it back (nullptr: written only, see there).
struct RecordedOption {
  const char* key;  // the record's member (fit_record.h)
  void (*write)(const FitOptions& options, FitRecord* record);
  void (*read)(const FitRecord& record, FitOptions* options);
};

// The groups the record names as fitted, as the sensors' SensorFit and the g-sensitivity: the one
// combination whose Groups(true) they are. Throws InputError for any other set of names.
void ReadFittedGroups(const FitRecord& record, FitOptions* options) {
  if (!record.fitted) return;
  std::vector<std::string> named = *record.fitted;
  std::sort(named.begin(), named.end());
  for (const SensorFit gyro : {SensorFit::kAll, SensorFit::kBias, SensorFit::kNone}) {
    for (const SensorFit accel : {SensorFit::kAll, SensorFit::kBias, SensorFit::kNone}) {
      for (const bool g_sensitivity : {true, false}) {
        FitOptions candidate = *options;
        candidate.gyro_fit = gyro;
        candidate.accel_fit = accel;
        if (gyro == SensorFit::kAll) candidate.fit_g_sensitivity = g_sensitivity;
        std::vector<std::string> groups = candidate.Groups(true);
        std::sort(groups.begin(), groups.end());
        if (groups != named) continue;
        *options = candidate;
        return;
      }
    }
  }
  throw InputError("fit.fitted",
                   "[" + Join(*record.fitted, ", ") +
                       "] is not a set of groups a fit estimates (what imufit fit --fit names)");
}

const RecordedOption kRecordedOptions[] = {
    {"gyro_temp_order", [](const FitOptions& o, FitRecord* r) { r->gyro_temp_order = o.gyro_temp_order; },
     [](const FitRecord& r, FitOptions* o) {
       o->gyro_temp_order = r.gyro_temp_order.value_or(o->gyro_temp_order);
     }},
    {"accel_temp_order", [](const FitOptions& o, FitRecord* r) { r->accel_temp_order = o.accel_temp_order; },
     [](const FitRecord& r, FitOptions* o) {
       o->accel_temp_order = r.accel_temp_order.value_or(o->accel_temp_order);
     }},
    {"g_sensitivity_fitted",
     [](const FitOptions& o, FitRecord* r) {
       r->g_sensitivity_fitted = o.Fits(true, kGSensitivityCoefficient);
     },
     [](const FitRecord& r, FitOptions* o) { o->fit_g_sensitivity = r.g_sensitivity_fitted.value_or(true); }},
    // What the fit estimated; the held groups keep their stated values (a prior calibration's, or
    // scale 1 and 0 otherwise) and a sigma of 0.
    {"fitted",
     [](const FitOptions& o, FitRecord* r) {
       r->fitted = o.Groups(true);
       r->held = o.Groups(false);
       if (!r->held->empty()) r->held_values = o.held ? "prior" : "scale 1, others 0";
     },
     ReadFittedGroups},
    {"loss", [](const FitOptions& o, FitRecord* r) { r->loss = RobustLossName(o.loss); },
     [](const FitRecord& r, FitOptions* o) {
       std::string error;
       if (r.loss && !ParseRobustLoss(*r.loss, &o->loss, &error)) throw InputError("fit.loss", error);
     }},
    // Written only: the fit a record describes weights white noise alone (FitOptionsOfRecord).
    {"gyro_bias_stability_radps",
     [](const FitOptions& o, FitRecord* r) { r->gyro_bias_stability_radps = o.gyro_bias_stability_radps; },
     nullptr},
    {"accel_bias_stability_mps2",
     [](const FitOptions& o, FitRecord* r) { r->accel_bias_stability_mps2 = o.accel_bias_stability_mps2; },
     nullptr},
    {"bias_correlation_s",
     [](const FitOptions& o, FitRecord* r) { r->bias_correlation_s = o.bias_correlation_s; }, nullptr},
};

FitRecord RecordOf(const FitRunResult& result, const std::string& plan_path, const std::string& samples_path,
                   const FitOptions& options) {
  const FitSummary& fit = result.fit;
  FitRecord record;
  record.plan = plan_path;
  record.samples = samples_path;
  record.samples_read = result.run.stats.samples;
  if (result.run.segmentation) {
    record.segments_found_in_data = static_cast<int>(result.run.segmentation->matches.size());
    record.plan_passes_found = result.run.segmentation->passes;
  }
  record.windows_used = fit.windows_used;
  record.windows_downweighted = fit.windows_downweighted;
  record.distinct_temperatures_c = fit.distinct_temps_c;
  record.iterations = fit.iterations;
  record.termination = fit.termination;
  record.gyro_residual_rms_radps = fit.gyro_rms_radps;
  record.accel_residual_rms_mps2 = fit.accel_rms_mps2;
  record.gyro_reduced_chi2 = fit.gyro_reduced_chi2;
  record.accel_reduced_chi2 = fit.accel_reduced_chi2;
  for (const RecordedOption& option : kRecordedOptions) option.write(options, &record);
  // Plan segments without a single usable window (never visited, or every visit too short).
  std::set<int> visited;
  for (const Window& w : result.run.windows) visited.insert(w.segment);
  record.segments_without_windows.emplace();
  for (const TableSegment& segment : result.plan.segments) {
    if (visited.count(segment.id) == 0) record.segments_without_windows->push_back(segment.id);
  }
  record.missing_segments = static_cast<int>(record.segments_without_windows->size());
  return record;
}

// What the samples header says of the run, apart from the fit's own time (calibration created_utc).
void RecordRunHeader(const RunHeader& header, FitRecord* record) {
  const auto set = [](const std::string& value, std::optional<std::string>* key) {
    if (!value.empty()) *key = value;
  };
  set(header.acquired_utc, &record->acquired_utc);
  set(header.model, &record->unit_model);
  set(header.firmware, &record->unit_firmware);
  set(header.ambient, &record->ambient);
}

// The unit's serial: the most specific source first (the caller's, the unit's own log, then the
// possibly shared plan).
UnitSerial ResolveUnitSerial(const FitRunOptions& options, const std::string& plan_path, const Plan& plan,
                             const RunReader& samples) {
  SerialSource stated;
  stated.kind = SerialSource::Kind::kStated;
  stated.name = options.serial_source;
  stated.serial = options.serial;
  SerialSource planned;
  planned.name = "the plan " + plan_path;
  planned.serial = plan.serial;
  return ResolveSerial({stated, SamplesHeaderSerial(samples.name(), samples.located_serial()), planned},
                       options.allow_serial_mismatch);
}

// The calibration of a usable fit, with its `fit:` record.
Calibration MakeCalibration(const FitRunResult& result, const FitRunOptions& options) {
  Calibration calibration;
  calibration.serial = result.serial;
  calibration.created_utc = UtcNow();
  calibration.software = options.software;
  calibration.fit_temp_range_c = result.fit.temp_range_c;
  calibration.model = result.fit.model;
  calibration.sigma = result.fit.sigma;
  calibration.fit = result.record;
  return calibration;
}

// Before any work: the controller's labels against the plan (an unlabelled log was matched to it
// while it was labelled), then every raw channel live (a dead or railed channel does not upset the
// label check: a zero or constant row of K fits it; mislabelled windows would upset this one).
// Throws PlanMismatchError.
void CheckBeforeFit(const std::string& plan_path, const std::string& samples_path,
                    const FitRunOptions& options, const FitRunResult& result) {
  if (!result.run.segmentation) {
    const std::string disagreement = CheckLabels(result.run.windows, result.plan.site, result.plan.segments,
                                                 options.fit.gyro_temp_order, options.fit.accel_temp_order);
    if (!disagreement.empty()) {
      throw PlanMismatchError(samples_path + ": the labelled log does not match the plan " + plan_path +
                              ": " + disagreement);
    }
  }
  const std::string dead = CheckChannels(result.run.windows, result.run.stats, result.plan.site,
                                         result.plan.segments, options.windows);
  if (!dead.empty()) throw PlanMismatchError(samples_path + ": " + dead);
}

// The fit of `plan` (named by its path) and the samples `open` opens for it.
FitRunResult FitRunOf(Plan plan, std::string plan_sha256,
                      const std::function<std::unique_ptr<RunReader>(const Plan&)>& open,
                      const FitRunOptions& options) {
  FitRunResult result;
  result.plan = std::move(plan);
  result.plan_sha256 = std::move(plan_sha256);
  const std::string plan_path = result.plan.path;
  const std::unique_ptr<RunReader> samples = open(result.plan);
  const std::string samples_path = samples->name();
  UnitSerial serial = ResolveUnitSerial(options, plan_path, result.plan, *samples);
  result.serial = std::move(serial.serial);
  result.serial_warnings = std::move(serial.warnings);
  const RunHeader header = samples->run_header();
  result.run = samples->Read(options.windows, options.keep_static_stretch
                                                  ? std::optional<NoiseStretchOptions>(options.noise_stretch)
                                                  : std::nullopt);
  CheckBeforeFit(plan_path, samples_path, options, result);
  // A held-out run is read before fitting, so that a bad file is reported before any work.
  Plan check_plan;
  std::vector<Window> check_windows;
  if (!options.check_samples.empty()) {
    check_plan = options.check_plan.empty() ? result.plan : ReadPlan(options.check_plan);
    check_windows = ReadRunWindows(check_plan, options.check_samples, options.windows, options.input).windows;
  }

  result.fit = FitThermalModel(result.run.windows, result.plan.site, result.plan.segments, options.fit);
  result.record = RecordOf(result, plan_path, samples_path, options.fit);
  RecordRunHeader(header, &result.record);
  if (const std::vector<int>& missing = *result.record.segments_without_windows; !missing.empty()) {
    std::string ids;
    for (const int id : missing) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
    result.run_warnings.push_back(
        samples_path + ": plan " + (missing.size() == 1 ? "segment " : "segments ") + ids + " of " +
        plan_path + (missing.size() == 1 ? " has" : " have") +
        " no usable window in the log (never visited, or every visit too short): fitted without " +
        (missing.size() == 1 ? "it" : "them"));
  }
  if (!result.fit.IsSolutionUsable()) return result;
  result.inconsistency = Inconsistency(result.fit, result.run.windows, options.fit);
  if (!result.inconsistency.empty()) {
    if (!options.write_inconsistent) {
      throw PlanMismatchError(samples_path + ": the fit is inconsistent with the run's noise: " +
                              result.inconsistency + " (--write-inconsistent writes it anyway, marked)");
    }
    result.record.inconsistent = result.inconsistency;
  }
  result.record.plan_sha256 = result.plan_sha256;
  result.record.samples_sha256 = result.run.samples_sha256;
  Calibration calibration = MakeCalibration(result, options);
  if (options.validate) {
    result.folds =
        LeaveOneTemperatureOut(result.run.windows, result.plan.site, result.plan.segments, options.fit);
  }
  if (!check_windows.empty()) {
    const std::vector<WindowError> errors =
        PredictWindows(result.fit.model, check_windows, check_plan.site, check_plan.segments);
    result.check_errors = ErrorsBySegment(errors);
    result.check_errors.push_back(SummariseErrors(errors));
    CheckRecord check;
    check.samples = options.check_samples;
    check.gyro_error_rms_radps = result.check_errors.back().gyro_rms_radps;
    check.accel_error_rms_mps2 = result.check_errors.back().accel_rms_mps2;
    calibration.check = check;
  }
  result.calibration = std::move(calibration);
  return result;
}

}  // namespace

FitRunResult FitRun(const std::string& plan_path, const std::string& samples_path,
                    const FitRunOptions& options) {
  return FitRun(ReadPlan(plan_path),
                options.plan_sha256.empty() ? Sha256OfFile(plan_path) : options.plan_sha256, samples_path,
                options);
}

FitRunResult FitRun(Plan plan, std::string plan_sha256, const std::string& samples_path,
                    const FitRunOptions& options) {
  return FitRunOf(
      std::move(plan), std::move(plan_sha256),
      [&](const Plan& read) { return std::make_unique<RunReader>(read, samples_path, options.input); },
      options);
}

FitRunResult FitRun(Plan plan, std::string plan_sha256, const SamplesInMemory& samples,
                    const FitRunOptions& options) {
  return FitRunOf(
      std::move(plan), std::move(plan_sha256),
      [&](const Plan& read) { return std::make_unique<RunReader>(read, samples, options.input); }, options);
}

std::string UndeterminedMessage(const std::string& samples, const FitRunOptions& options,
                                const FitRunResult& result) {
  const FitSummary& fit = result.fit;
  const WindowStats& stats = result.run.stats;
  std::string held = std::to_string(stats.samples) + " samples, " + std::to_string(stats.window_samples) +
                     " of them in the windows, " + std::to_string(fit.windows_used) + " windows used";
  if (const std::string left_out = LeftOutNote(stats, options.windows); !left_out.empty()) {
    held += "; left out: " + left_out;
  }
  if (const std::string note = TimeStampNote(stats); !note.empty()) held += "; time stamps: " + note;
  if (const std::string note = SaturationNote(stats); !note.empty()) held += "; saturation: " + note;
  return samples + ": the run does not determine the model: " + Join(fit.undetermined, "; ") +
         " (the run: " + held + ")";
}

FitOptions FitOptionsOfRecord(const FitRecord& record) {
  FitOptions options;
  for (const RecordedOption& option : kRecordedOptions) {
    if (option.read != nullptr) option.read(record, &options);
  }
  return options;
}

}  // namespace imufit
