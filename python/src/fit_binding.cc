// imufit Python module: the fit (pipeline's FitRun, exactly what `imufit fit` runs) and the
// simulator (fit/simulator.h, what `imufit simulate` runs).
//
// Keyword options are those of the libraries' option tables (FitRunOptionTable(),
// SimulationOptionTable(); keyword_options.h): SI units, as the stub lists them.
#include <optional>

#include "binding.h"
#include "imufit/io/plan.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/sim/simulator.h"
#include "keyword_options.h"

namespace imufit::python {

py::array_t<double> Triads(const std::vector<Eigen::Vector3d>& vectors) {
  py::array_t<double> array = NewArray(static_cast<py::ssize_t>(vectors.size()), 3);
  for (size_t i = 0; i < vectors.size(); ++i)
    std::copy(vectors[i].data(), vectors[i].data() + 3, array.mutable_data() + 3 * i);
  return array;
}

[[noreturn]] void Raise(const py::object& type, const std::string& message, const py::dict& attributes) {
  py::object error = type(message);
  for (const auto& [key, value] : attributes) error.attr(key) = value;
  PyErr_SetObject(type.ptr(), error.ptr());
  throw py::error_already_set();
}

namespace {

// --------------------------------------------------------------------------------------- fit

py::dict ErrorStatsDict(const ErrorStats& s) {
  py::dict d;
  d["segment"] = s.segment;
  d["windows"] = s.windows;
  d["accel_windows"] = s.accel_windows;  // with a known specific force: the accel figures' windows
  d["gyro_rms_radps"] = s.gyro_rms_radps;
  d["gyro_max_radps"] = s.gyro_max_radps;
  d["accel_rms_mps2"] = s.accel_rms_mps2;
  d["accel_max_mps2"] = s.accel_max_mps2;
  return d;
}

// The fit's summary, the run's windows and residuals, and the validation results, as Python
// objects (arrays for per-window values).
py::dict Diagnostics(const FitRunResult& result) {
  const FitSummary& fit = result.fit;
  const FitRecord& record = result.record;  // what the calibration's fit: block says
  const WindowStats& stats = result.run.stats;
  py::dict d;
  d["termination"] = *record.termination;
  d["iterations"] = *record.iterations;
  d["initial_cost"] = fit.initial_cost;
  d["final_cost"] = fit.final_cost;
  d["windows_used"] = *record.windows_used;
  d["windows_downweighted"] = *record.windows_downweighted;
  d["distinct_temperatures_c"] = ToArray(*record.distinct_temperatures_c);
  d["temp_range_c"] = py::make_tuple(fit.temp_range_c[0], fit.temp_range_c[1]);
  d["gyro_residual_rms_radps"] = *record.gyro_residual_rms_radps;
  d["accel_residual_rms_mps2"] = *record.accel_residual_rms_mps2;
  d["gyro_reduced_chi2"] = *record.gyro_reduced_chi2;
  d["accel_reduced_chi2"] = *record.accel_reduced_chi2;
  d["samples_read"] = *record.samples_read;
  d["transition_samples"] = stats.transition_samples;
  d["trimmed_samples"] = stats.trimmed_samples;
  d["short_windows"] = stats.short_windows;
  d["lost_samples"] = stats.lost_samples;
  d["gaps"] = stats.gaps;
  d["longest_gap_s"] = stats.longest_gap_s;
  d["off_grid_samples"] = stats.off_grid_samples;
  d["turns_dropped_for_gaps"] = stats.turns_dropped_for_gaps;
  d["turns_off_grid"] = stats.turns_off_grid;
  d["time_stamp_note"] = TimeStampNote(stats);
  d["saturated_windows"] = stats.saturated_windows;
  d["saturation_note"] = SaturationNote(stats);
  d["brief_report"] = fit.BriefReport();
  d["full_report"] = fit.FullReport();

  const std::vector<Window>& windows = result.run.windows;
  const py::ssize_t n = static_cast<py::ssize_t>(windows.size());
  py::array_t<int64_t> segment(n), occurrence(n), samples(n);
  std::vector<double> start_s, end_s, temp_c;
  std::vector<Eigen::Vector3d> gyro_mean, accel_mean, gyro_std, accel_std;
  for (py::ssize_t i = 0; i < n; ++i) {
    const Window& w = windows[i];
    segment.mutable_data()[i] = w.segment;
    occurrence.mutable_data()[i] = w.occurrence;
    samples.mutable_data()[i] = w.samples;
    start_s.push_back(w.start_s);
    end_s.push_back(w.end_s);
    temp_c.push_back(w.temp_c);
    gyro_mean.push_back(w.gyro_mean);
    accel_mean.push_back(w.accel_mean);
    gyro_std.push_back(w.gyro_std);
    accel_std.push_back(w.accel_std);
  }
  py::dict w;
  w["segment"] = segment;
  w["occurrence"] = occurrence;
  w["samples"] = samples;
  w["start_s"] = ToArray(start_s);
  w["end_s"] = ToArray(end_s);
  w["temp_c"] = ToArray(temp_c);
  w["gyro_mean"] = Triads(gyro_mean);
  w["accel_mean"] = Triads(accel_mean);
  w["gyro_std"] = Triads(gyro_std);
  w["accel_std"] = Triads(accel_std);
  d["windows"] = w;

  const py::ssize_t r = static_cast<py::ssize_t>(fit.residuals.size());
  py::array_t<int64_t> window(r);
  py::array_t<bool> downweighted(r);
  std::vector<Eigen::Vector3d> gyro, accel, gyro_sigma, accel_sigma;
  for (py::ssize_t i = 0; i < r; ++i) {
    const WindowResidual& res = fit.residuals[i];
    window.mutable_data()[i] = res.window;
    downweighted.mutable_data()[i] = res.downweighted;
    gyro.push_back(res.gyro_radps);
    accel.push_back(res.accel_mps2);
    gyro_sigma.push_back(res.gyro_sigma_radps);
    accel_sigma.push_back(res.accel_sigma_mps2);
  }
  py::dict residuals;
  residuals["window"] = window;
  residuals["gyro_radps"] = Triads(gyro);
  residuals["accel_mps2"] = Triads(accel);
  residuals["gyro_sigma_radps"] = Triads(gyro_sigma);
  residuals["accel_sigma_mps2"] = Triads(accel_sigma);
  residuals["downweighted"] = downweighted;
  d["residuals"] = residuals;

  py::list folds;
  for (const HeldOutGroup& g : result.folds) {
    py::dict fold;
    fold["temp_c"] = g.temp_c;
    fold["fitted"] = g.fitted;
    fold["why_not"] = g.why_not;
    fold["gyro_temp_order"] = g.gyro_temp_order;
    fold["accel_temp_order"] = g.accel_temp_order;
    fold["order_lowered"] = g.order_lowered;
    fold["errors"] = ErrorStatsDict(g.errors);
    folds.append(fold);
  }
  d["folds"] = folds;
  py::list check;
  for (const ErrorStats& s : result.check_errors) check.append(ErrorStatsDict(s));
  d["check_errors"] = check;
  return d;
}

// imufit.fit(plan, samples, **options) -> {calibration, sigma, diagnostics}. `plan` is a path or
// a dict (the plan's YAML as a mapping); `samples` a path or arrays (SamplesFromArrays), fitted as
// they are, through the reader of files (RunReader), with no file written.
py::dict Fit(const py::object& plan, const py::object& samples, const py::dict& kwargs) {
  const std::string where = "imufit.fit";
  FitRunOptions options;
  options.software = std::string("imufit ") + IMUFIT_VERSION;
  ApplyKeywords(FitRunOptionTable(), where, kwargs, &options);
  if (const std::string problem = options.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  std::optional<SamplesInMemory> arrays;
  if (py::isinstance<py::dict>(samples)) {
    arrays = SamplesFromArrays(samples.cast<py::dict>(), where);
    if (options.input.temp_c) ThrowBadArgument(where, "temp_c is for a samples file without a temp_c column");
  }
  std::optional<Plan> plan_read;
  std::string plan_sha256;
  if (py::isinstance<py::dict>(plan)) {
    // JSON is YAML: the dict is read by the plan reader, with its checks and messages.
    const std::string text = py::str(py::module_::import("json").attr("dumps")(plan));
    plan_read = ReadPlanText(text, where + " plan");
    plan_sha256 = Sha256Hex(text);
  }
  const std::string plan_path = plan_read ? plan_read->path : PathString(plan);
  const std::string samples_path = arrays ? arrays->name : PathString(samples);
  std::optional<FitRunResult> result;
  {
    py::gil_scoped_release release;
    if (!plan_read) {
      plan_read = ReadPlan(plan_path);
      plan_sha256 = Sha256OfFile(plan_path);
    }
    result = arrays ? FitRun(std::move(*plan_read), plan_sha256, *arrays, options)
                    : FitRun(std::move(*plan_read), plan_sha256, samples_path, options);
  }
  const FitSummary& fit = result->fit;
  py::dict diagnostics = Diagnostics(*result);
  if (fit.status == FitStatus::kUndetermined) {
    py::list missing;
    for (const std::string& finding : fit.undetermined) missing.append(finding);
    const std::string message = UndeterminedMessage(samples_path, options, *result);
    py::dict attributes;
    attributes["missing"] = missing;
    attributes["diagnostics"] = diagnostics;
    Raise(GetExceptions().undetermined_error, message, attributes);
  }
  if (!result->calibration) {
    py::dict attributes;
    attributes["diagnostics"] = diagnostics;
    Raise(GetExceptions().fit_error, samples_path + ": " + fit.BriefReport(), attributes);
  }
  py::dict out;
  out["calibration"] = *result->calibration;
  out["sigma"] = ModelArrays(fit.sigma);
  out["diagnostics"] = diagnostics;
  return out;
}

// ---------------------------------------------------------------------------------- simulate

py::dict Simulate(const py::object& plan_path, const py::object& truth, const py::dict& kwargs) {
  SimulationOptions options;
  ApplyKeywords(SimulationOptionTable(), "imufit.simulate", kwargs, &options);
  if (const std::string problem = options.Validate(); !problem.empty())
    ThrowBadArgument("imufit.simulate", problem);
  const Plan plan = ReadPlan(PathString(plan_path));
  const Calibration calibration =
      py::isinstance<Calibration>(truth) ? truth.cast<Calibration>() : ReadCalibration(PathString(truth));
  const py::ssize_t n = static_cast<py::ssize_t>(options.SampleCount(plan.segments.size()));
  py::array_t<double> time_s = NewArray(n), temp_c = NewArray(n);
  py::array_t<int64_t> segment(n);
  py::array_t<double> gyro = NewArray(n, 3), accel = NewArray(n, 3), omega_true = NewArray(n, 3),
                      a_true = NewArray(n, 3);
  double *time = time_s.mutable_data(), *temp = temp_c.mutable_data();
  int64_t* seg = segment.mutable_data();
  double *g = gyro.mutable_data(), *a = accel.mutable_data(), *w = omega_true.mutable_data(),
         *f = a_true.mutable_data();
  py::ssize_t count = 0;
  {
    py::gil_scoped_release release;
    SimulateRun(options, plan.site, plan.segments, calibration.model,
                [&](const Sample& raw, const SegmentTruth& t) {
                  if (count >= n) return;  // guarded below: SampleCount() is the bound
                  time[count] = raw.time_s;
                  temp[count] = raw.temp_c;
                  seg[count] = raw.segment;
                  std::copy(raw.gyro.data(), raw.gyro.data() + 3, g + 3 * count);
                  std::copy(raw.accel.data(), raw.accel.data() + 3, a + 3 * count);
                  std::copy(t.omega_radps.data(), t.omega_radps.data() + 3, w + 3 * count);
                  std::copy(t.a_mps2.data(), t.a_mps2.data() + 3, f + 3 * count);
                  ++count;
                });
  }
  if (count > n || (count < n && options.drop_probability == 0.0)) {
    throw std::logic_error("imufit.simulate: the simulator gave " + std::to_string(count) +
                           " samples, not the " + std::to_string(n) +
                           " SimulationOptions::SampleCount() promised");
  }
  // Lost samples (drop_probability) leave the arrays' tails unused: views of the samples given.
  const py::slice given(0, count, 1);
  py::dict samples;
  samples["time_s"] = time_s[given];
  samples["temp_c"] = temp_c[given];
  samples["segment"] = segment[given];
  samples["gyro"] = gyro[given];
  samples["accel"] = accel[given];
  samples["omega_true_radps"] = omega_true[given];
  samples["a_true_mps2"] = a_true[given];
  return samples;
}

}  // namespace

void BindFit(py::module_& m) {
  m.def(
      "_fit", &Fit, py::arg("plan"), py::arg("samples"), py::arg("options"),
      "imufit.fit() with the options as a dict: plan a path or a dict, samples a path or a dict of arrays.");
  m.def(
      "fit_options", [] { return DescribeKeywords(FitRunOptionTable()); },
      "{name: (default, description)} of every keyword option of imufit.fit().");
  m.def(
      "simulate",
      [](const py::object& plan, const py::object& truth, const py::kwargs& kwargs) {
        return Simulate(plan, truth, kwargs);
      },
      py::arg("plan"), py::arg("truth"),
      "Simulates a rate-table run (what `imufit simulate` writes, sample for sample) of the plan at `plan` "
      "(a path) for a unit calibrated as `truth` (a Calibration or a path). Keyword options: see "
      "simulate_options(). Returns {time_s, temp_c, segment, gyro, accel (raw), omega_true_radps, "
      "a_true_mps2}.");
  m.def(
      "simulate_options", [] { return DescribeKeywords(SimulationOptionTable()); },
      "{name: (default, description)} of every keyword option of imufit.simulate().");
}

}  // namespace imufit::python
