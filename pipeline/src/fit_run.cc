#include "imufit/pipeline/fit_run.h"

#include <set>

#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/unit_serial.h"

namespace imufit {
namespace {

YAML::Node Diagnostics(const FitRunResult& result, const std::string& plan_path,
                       const std::string& samples_path, const std::string& plan_sha256,
                       const std::string& samples_sha256, const FitOptions& options) {
  const FitSummary& fit = result.fit;
  YAML::Node node;
  node["plan"] = plan_path;
  node["samples"] = samples_path;
  node["plan_sha256"] = plan_sha256;
  node["samples_sha256"] = samples_sha256;
  node["samples_read"] = result.run.stats.samples;
  if (result.run.segmentation) {
    node["segments_found_in_data"] = static_cast<int>(result.run.segmentation->matches.size());
    node["plan_passes_found"] = result.run.segmentation->passes;
  }
  node["windows_used"] = fit.windows_used;
  node["windows_downweighted"] = fit.windows_downweighted;
  node["distinct_temperatures_c"] = fit.distinct_temps_c;
  node["iterations"] = fit.iterations;
  node["termination"] = fit.termination;
  node["gyro_residual_rms_radps"] = fit.gyro_rms_radps;
  node["accel_residual_rms_mps2"] = fit.accel_rms_mps2;
  node["gyro_reduced_chi2"] = fit.gyro_reduced_chi2;
  node["accel_reduced_chi2"] = fit.accel_reduced_chi2;
  node["gyro_temp_order"] = options.gyro_temp_order;
  node["accel_temp_order"] = options.accel_temp_order;
  node["g_sensitivity_fitted"] = options.Fits(true, kGSensitivityCoefficient);
  // What the fit estimated; the held groups keep their stated values (a prior calibration's, or
  // scale 1 and 0 otherwise) and a sigma of 0.
  for (const bool fitted : {true, false}) {
    const char* key = fitted ? "fitted" : "held";
    node[key] = YAML::Node(YAML::NodeType::Sequence);
    for (const std::string& group : options.Groups(fitted)) node[key].push_back(group);
    node[key].SetStyle(YAML::EmitterStyle::Flow);
  }
  if (!options.Groups(false).empty()) node["held_values"] = options.held ? "prior" : "scale 1, others 0";
  node["loss"] = RobustLossName(options.loss);
  node["gyro_bias_stability_radps"] = options.gyro_bias_stability_radps;
  node["accel_bias_stability_mps2"] = options.accel_bias_stability_mps2;
  node["bias_correlation_s"] = options.bias_correlation_s;
  // Plan segments without a single usable window (never visited, or every visit too short).
  std::set<int> visited;
  for (const Window& w : result.run.windows) visited.insert(w.segment);
  YAML::Node missing(YAML::NodeType::Sequence);
  for (const TableSegment& segment : result.plan.segments) {
    if (visited.count(segment.id) == 0) missing.push_back(segment.id);
  }
  node["segments_without_windows"] = missing;
  node["segments_without_windows"].SetStyle(YAML::EmitterStyle::Flow);
  node["missing_segments"] = static_cast<int>(missing.size());
  return node;
}

}  // namespace

FitRunResult FitRun(const std::string& plan_path, const std::string& samples_path,
                    const FitRunOptions& options) {
  FitRunResult result;
  result.plan = ReadPlan(plan_path);
  // The most specific source first: the caller's, the unit's own log, then the (possibly shared) plan.
  SerialSource stated;
  stated.kind = SerialSource::Kind::kStated;
  stated.name = options.serial_source;
  stated.serial = options.serial;
  SerialSource plan;
  plan.name = "the plan " + plan_path;
  plan.serial = result.plan.serial;
  UnitSerial serial =
      ResolveSerial({stated, SamplesHeaderSerial(samples_path), plan}, options.allow_serial_mismatch);
  result.serial = std::move(serial.serial);
  result.serial_warnings = std::move(serial.warnings);
  result.run = ReadRunWindows(result.plan, samples_path, options.windows, options.input);
  // A held-out run is read before fitting, so that a bad file is reported before any work.
  std::vector<Window> check_windows;
  Plan check_plan;
  if (!options.check_samples.empty()) {
    check_plan = ReadPlan(options.check_plan.empty() ? plan_path : options.check_plan);
    check_windows = ReadRunWindows(check_plan, options.check_samples, options.windows, options.input).windows;
  }

  result.fit = FitThermalModel(result.run.windows, result.plan.site, result.plan.segments, options.fit);
  if (!result.fit.IsSolutionUsable()) return result;

  Calibration calibration;
  calibration.serial = result.serial;
  calibration.created_utc = UtcNow();
  calibration.software = options.software;
  calibration.fit_temp_range_c = result.fit.temp_range_c;
  calibration.model = result.fit.model;
  calibration.sigma = result.fit.sigma;
  calibration.extra = YAML::Node(YAML::NodeType::Map);
  calibration.extra["fit"] = Diagnostics(
      result, plan_path, samples_path,
      options.plan_sha256.empty() ? Sha256OfFile(plan_path) : options.plan_sha256,
      options.samples_sha256.empty() ? Sha256OfFile(samples_path) : options.samples_sha256, options.fit);

  if (options.validate) {
    result.folds =
        LeaveOneTemperatureOut(result.run.windows, result.plan.site, result.plan.segments, options.fit);
  }
  if (!check_windows.empty()) {
    const std::vector<WindowError> errors =
        PredictWindows(result.fit.model, check_windows, check_plan.site, check_plan.segments);
    result.check_errors = ErrorsBySegment(errors);
    result.check_errors.push_back(SummariseErrors(errors));
    calibration.extra["check"]["samples"] = options.check_samples;
    calibration.extra["check"]["gyro_error_rms_radps"] = result.check_errors.back().gyro_rms_radps;
    calibration.extra["check"]["accel_error_rms_mps2"] = result.check_errors.back().accel_rms_mps2;
  }
  result.calibration = std::move(calibration);
  return result;
}

}  // namespace imufit
