#include "imufit/pipeline/fit_run.h"

#include <set>
#include <sstream>

#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/unit_serial.h"

namespace imufit {
namespace {

// The calibration's `fit:` block (io/fit_record.h), without the files' hashes.
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
  record.gyro_temp_order = options.gyro_temp_order;
  record.accel_temp_order = options.accel_temp_order;
  record.g_sensitivity_fitted = options.Fits(true, kGSensitivityCoefficient);
  // What the fit estimated; the held groups keep their stated values (a prior calibration's, or
  // scale 1 and 0 otherwise) and a sigma of 0.
  record.fitted = options.Groups(true);
  record.held = options.Groups(false);
  if (!record.held->empty()) record.held_values = options.held ? "prior" : "scale 1, others 0";
  record.loss = RobustLossName(options.loss);
  record.gyro_bias_stability_radps = options.gyro_bias_stability_radps;
  record.accel_bias_stability_mps2 = options.accel_bias_stability_mps2;
  record.bias_correlation_s = options.bias_correlation_s;
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

// The unit's serial: the most specific source first (the caller's, the unit's own log, then the
// possibly shared plan).
UnitSerial ResolveUnitSerial(const FitRunOptions& options, const std::string& plan_path, const Plan& plan,
                             const SamplesReader& samples) {
  SerialSource stated;
  stated.kind = SerialSource::Kind::kStated;
  stated.name = options.serial_source;
  stated.serial = options.serial;
  SerialSource planned;
  planned.name = "the plan " + plan_path;
  planned.serial = plan.serial;
  return ResolveSerial({stated, SamplesHeaderSerial(samples), planned}, options.allow_serial_mismatch);
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

}  // namespace

std::string FitRunOptions::Validate() const {
  if (std::string problem = fit.Validate(); !problem.empty()) return problem;
  if (std::string problem = windows.Validate(); !problem.empty()) return problem;
  if (std::string problem = input.Validate(); !problem.empty()) return problem;
  if (check_samples.empty() && !check_plan.empty()) return "a check plan needs check samples";
  return "";
}

std::string FitRunOptions::Describe() const {
  std::ostringstream text;
  const auto add = [&text](const char* key, const std::string& value) {
    text << (text.tellp() > 0 ? "; " : "") << key << "=" << value;
  };
  const auto number = [](double value) { return FormatDouble(value); };
  std::string fitted;
  for (const std::string& group : fit.Groups(true)) fitted += (fitted.empty() ? "" : ",") + group;
  add("fitted", fitted);
  if (!fit.Groups(false).empty()) {
    std::string held = "nominal";
    if (fit.held) {
      std::string values = number(fit.held->basis.center_c) + " " + number(fit.held->basis.half_range_c);
      for (double value : fit.held->gyro) values += " " + number(value);
      for (double value : fit.held->accel) values += " " + number(value);
      held = "prior " + Sha256Hex(values);
    }
    add("held", held);
  }
  add("gyro_temp_order", std::to_string(fit.gyro_temp_order));
  add("accel_temp_order", std::to_string(fit.accel_temp_order));
  add("loss", RobustLossName(fit.loss));
  add("loss_scale", number(fit.loss_scale));
  add("gyro_bias_stability_radps", number(fit.gyro_bias_stability_radps));
  add("accel_bias_stability_mps2", number(fit.accel_bias_stability_mps2));
  add("bias_correlation_s", number(fit.bias_correlation_s));
  add("max_iterations", std::to_string(fit.max_iterations));
  add("closed_form_start", fit.closed_form_start ? "true" : "false");
  add("distinct_temp_c", number(fit.distinct_temp_c));
  add("min_excitation_rate_radps", number(fit.min_excitation_rate_radps));
  add("rank_tolerance", number(fit.rank_tolerance));
  add("trim_s", number(windows.trim_s));
  add("window_temp_span_c", number(windows.max_temp_span_c));
  add("window_max_duration_s", number(windows.max_duration_s));
  add("window_min_samples", std::to_string(windows.min_samples));
  add("max_turn_gap_s", number(windows.max_turn_gap_s));
  add("gyro_full_scale_raw", number(windows.gyro_full_scale_raw));
  add("accel_full_scale_raw", number(windows.accel_full_scale_raw));
  add("temp_c", input.temp_c ? number(*input.temp_c) : "column");
  const SegmentationOptions& segmentation = input.segmentation;
  add("segment_window_s", number(segmentation.window_s));
  add("segment_noise_quantile", number(segmentation.noise_quantile));
  add("segment_threshold_factor", number(segmentation.threshold_factor));
  add("min_steady_s", number(segmentation.min_steady_s));
  add("direction_tolerance_deg", number(segmentation.direction_tolerance_deg));
  add("rate_tolerance", number(segmentation.rate_tolerance));
  add("turn_margin_s", number(segmentation.turn_margin_s));
  add("validate", validate ? "true" : "false");
  if (!check_samples.empty()) add("check", check_samples + " " + check_plan);
  add("allow_serial_mismatch", allow_serial_mismatch ? "true" : "false");
  return text.str();
}

FitRunResult FitRun(const std::string& plan_path, const std::string& samples_path,
                    const FitRunOptions& options) {
  FitRunResult result;
  result.plan = ReadPlan(plan_path);
  result.plan_sha256 = options.plan_sha256.empty() ? Sha256OfFile(plan_path) : options.plan_sha256;
  RunReader samples(result.plan, samples_path, options.input);
  UnitSerial serial = ResolveUnitSerial(options, plan_path, result.plan, samples.header());
  result.serial = std::move(serial.serial);
  result.serial_warnings = std::move(serial.warnings);
  result.run = samples.Read(options.windows, options.keep_static_stretch);
  // A held-out run is read before fitting, so that a bad file is reported before any work.
  Plan check_plan;
  std::vector<Window> check_windows;
  if (!options.check_samples.empty()) {
    check_plan = ReadPlan(options.check_plan.empty() ? plan_path : options.check_plan);
    check_windows = ReadRunWindows(check_plan, options.check_samples, options.windows, options.input).windows;
  }

  result.fit = FitThermalModel(result.run.windows, result.plan.site, result.plan.segments, options.fit);
  result.record = RecordOf(result, plan_path, samples_path, options.fit);
  if (!result.fit.IsSolutionUsable()) return result;
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

}  // namespace imufit
