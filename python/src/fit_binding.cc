// imufit Python module: the fit (pipeline's FitRun, exactly what `imufit fit` runs) and the
// simulator (fit/simulator.h, what `imufit simulate` runs).
//
// Keyword options map onto the libraries' option structs through one table per function
// (FitOptionTable, SimulateOptionTable): a new option of FitOptions, WindowOptions or
// FitRunOptions is one line there. Names are the structs' own, SI units, as the stub lists them.
#include <functional>
#include <optional>

#include "binding.h"
#include "imufit/io/plan.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/sim/simulator.h"

namespace imufit::python {
namespace {

// Keyword options of one function, each a name, a line of documentation and how it reads and
// writes the options struct.
template <typename Options>
class OptionTable {
 public:
  struct Entry {
    std::string name;
    std::string doc;
    std::function<void(const py::handle&, Options*)> set;
    std::function<py::object(const Options&)> get;
  };

  // An option that is a field of Options (or of a struct inside it) of a type pybind11 converts.
  template <typename T>
  OptionTable& Field(const char* name, const char* doc, std::function<T&(Options&)> field) {
    entries_.push_back({name, doc,
                        [field](const py::handle& value, Options* o) { field(*o) = value.cast<T>(); },
                        [field](const Options& o) { return py::cast(field(const_cast<Options&>(o))); }});
    return *this;
  }
  OptionTable& Custom(const char* name, const char* doc, std::function<void(const py::handle&, Options*)> set,
                      std::function<py::object(const Options&)> get) {
    entries_.push_back({name, doc, std::move(set), std::move(get)});
    return *this;
  }

  // Sets the options named in `kwargs`. An unknown name is a TypeError (as for any Python
  // function); a value of the wrong type an InputError naming the option.
  void Apply(const std::string& function, const py::dict& kwargs, Options* options) const {
    for (const auto& [key, value] : kwargs) {
      const std::string name = py::str(key);
      const Entry* entry = Find(name);
      if (entry == nullptr) {
        std::string names;
        for (const Entry& e : entries_) names += (names.empty() ? "" : ", ") + e.name;
        throw py::type_error(function + "() got an unexpected keyword argument '" + name +
                             "'; the options are: " + names);
      }
      try {
        entry->set(value, options);
      } catch (const py::cast_error&) {
        ThrowBadArgument(function, name + "=" + std::string(py::str(py::repr(value))) +
                                       " has the wrong type (" + entry->doc + ")");
      }
    }
  }

  // {name: (default, doc)}.
  py::dict Describe(const Options& defaults) const {
    py::dict described;
    for (const Entry& e : entries_) described[py::str(e.name)] = py::make_tuple(e.get(defaults), e.doc);
    return described;
  }

 private:
  const Entry* Find(const std::string& name) const {
    for (const Entry& e : entries_) {
      if (e.name == name) return &e;
    }
    return nullptr;
  }
  std::vector<Entry> entries_;
};

// --------------------------------------------------------------------------------------- fit

const OptionTable<FitRunOptions>& FitOptionTable() {
  using O = FitRunOptions;
  static const OptionTable<O>* table = [] {
    auto* t = new OptionTable<O>();
    t->Field<int>("gyro_temp_order", "order of the gyro temperature polynomials, 0..3",
                  [](O& o) -> int& { return o.fit.gyro_temp_order; })
        .Field<int>("accel_temp_order", "order of the accelerometer temperature polynomials, 0..3",
                    [](O& o) -> int& { return o.fit.accel_temp_order; })
        .Field<bool>("fit_g_sensitivity", "fit the gyro g-sensitivity (False: held at zero)",
                     [](O& o) -> bool& { return o.fit.fit_g_sensitivity; })
        .Custom(
            "loss", "robust loss: 'none', 'huber' or 'cauchy'",
            [](const py::handle& value, O* o) {
              std::string error;
              if (!ParseRobustLoss(value.cast<std::string>(), &o->fit.loss, &error))
                ThrowBadArgument("imufit.fit", error);
            },
            [](const O& o) { return py::cast(RobustLossName(o.fit.loss)); })
        .Custom(
            "fit",
            "what to fit, comma-separated: 'all', 'gyro', 'gyro-bias', 'accel', 'accel-bias' (the rest held)",
            [](const py::handle& value, O* o) {
              std::string error;
              if (!ParseFitGroups(value.cast<std::string>(), &o->fit, &error))
                ThrowBadArgument("imufit.fit", error);
            },
            [](const O& o) {
              const auto name = [](SensorFit fit, const char* sensor) -> std::string {
                if (fit == SensorFit::kNone) return "";
                return std::string(sensor) + (fit == SensorFit::kBias ? "-bias" : "");
              };
              const std::string gyro = name(o.fit.gyro_fit, "gyro"), accel = name(o.fit.accel_fit, "accel");
              if (gyro == "gyro" && accel == "accel") return py::cast(std::string("all"));
              return py::cast(gyro + (gyro.empty() || accel.empty() ? "" : ",") + accel);
            })
        .Field<double>("loss_scale",
                       "where the robust loss acts, in robust spreads of the normalised residuals",
                       [](O& o) -> double& { return o.fit.loss_scale; })
        .Field<double>("gyro_bias_stability_radps", "the unit's in-run gyro bias stability, rad/s 1-sigma",
                       [](O& o) -> double& { return o.fit.gyro_bias_stability_radps; })
        .Field<double>("accel_bias_stability_mps2", "the unit's in-run accel bias stability, m/s^2 1-sigma",
                       [](O& o) -> double& { return o.fit.accel_bias_stability_mps2; })
        .Field<double>("bias_correlation_s", "seconds over which the wandering bias is taken as constant",
                       [](O& o) -> double& { return o.fit.bias_correlation_s; })
        .Field<int>("max_iterations", "solver iterations at most, per pass",
                    [](O& o) -> int& { return o.fit.max_iterations; })
        .Field<bool>("closed_form_start", "start from the closed-form solution (False: from nominal scales)",
                     [](O& o) -> bool& { return o.fit.closed_form_start; })
        .Field<int>("threads", "solver threads", [](O& o) -> int& { return o.fit.num_threads; })
        .Field<double>("distinct_temp_c", "temperatures within this span count as one, degC",
                       [](O& o) -> double& { return o.fit.distinct_temp_c; })
        .Field<double>("min_excitation_rate_radps", "a rate segment excites an axis from this rate, rad/s",
                       [](O& o) -> double& { return o.fit.min_excitation_rate_radps; })
        .Field<double>("rank_tolerance", "relative singular value below which a direction is undetermined",
                       [](O& o) -> double& { return o.fit.rank_tolerance; })
        .Field<double>("trim_s", "seconds dropped at the start of each segment occurrence",
                       [](O& o) -> double& { return o.windows.trim_s; })
        .Field<double>("window_temp_span_c", "a window closes when its temperature has moved this far, degC",
                       [](O& o) -> double& { return o.windows.max_temp_span_c; })
        .Field<double>("window_max_duration_s", "a window closes after this many seconds (0: never)",
                       [](O& o) -> double& { return o.windows.max_duration_s; })
        .Field<int>("window_min_samples", "windows with fewer samples are dropped",
                    [](O& o) -> int& { return o.windows.min_samples; })
        .Field<double>("max_turn_gap_s",
                       "a turn with a longer gap in its time stamps (lost samples), s, is dropped",
                       [](O& o) -> double& { return o.windows.max_turn_gap_s; })
        .Field<double>("gyro_full_scale_raw",
                       "the gyro's full scale, raw (0: not given): clipped windows are left out",
                       [](O& o) -> double& { return o.windows.gyro_full_scale_raw; })
        .Field<double>("accel_full_scale_raw", "the accel's full scale, raw (0: not given)",
                       [](O& o) -> double& { return o.windows.accel_full_scale_raw; })
        .Custom(
            "temp_c",
            "the temperature of every sample, degC, for samples without a temp_c column (None: read it)",
            [](const py::handle& value, O* o) {
              o->input.temp_c = value.is_none() ? std::nullopt : std::optional<double>(value.cast<double>());
            },
            [](const O& o) { return o.input.temp_c ? py::cast(*o.input.temp_c) : py::none(); })
        .Field<double>("segment_window_s",
                       "without a segment column: sliding window whose variance tells rest from motion, s",
                       [](O& o) -> double& { return o.input.segmentation.window_s; })
        .Field<double>("segment_noise_quantile",
                       "without a segment column: the noise level is this quantile of the windows' variances",
                       [](O& o) -> double& { return o.input.segmentation.noise_quantile; })
        .Field<double>("segment_threshold_factor",
                       "without a segment column: steady below this multiple of the noise level",
                       [](O& o) -> double& { return o.input.segmentation.threshold_factor; })
        .Field<double>("min_steady_s",
                       "without a segment column: shorter rests and constant rates count as motion, s",
                       [](O& o) -> double& { return o.input.segmentation.min_steady_s; })
        .Field<double>("direction_tolerance_deg",
                       "without a segment column: how far a measured direction may be from the plan's, deg",
                       [](O& o) -> double& { return o.input.segmentation.direction_tolerance_deg; })
        .Field<double>(
            "rate_tolerance",
            "without a segment column: how far the raw size of a rate or turn may be from the others', "
            "relative",
            [](O& o) -> double& { return o.input.segmentation.rate_tolerance; })
        .Field<bool>("validate", "leave each interior temperature out in turn and report the errors on it",
                     [](O& o) -> bool& { return o.validate; })
        .Custom(
            "check_samples", "a held-out run (path) to report the calibration's errors on",
            [](const py::handle& value, O* o) { o->check_samples = PathString(value); },
            [](const O& o) { return py::cast(o.check_samples); })
        .Custom(
            "check_plan", "the plan (path) of check_samples (default: the fitted run's)",
            [](const py::handle& value, O* o) { o->check_plan = PathString(value); },
            [](const O& o) { return py::cast(o.check_plan); });
    return t;
  }();
  return *table;
}

py::array_t<double> Triads(const std::vector<Eigen::Vector3d>& vectors) {
  py::array_t<double> array = NewArray(static_cast<py::ssize_t>(vectors.size()), 3);
  for (size_t i = 0; i < vectors.size(); ++i)
    std::copy(vectors[i].data(), vectors[i].data() + 3, array.mutable_data() + 3 * i);
  return array;
}

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
  const WindowStats& stats = result.run.stats;
  py::dict d;
  d["termination"] = fit.termination;
  d["iterations"] = fit.iterations;
  d["initial_cost"] = fit.initial_cost;
  d["final_cost"] = fit.final_cost;
  d["windows_used"] = fit.windows_used;
  d["windows_downweighted"] = fit.windows_downweighted;
  d["distinct_temps_c"] = ToArray(fit.distinct_temps_c);
  d["temp_range_c"] = py::make_tuple(fit.temp_range_c[0], fit.temp_range_c[1]);
  d["gyro_residual_rms_radps"] = fit.gyro_rms_radps;
  d["accel_residual_rms_mps2"] = fit.accel_rms_mps2;
  d["gyro_reduced_chi2"] = fit.gyro_reduced_chi2;
  d["accel_reduced_chi2"] = fit.accel_reduced_chi2;
  d["samples"] = stats.samples;
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

// Raises `type`(message) with the attributes given.
[[noreturn]] void Raise(const py::object& type, const std::string& message, const py::dict& attributes) {
  py::object error = type(message);
  for (const auto& [key, value] : attributes) error.attr(key) = value;
  PyErr_SetObject(type.ptr(), error.ptr());
  throw py::error_already_set();
}

// imufit._fit(plan, samples, options) -> {calibration, sigma, diagnostics}.
py::dict Fit(const py::object& plan, const py::object& samples, const py::dict& kwargs) {
  FitRunOptions options;
  options.software = std::string("imufit ") + IMUFIT_VERSION;
  FitOptionTable().Apply("imufit.fit", kwargs, &options);
  if (const std::string problem = options.Validate(); !problem.empty())
    ThrowBadArgument("imufit.fit", problem);
  const std::string plan_path = PathString(plan);
  const std::string samples_path = PathString(samples);
  std::optional<FitRunResult> result;
  {
    py::gil_scoped_release release;
    result = FitRun(plan_path, samples_path, options);
  }
  const FitSummary& fit = result->fit;
  py::dict diagnostics = Diagnostics(*result);
  if (fit.status == FitStatus::kUndetermined) {
    std::string message = samples_path + ": the run does not determine the model:";
    py::list missing;
    for (const std::string& finding : fit.undetermined) {
      message += "\n  - " + finding;
      missing.append(finding);
    }
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

const OptionTable<SimulationOptions>& SimulateOptionTable() {
  using O = SimulationOptions;
  static const OptionTable<O>* table = [] {
    auto* t = new OptionTable<O>();
    t->Custom(
         "soak_temps_c", "soak temperatures, degC: one pass through the plan at each",
         [](const py::handle& value, O* o) { o->soak_temps_c = value.cast<std::vector<double>>(); },
         [](const O& o) { return py::cast(o.soak_temps_c); })
        .Custom(
            "ramp_c", "(from, to): a linear temperature ramp across `passes` passes, degC (None: soaks)",
            [](const py::handle& value, O* o) {
              if (value.is_none()) {
                o->ramp = false;
                return;
              }
              const auto range = value.cast<std::array<double, 2>>();
              o->ramp = true;
              o->ramp_from_c = range[0];
              o->ramp_to_c = range[1];
            },
            [](const O& o) -> py::object {
              if (!o.ramp) return py::none();
              return py::make_tuple(o.ramp_from_c, o.ramp_to_c);
            })
        .Field<int>("passes", "passes through the plan during a ramp", [](O& o) -> int& { return o.passes; })
        .Field<double>("dwell_s", "seconds in each segment", [](O& o) -> double& { return o.dwell_s; })
        .Field<double>("transition_s", "seconds the table moves between segments (segment -1)",
                       [](O& o) -> double& { return o.transition_s; })
        .Field<double>("rate_hz", "sample rate, Hz", [](O& o) -> double& { return o.rate_hz; })
        .Field<double>("start_time_s", "time_s of the first sample",
                       [](O& o) -> double& { return o.start_time_s; })
        .Field<double>("gyro_noise_density", "gyro white noise, rad/s/sqrt(Hz)",
                       [](O& o) -> double& { return o.gyro_noise_density; })
        .Field<double>("accel_noise_density", "accel white noise, m/s^2/sqrt(Hz)",
                       [](O& o) -> double& { return o.accel_noise_density; })
        .Field<double>("gyro_random_walk", "gyro bias random walk, rad/s^2/sqrt(Hz)",
                       [](O& o) -> double& { return o.gyro_random_walk; })
        .Field<double>("accel_random_walk", "accel bias random walk, m/s^3/sqrt(Hz)",
                       [](O& o) -> double& { return o.accel_random_walk; })
        .Field<double>("gyro_bias_instability", "gyro Gauss-Markov bias, steady-state sigma, rad/s",
                       [](O& o) -> double& { return o.gyro_bias_instability; })
        .Field<double>("accel_bias_instability", "accel Gauss-Markov bias, steady-state sigma, m/s^2",
                       [](O& o) -> double& { return o.accel_bias_instability; })
        .Field<double>("bias_correlation_s", "correlation time of the Gauss-Markov bias, s",
                       [](O& o) -> double& { return o.bias_correlation_s; })
        .Field<double>("time_jitter_s",
                       "uniform jitter of the time stamps, +- s (less than half the interval)",
                       [](O& o) -> double& { return o.time_jitter_s; })
        .Field<double>("drop_probability", "probability that a sample starts a loss of drop_burst samples",
                       [](O& o) -> double& { return o.drop_probability; })
        .Field<int>("drop_burst", "samples lost in a row at each loss",
                    [](O& o) -> int& { return o.drop_burst; })
        .Field<double>("gyro_full_scale_raw", "clip the raw gyro outputs to +- this (0: no clip)",
                       [](O& o) -> double& { return o.gyro_full_scale_raw; })
        .Field<double>("accel_full_scale_raw", "clip the raw accel outputs to +- this (0: no clip)",
                       [](O& o) -> double& { return o.accel_full_scale_raw; })
        .Field<double>("temp_noise_c", "white noise of the temperature reading, degC",
                       [](O& o) -> double& { return o.temp_noise_c; })
        .Field<bool>("quantize", "round raw outputs to integer counts",
                     [](O& o) -> bool& { return o.quantize; })
        .Field<std::uint64_t>("seed", "random seed: the same seed gives the same samples",
                              [](O& o) -> std::uint64_t& { return o.seed; });
    return t;
  }();
  return *table;
}

py::dict Simulate(const py::object& plan_path, const py::object& truth, const py::dict& kwargs) {
  SimulationOptions options;
  SimulateOptionTable().Apply("imufit.simulate", kwargs, &options);
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
  m.def("_fit", &Fit, py::arg("plan"), py::arg("samples"), py::arg("options"),
        "imufit.fit() without the conversion of in-memory samples: paths only.");
  m.def(
      "fit_options", [] { return FitOptionTable().Describe(FitRunOptions()); },
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
      "simulate_options", [] { return SimulateOptionTable().Describe(SimulationOptions()); },
      "{name: (default, description)} of every keyword option of imufit.simulate().");
}

}  // namespace imufit::python
