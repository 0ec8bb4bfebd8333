#include "imufit/pipeline/consistency.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>
#include <set>

#include "imufit/base/text.h"
#include "imufit/fit/validation.h"
#include "imufit/model/constants.h"

namespace imufit {
namespace {

// A sensor held whole (SensorFit::kNone) was not fitted: its chi-square measures the held values.
std::string Chi2Finding(const char* sensor, bool judged, double reduced_chi2, int dof) {
  if (!judged || dof <= 0 || !(reduced_chi2 > ReducedChi2Limit(dof))) return "";
  return std::string(sensor) + " reduced chi-square " + NumberText("%.3g", reduced_chi2) + " (at most " +
         NumberText("%.3g", ReducedChi2Limit(dof)) + " for the noise and model error of " +
         std::to_string(dof) + " degrees of freedom)";
}

// The temperature cluster (index into distinct_temps_c) nearest to `temp_c`.
size_t Cluster(const std::vector<double>& centres, double temp_c) {
  size_t best = 0;
  for (size_t c = 1; c < centres.size(); ++c) {
    if (std::abs(centres[c] - temp_c) < std::abs(centres[best] - temp_c)) best = c;
  }
  return best;
}

// Segments down-weighted (more than half of their windows) at every temperature they were seen at.
std::string DownweightedSegments(const FitSummary& fit, const std::vector<Window>& windows, bool gyro_judged,
                                 bool accel_judged) {
  struct Count {
    int windows = 0;
    int downweighted = 0;
  };
  std::map<int, std::map<size_t, Count>> counts;  // segment -> temperature cluster -> counts
  std::map<int, double> gyro_sum;                 // squared residuals, for the finding
  std::map<int, double> accel_sum;
  std::map<int, double> normalised_sum;  // squared residuals over the noise of the window means
  // |residual / sigma|^2 per axis, over the axes that carry a weight.
  const auto normalised = [](const Eigen::Vector3d& residual, const Eigen::Vector3d& sigma) {
    double sum = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      if (sigma(axis) > 0.0) sum += (residual(axis) / sigma(axis)) * (residual(axis) / sigma(axis));
    }
    return sum;
  };
  for (const WindowResidual& r : fit.residuals) {
    const Window& w = windows[static_cast<size_t>(r.window)];
    Count& count =
        counts[w.segment][fit.distinct_temps_c.empty() ? 0 : Cluster(fit.distinct_temps_c, w.temp_c)];
    ++count.windows;
    count.downweighted += r.downweighted ? 1 : 0;
    gyro_sum[w.segment] += r.gyro_radps.squaredNorm() / 3.0;
    accel_sum[w.segment] += r.accel_mps2.squaredNorm() / 3.0;
    normalised_sum[w.segment] += ((gyro_judged ? normalised(r.gyro_radps, r.gyro_sigma_radps) : 0.0) +
                                  (accel_judged ? normalised(r.accel_mps2, r.accel_sigma_mps2) : 0.0)) /
                                 (3.0 * (gyro_judged + accel_judged));
  }
  std::string text;
  for (const auto& [segment, by_temp] : counts) {
    std::string temps;
    int windows_seen = 0;
    bool everywhere = true;
    for (const auto& [cluster, count] : by_temp) {
      everywhere = everywhere && 2 * count.downweighted > count.windows;
      windows_seen += count.windows;
      if (!fit.distinct_temps_c.empty())
        temps += (temps.empty() ? "" : ", ") + NumberText("%.0f", fit.distinct_temps_c[cluster]);
    }
    if (!everywhere ||
        normalised_sum[segment] / windows_seen <= kModelErrorAllowance * kModelErrorAllowance) {
      continue;
    }
    text += (text.empty() ? "" : "; ") + std::string("segment ") + std::to_string(segment) +
            " down-weighted at every temperature (" + temps + " degC), residual RMS gyro " +
            NumberText("%.3g", std::sqrt(gyro_sum[segment] / windows_seen) * kRadToDeg) + " deg/s, accel " +
            NumberText("%.3g", std::sqrt(accel_sum[segment] / windows_seen) / (1e-3 * kStandardGravityMps2)) +
            " mg";
  }
  return text;
}

// A unit of measure a logger may write a sensor in, as raw units per SI unit.
struct LoggedUnit {
  double raw_per_si;
  const char* name;
};
constexpr LoggedUnit kGyroUnits[] = {
    {1.0, "rad/s"}, {kRadToDeg, "deg/s"}, {1e3 * kRadToDeg, "mdeg/s"}, {3600.0 * kRadToDeg, "deg/h"}};
constexpr LoggedUnit kAccelUnits[] = {
    {1.0, "m/s^2"}, {1.0 / kStandardGravityMps2, "g"}, {1e3 / kStandardGravityMps2, "mg"}};

// The unit among `units` whose raw-per-SI lies within kLoggedUnitTolerance of `raw_per_si`, or nullptr.
const LoggedUnit* UnitOf(double raw_per_si, const LoggedUnit* begin, const LoggedUnit* end) {
  for (const LoggedUnit* unit = begin; unit != end; ++unit) {
    if (std::abs(raw_per_si / unit->raw_per_si - 1.0) <= kLoggedUnitTolerance) return unit;
  }
  return nullptr;
}

// The mean magnitude of a sensor's scale factors at the reference temperature, raw per SI unit.
double MeanScale(const double* params) {
  double sum = 0.0;
  for (int axis = 0; axis < 3; ++axis) sum += std::abs(params[(kScaleCoefficient + axis) * kPolynomialTerms]);
  return sum / 3.0;
}

// One sensor's gain of the corrected output over the truth, sum(corrected . truth) / sum(|truth|^2)
// over the windows `use` admits, or nullopt when they carry no signal to judge it by.
template <typename Truth, typename Error, typename Use>
std::optional<double> Gain(const std::vector<WindowError>& errors, Truth truth, Error error, Use use) {
  double along = 0.0, power = 0.0;
  for (const WindowError& e : errors) {
    if (!use(e)) continue;
    along += (truth(e) + error(e)).dot(truth(e));
    power += truth(e).squaredNorm();
  }
  if (!(power > 0.0)) return std::nullopt;
  return along / power;
}

// The finding for one sensor whose corrected output is `gain` times the truth: the log's raw units
// per SI unit (gain times the calibration's scale), named when they are a unit loggers write.
std::string ScaleFinding(const char* sensor, double gain, double model_scale, const char* si,
                         const LoggedUnit* begin, const LoggedUnit* end) {
  if (std::abs(gain - 1.0) <= kGrossScaleError) return "";
  const double logged = gain * model_scale;
  std::string text = std::string(sensor) + " corrected to " + NumberText("%.3g", gain) +
                     " times the plan's truth: the log reads " + NumberText("%.4g", logged) + " raw per " +
                     si + " where the calibration's " + (sensor[0] == 'g' ? "gyro" : "accelerometer") +
                     " scale is " + NumberText("%.4g", model_scale);
  if (const LoggedUnit* unit = UnitOf(logged, begin, end)) {
    text += std::string(" (the ") + sensor + " looks logged in " + unit->name;
    if (const LoggedUnit* held = UnitOf(model_scale, begin, end))
      text += std::string(", the calibration's values are in ") + held->name;
    else
      text += ", while the held values are raw counts";
    text += ": give --prior a calibration of the log's unit, or log in the prior's)";
  } else {
    text += " (a wrong unit of measure, or a prior of another kind of unit?)";
  }
  return text;
}

}  // namespace

std::string UnitOfMeasureFinding(const FitSummary& fit, const std::vector<Window>& windows,
                                 const TableSite& site, const std::vector<TableSegment>& segments,
                                 const FitOptions& options) {
  const std::vector<WindowError> errors = PredictWindows(fit.model, windows, site, segments);
  std::string text;
  const auto add = [&text](const std::string& finding) {
    if (!finding.empty()) text += (text.empty() ? "" : "; ") + finding;
  };
  // A sensor held whole without a prior is not calibrated (fit record uncalibrated_sensors): not judged.
  if (options.gyro_fit != SensorFit::kNone || options.held) {
    const double min_rate = options.min_excitation_rate_radps;
    const std::optional<double> gain = Gain(
        errors, [](const WindowError& e) { return e.omega_true_radps; },
        [](const WindowError& e) { return e.gyro_radps; },
        [min_rate](const WindowError& e) { return e.omega_true_radps.norm() >= min_rate; });
    if (gain)
      add(ScaleFinding("gyro", *gain, MeanScale(fit.model.gyro.data()), "rad/s", std::begin(kGyroUnits),
                       std::end(kGyroUnits)));
  }
  if (options.accel_fit != SensorFit::kNone || options.held) {
    const std::optional<double> gain = Gain(
        errors, [](const WindowError& e) { return e.a_true_mps2; },
        [](const WindowError& e) { return e.accel_mps2; },
        [](const WindowError& e) { return e.specific_force_known; });
    if (gain)
      add(ScaleFinding("accel", *gain, MeanScale(fit.model.accel.data()), "m/s^2", std::begin(kAccelUnits),
                       std::end(kAccelUnits)));
  }
  return text;
}

TemperatureFinding CheckRunTemperatures(const std::vector<Window>& windows,
                                        const std::vector<double>& soak_temps_c) {
  TemperatureFinding finding;
  if (windows.empty()) return finding;
  const auto [coldest, warmest] = std::minmax_element(
      windows.begin(), windows.end(), [](const Window& a, const Window& b) { return a.temp_c < b.temp_c; });
  const double lo = coldest->temp_c, hi = warmest->temp_c;
  const auto celsius_of_fahrenheit = [](double temp_f) { return (temp_f - 32.0) * 5.0 / 9.0; };
  const std::string span = NumberText("%.4g", lo) + ".." + NumberText("%.4g", hi);
  const std::string as_celsius =
      NumberText("%.4g", celsius_of_fahrenheit(lo)) + ".." + NumberText("%.4g", celsius_of_fahrenheit(hi));
  if (soak_temps_c.empty()) {
    if (hi > kMaxRatedTempC) {
      finding.warning = "the run's temperatures reach " + NumberText("%.4g", hi) +
                        " degC, above any IMU's rating (" + NumberText("%.4g", kMaxRatedTempC) +
                        " degC): Fahrenheit? (" + span + " degF is " + as_celsius +
                        " degC; temp_c must be degC; the plan's soak_temps_c would have it refused)";
    }
    return finding;
  }
  // Iterators, not a structured binding: a lambda may not capture one before C++20 (clang refuses).
  const auto soak_range = std::minmax_element(soak_temps_c.begin(), soak_temps_c.end());
  const auto cold_soak = soak_range.first;
  const auto warm_soak = soak_range.second;
  const auto agrees = [&](double cold, double warm) {
    return std::abs(cold - *cold_soak) <= kSoakToleranceC && std::abs(warm - *warm_soak) <= kSoakToleranceC;
  };
  if (agrees(lo, hi)) return finding;
  finding.refusal = "the run's temperatures span " + span + " degC where the plan's soak set-points span " +
                    NumberText("%.4g", *cold_soak) + ".." + NumberText("%.4g", *warm_soak) +
                    " degC (soak_temps_c; the unit's thermometer within " +
                    NumberText("%.3g", kSoakToleranceC) + " degC of them at the coldest and warmest)";
  if (agrees(celsius_of_fahrenheit(lo), celsius_of_fahrenheit(hi))) {
    finding.refusal += ": Fahrenheit? (" + span + " degF is " + as_celsius + " degC; temp_c must be degC)";
  } else {
    finding.refusal += ": a run of another plan, or a chamber run stopped early?";
  }
  return finding;
}

double ReducedChi2Limit(int dof) {
  return kModelErrorAllowance * kModelErrorAllowance *
         (1.0 + kChi2Sigmas * std::sqrt(2.0 / std::max(dof, 1)));
}

bool JudgedByTheGate(const FitOptions& options, bool gyro) {
  const int default_order = FitOptions().gyro_temp_order;
  if (gyro) {
    return options.gyro_fit == SensorFit::kAll && options.fit_g_sensitivity &&
           options.gyro_temp_order >= default_order;
  }
  return options.accel_fit == SensorFit::kAll && options.accel_temp_order >= default_order;
}

std::string Inconsistency(const FitSummary& fit, const std::vector<Window>& windows, const TableSite& site,
                          const std::vector<TableSegment>& segments, const FitOptions& options) {
  // Every fit, subsets included: a held scale in another unit than the log's.
  const std::string unit = UnitOfMeasureFinding(fit, windows, site, segments, options);
  if (!unit.empty()) return unit + ": a wrong unit of measure, not a calibration";
  const bool gyro = JudgedByTheGate(options, true), accel = JudgedByTheGate(options, false);
  if (!gyro && !accel) return "";
  std::string text;
  for (const std::string& finding : {Chi2Finding("gyro", gyro, fit.gyro_reduced_chi2, fit.gyro_dof),
                                     Chi2Finding("accel", accel, fit.accel_reduced_chi2, fit.accel_dof),
                                     DownweightedSegments(fit, windows, gyro, accel)}) {
    if (!finding.empty()) text += (text.empty() ? "" : "; ") + finding;
  }
  if (text.empty()) return text;
  return text + ": the plan does not describe the run (a segment's up, rate, angle or axis, or its labels)";
}

}  // namespace imufit
