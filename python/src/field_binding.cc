// imufit Python module: the field fit (pipeline/field_run.h, exactly what `imufit fit --field` runs)
// of a session by hand, from a samples file or from arrays.
//
// Keyword options: the field fit's own (FieldFitOptionTable(): gravity_mps2, latitude_deg, height_m,
// min_pose_s, bias_temp_order, scale_temp_order) and those of a table fit that also mean something
// to a session by hand (AppliesToAFieldFit(): temp_c, time_unit, fit_g_sensitivity, rest detection,
// ...). A table fit's other options are refused by name, as `imufit fit --field` refuses them.
#include <optional>
#include <string>

#include "binding.h"
#include "imufit/pipeline/field_run.h"
#include "imufit/pipeline/fit_run.h"
#include "keyword_options.h"

namespace imufit::python {
namespace {

py::array_t<double> Triad(const Eigen::Vector3d& v) { return ToArray({v.x(), v.y(), v.z()}); }

// The summary of a field fit (FieldFitSummary) as Python objects: per pose and per turn arrays.
py::dict FieldSummaryDict(const FieldFitSummary& fit, long long samples_read, const std::string& serial) {
  py::dict d;
  d["status"] = fit.status == FieldFitStatus::kConverged      ? "converged"
                : fit.status == FieldFitStatus::kUndetermined ? "undetermined"
                : fit.status == FieldFitStatus::kFailed       ? "failed"
                                                              : "not run";
  d["brief_report"] = fit.BriefReport();
  py::list undetermined;
  for (const std::string& u : fit.undetermined) undetermined.append(u);
  d["undetermined"] = undetermined;
  d["samples_read"] = samples_read;
  d["serial"] = serial;
  d["iterations"] = fit.iterations;
  d["termination"] = fit.termination;
  d["temp_range_c"] = py::make_tuple(fit.temp_range_c[0], fit.temp_range_c[1]);
  d["pose_temp_range_c"] = py::make_tuple(fit.pose_temp_range_c[0], fit.pose_temp_range_c[1]);
  d["gyro_noise_raw"] = Triad(fit.gyro_noise_raw);
  d["accel_noise_raw"] = Triad(fit.accel_noise_raw);
  d["accel_norm_rms_mps2"] = fit.accel_norm_rms_mps2;
  d["gyro_static_rms_radps"] = fit.gyro_static_rms_radps;
  d["direction_rms_rad"] = fit.direction_rms_rad;
  d["reduced_chi2"] = fit.reduced_chi2;
  d["noise_scale"] = py::make_tuple(fit.noise_scale[0], fit.noise_scale[1], fit.noise_scale[2]);

  const py::ssize_t n = static_cast<py::ssize_t>(fit.poses.size());
  py::array_t<int64_t> first(n), last(n);
  std::vector<double> start_s, end_s, temp_c, norm_error;
  std::vector<Eigen::Vector3d> gyro_mean, accel_mean, up;
  for (py::ssize_t i = 0; i < n; ++i) {
    const FieldPose& p = fit.poses[i];
    first.mutable_data()[i] = p.first;
    last.mutable_data()[i] = p.last;
    start_s.push_back(p.start_s);
    end_s.push_back(p.end_s);
    temp_c.push_back(p.temp_c);
    norm_error.push_back(p.accel_norm_error_mps2);
    gyro_mean.push_back(p.gyro_mean);
    accel_mean.push_back(p.accel_mean);
    up.push_back(p.up);
  }
  py::dict poses;
  poses["first"] = first;
  poses["last"] = last;
  poses["start_s"] = ToArray(start_s);
  poses["end_s"] = ToArray(end_s);
  poses["temp_c"] = ToArray(temp_c);
  poses["gyro_mean"] = Triads(gyro_mean);
  poses["accel_mean"] = Triads(accel_mean);
  poses["up"] = Triads(up);
  poses["accel_norm_error_mps2"] = ToArray(norm_error);
  d["poses"] = poses;

  const py::ssize_t m = static_cast<py::ssize_t>(fit.turns.size());
  py::array_t<int64_t> from(m), to(m);
  py::array_t<bool> saturated(m);
  std::vector<double> angle, direction_error;
  for (py::ssize_t i = 0; i < m; ++i) {
    const FieldTurn& t = fit.turns[i];
    from.mutable_data()[i] = t.from;
    to.mutable_data()[i] = t.to;
    saturated.mutable_data()[i] = t.saturated;
    angle.push_back(t.angle_rad);
    direction_error.push_back(t.direction_error_rad);
  }
  py::dict turns;
  turns["from"] = from;
  turns["to"] = to;
  turns["saturated"] = saturated;
  turns["angle_rad"] = ToArray(angle);
  turns["direction_error_rad"] = ToArray(direction_error);
  d["turns"] = turns;
  return d;
}

// Splits the keywords between the field fit's table and the table fit's options that apply.
void ApplyFieldKeywords(const std::string& where, const py::dict& kwargs, FieldFitOptions* field,
                        FitRunOptions* run) {
  py::dict field_keywords, run_keywords;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (FieldFitOptionTable().Find(name) != nullptr) {
      field_keywords[key] = value;
    } else if (FitRunOptionTable().Find(name) != nullptr) {
      if (!AppliesToAFieldFit(name))
        ThrowBadArgument(where, name + " is an option of a table fit (imufit.fit), not of a session by hand");
      run_keywords[key] = value;
    } else {
      field_keywords[key] = value;  // unknown: ApplyKeywords raises a TypeError listing the names
    }
  }
  ApplyKeywords(FieldFitOptionTable(), where, field_keywords, field);
  ApplyKeywords(FitRunOptionTable(), where, run_keywords, run);
  field->detection = run->input.segmentation;
  field->fit_g_sensitivity = run->fit.Fits(true, kGSensitivityCoefficient);
}

py::dict FitFieldSession(const py::object& samples, const py::dict& kwargs) {
  const std::string where = "imufit.fit_field";
  FieldFitOptions options;
  FitRunOptions run;
  ApplyFieldKeywords(where, kwargs, &options, &run);
  if (const std::string problem = options.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  if (const std::string problem = run.input.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  const std::string software = std::string("imufit ") + IMUFIT_VERSION;
  FieldRunResult result;
  std::string name;
  if (py::isinstance<py::dict>(samples)) {
    SamplesInMemory arrays = SamplesFromArrays(samples.cast<py::dict>(), where);
    if (run.input.temp_c) ThrowBadArgument(where, "temp_c is for a samples file without a temp_c column");
    name = arrays.name;
    py::gil_scoped_release release;
    result.fit = FitField(arrays.samples, options);
    result.samples_read = static_cast<long long>(arrays.samples.size());
    result.samples_sha256 = arrays.Sha256();
    result.serial = arrays.serial.serial;
    if (result.fit.IsSolutionUsable()) {
      Calibration calibration = FieldCalibration(result.fit, options);
      calibration.serial = result.serial;
      calibration.software = software;
      calibration.fit->samples = arrays.name;
      calibration.fit->samples_sha256 = result.samples_sha256;
      calibration.fit->samples_read = result.samples_read;
      result.calibration = std::move(calibration);
    }
  } else {
    name = PathString(samples);
    py::gil_scoped_release release;
    result = FieldFitRun(name, run.input, options, software, "", run.allow_serial_mismatch);
  }
  py::dict summary = FieldSummaryDict(result.fit, result.samples_read, result.serial);
  if (result.fit.status == FieldFitStatus::kUndetermined) {
    py::dict attributes;
    attributes["missing"] = summary["undetermined"];
    attributes["diagnostics"] = summary;
    Raise(GetExceptions().undetermined_error, name + ": " + result.fit.BriefReport(), attributes);
  }
  if (!result.calibration) {
    py::dict attributes;
    attributes["diagnostics"] = summary;
    Raise(GetExceptions().fit_error, name + ": " + result.fit.BriefReport(), attributes);
  }
  py::dict out;
  out["calibration"] = *result.calibration;
  out["sigma"] = ModelArrays(result.fit.sigma);
  out["summary"] = summary;
  return out;
}

}  // namespace

void BindField(py::module_& m) {
  m.def("_fit_field", &FitFieldSession, py::arg("samples"), py::arg("options"),
        "imufit.fit_field() with the options as a dict: samples a path or a dict of arrays.");
  m.def(
      "fit_field_options",
      [] {
        py::dict described = DescribeKeywords(FieldFitOptionTable());
        for (const auto& [key, value] : DescribeKeywords(FitRunOptionTable())) {
          if (AppliesToAFieldFit(py::str(key))) described[key] = value;
        }
        return described;
      },
      "{name: (default, description)} of every keyword option of imufit.fit_field().");
}

}  // namespace imufit::python
