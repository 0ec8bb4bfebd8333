#include "imufit/factory/certificate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <utility>

#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/factory/engineering_units.h"

namespace imufit {
namespace {

constexpr int kCurvePoints = 61;             // temperatures at which the coefficient curves are drawn
constexpr double kHistogramHalfWidth = 5.0;  // normalised errors binned over [-5, 5]
constexpr int kHistogramBins = 20;

// "+z" for a body axis, else "[x, y, z]".
std::string DirectionText(const Eigen::Vector3d& v) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(std::abs(v(axis)) - 1.0) < 1e-12 && std::abs(v.norm() - 1.0) < 1e-12) {
      return std::string(v(axis) > 0 ? "+" : "-") + "xyz"[axis];
    }
  }
  char text[96];
  std::snprintf(text, sizeof text, "[%.3g, %.3g, %.3g]", v.x(), v.y(), v.z());
  return text;
}

// What the table did in a segment: "static", "+100 deg/s" (with " about +x" when the axis is not
// up), "turn 360 deg about +x".
std::string MotionText(const TableSegment& segment) {
  char text[64];
  if (segment.IsTurn()) {
    std::snprintf(text, sizeof text, "turn %g deg about ", *segment.angle_rad * kRadToDeg);
    return text + DirectionText(segment.RotationAxis());
  }
  if (segment.IsStatic()) return "static";
  std::snprintf(text, sizeof text, "%+g deg/s", DpsFromRadps(segment.rate_radps));
  return segment.axis && !segment.AxisIsVertical() ? text + (" about " + DirectionText(*segment.axis)) : text;
}

FitSettings Settings(const Calibration& calibration, const WindowOptions& windows) {
  FitSettings s;
  s.trim_s = windows.trim_s;
  s.window_temp_span_c = windows.max_temp_span_c;
  if (!calibration.fit || !calibration.fit->windows_used) return s;
  const FitRecord& fit = *calibration.fit;
  s.known = true;
  s.windows_used = *fit.windows_used;
  s.windows_downweighted = fit.windows_downweighted.value_or(s.windows_downweighted);
  s.iterations = fit.iterations.value_or(s.iterations);
  s.gyro_temp_order = fit.gyro_temp_order.value_or(s.gyro_temp_order);
  s.accel_temp_order = fit.accel_temp_order.value_or(s.accel_temp_order);
  s.gyro_reduced_chi2 = fit.gyro_reduced_chi2.value_or(s.gyro_reduced_chi2);
  s.accel_reduced_chi2 = fit.accel_reduced_chi2.value_or(s.accel_reduced_chi2);
  if (fit.gyro_bias_stability_radps) s.gyro_bias_stability_dph = DphFromRadps(*fit.gyro_bias_stability_radps);
  if (fit.accel_bias_stability_mps2) s.accel_bias_stability_ug = UgFromMps2(*fit.accel_bias_stability_mps2);
  s.g_sensitivity_fitted = fit.g_sensitivity_fitted.value_or(true);
  s.loss = fit.loss.value_or("");
  s.termination = fit.termination.value_or("");
  if (const size_t end = s.termination.find(". "); end != std::string::npos) s.termination.resize(end + 1);
  return s;
}

RunSummary SummariseRun(const Calibration& calibration, const Plan& plan, const RunWindows& run) {
  RunSummary r;
  r.plan_path = plan.path;
  r.segments = static_cast<int>(plan.segments.size());
  std::set<double> rates, angles;
  for (const TableSegment& s : plan.segments) {
    if (s.IsStatic()) {
      ++r.static_segments;
    } else if (s.IsTurn()) {
      ++r.turn_segments;
      angles.insert(std::abs(*s.angle_rad * kRadToDeg));
    } else {
      rates.insert(std::abs(DpsFromRadps(s.rate_radps)));
    }
  }
  r.rates_dps.assign(rates.begin(), rates.end());
  r.turn_angles_deg.assign(angles.begin(), angles.end());
  std::set<int> visited;
  for (const Window& w : run.windows) visited.insert(w.segment);
  for (const TableSegment& s : plan.segments) {
    if (visited.count(s.id) == 0) r.segments_without_windows.push_back(s.id);
  }
  r.gravity_mps2 = plan.site.gravity_mps2;
  if (plan.site.latitude_rad) r.latitude_deg = *plan.site.latitude_rad * kRadToDeg;
  r.samples = run.stats.samples;
  r.windows = static_cast<int>(run.windows.size());
  std::set<long> temps;
  for (const Window& w : run.windows) {
    temps.insert(std::lround(w.temp_c));
    r.time_s.push_back(0.5 * (w.start_s + w.end_s));
    r.window_temp_c.push_back(w.temp_c);
  }
  for (long t : temps) r.temperatures_c.push_back(static_cast<double>(t));
  r.temp_range_c = calibration.fit_temp_range_c;
  return r;
}

// ---------------------------------------------------------------- window estimates
//
// A window w at temperature T_w, corrected through the shared model (validation.h: accelerometer
// first, the gyro's g-sensitivity from the corrected specific force a^), leaves the error
// e = corrected - truth (SI) and, mapped to raw units as the fit weighs it (fit/window_cost.h),
//
//   r = diag(S) inv(M) e = B - V - H a^ - diag(S) inv(M) truth           (raw; H = 0 for accel)
//
// with every coefficient at its fitted value at T_w. The window's own estimate of one coefficient
// is the value that zeroes the residual of its row i with all others held, solved exactly: r_i is
// affine in V_i, S_i and H_ij, and the corrected output's row i, corrected_i = sum_k M_ik u_k with
// u = inv(M) corrected = diag(1/S) (B - V - H a^), is affine in M_ij:
//
//   bias           V_i  + r_i                    1-sigma  n_i
//   scale          S_i  + r_i / x_i,             x = inv(M) truth          n_i / |x_i|
//   g-sensitivity  H_ij + r_i / a^_j                                        n_i / |a^_j|
//   misalignment   M_ij - e_i / u_j                                         sqrt(sum_k (M_ik n_k / S_k)^2) /
//   |u_j|
//
// n: the noise of the window's mean, raw, per axis (windows.h), propagated to first order. The
// estimate is stated in the group's unit by the same factor as the polynomial at T_w (io/units.h).
// Windows used: the truth must be exact (the accelerometer: a constant specific force); biases and
// g-sensitivity from static windows only (in a rate window the rate times the scale factor's own
// error would dominate); and a slope (x_i, a^_j, u_j) at least kPointRegressorFraction of its
// largest magnitude in the run, so that no point's error bar is more than 1 / fraction of the best.

constexpr double kPointRegressorFraction = 0.25;

// One window as one sensor saw it.
struct SensorWindow {
  int segment = -1;
  double temp_c = 0.0;
  bool is_static = false;
  SensorCoefficients<double> c;         // the calibration's coefficients at temp_c
  Eigen::Vector3d truth;                // omega_true (rad/s) or a_true (m/s^2), body frame
  Eigen::Vector3d error;                // e = corrected - truth, SI
  Eigen::Vector3d raw_residual;         // r = diag(S) inv(M) e, raw
  Eigen::Vector3d sensor_frame;         // u = inv(M) corrected
  Eigen::Vector3d specific_force_mps2;  // a^: the corrected accelerometer mean
  Eigen::Vector3d noise_raw;            // n: the noise of the window's mean, raw
};

std::vector<SensorWindow> SensorWindows(const Calibration& cal, const Plan& plan,
                                        const std::vector<Window>& windows,
                                        const std::vector<WindowError>& errors, Sensor sensor) {
  const bool gyro = sensor == Sensor::kGyro;
  std::vector<SensorWindow> result;
  for (const WindowError& e : errors) {
    if (!gyro && !e.specific_force_known) continue;  // the accelerometer's truth is not constant there
    const Window& w = windows[e.window];
    const TableSegment* segment = plan.Find(e.segment);
    SensorWindow s;
    s.segment = e.segment;
    s.temp_c = w.temp_c;
    s.is_static = segment != nullptr && segment->IsStatic();
    s.c = CoefficientsAt(gyro ? cal.model.gyro.data() : cal.model.accel.data(),
                         gyro ? kGyroCoefficients : kAccelCoefficients, cal.model.basis.Argument(w.temp_c));
    s.truth = gyro ? e.omega_true_radps : e.a_true_mps2;
    s.error = gyro ? e.gyro_radps : e.accel_mps2;
    const Eigen::PartialPivLU<Eigen::Matrix3d> misalignment(s.c.misalignment);
    s.raw_residual = s.c.scale.cwiseProduct(misalignment.solve(s.error));
    s.sensor_frame = misalignment.solve(Eigen::Vector3d(s.truth + s.error));
    s.specific_force_mps2 = e.a_true_mps2 + e.accel_mps2;
    s.noise_raw = w.NoiseOfMean(gyro);
    result.push_back(s);
  }
  return result;
}

// The slope of the row's residual in the coefficient (the regressor), and whether the window may
// estimate it at all (the table above).
double Regressor(const SensorWindow& w, int coefficient) {
  if (coefficient < kScaleCoefficient) return 1.0;
  if (coefficient < kMisalignmentCoefficient) {
    const int i = coefficient - kScaleCoefficient;
    return w.c.misalignment.partialPivLu().solve(w.truth)(i);
  }
  if (coefficient < kGSensitivityCoefficient) {
    return w.sensor_frame(kMisalignmentCol[coefficient - kMisalignmentCoefficient]);
  }
  return w.specific_force_mps2((coefficient - kGSensitivityCoefficient) % 3);
}

bool StaticOnly(int coefficient) {
  return coefficient < kScaleCoefficient || coefficient >= kGSensitivityCoefficient;
}

// The window's estimate minus the fitted value at T_w, raw, and its 1-sigma (the table above).
std::pair<double, double> WindowEstimate(const SensorWindow& w, int coefficient, double regressor) {
  if (coefficient < kGSensitivityCoefficient && coefficient >= kMisalignmentCoefficient) {
    const int m = coefficient - kMisalignmentCoefficient;
    const int i = kMisalignmentRow[m];
    double variance = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double term = w.c.misalignment(i, k) * w.noise_raw(k) / w.c.scale(k);
      variance += term * term;
    }
    return {-w.error(i) / regressor, std::sqrt(variance) / std::abs(regressor)};
  }
  const int i = coefficient < kScaleCoefficient          ? coefficient
                : coefficient < kMisalignmentCoefficient ? coefficient - kScaleCoefficient
                                                         : (coefficient - kGSensitivityCoefficient) / 3;
  return {w.raw_residual(i) / regressor, w.noise_raw(i) / std::abs(regressor)};
}

// The window estimates of one coefficient, in the group's unit (ppm of the scale change when
// `scale_change`).
std::vector<CoefficientPoint> WindowPoints(const Calibration& cal, const std::vector<SensorWindow>& windows,
                                           Sensor sensor, int coefficient, bool scale_change) {
  double largest = 0.0;
  for (const SensorWindow& w : windows) {
    if (StaticOnly(coefficient) && !w.is_static) continue;
    largest = std::max(largest, std::abs(Regressor(w, coefficient)));
  }
  std::vector<CoefficientPoint> points;
  if (!(largest > 0.0)) return points;
  for (const SensorWindow& w : windows) {
    if (StaticOnly(coefficient) && !w.is_static) continue;
    const double regressor = Regressor(w, coefficient);
    if (std::abs(regressor) < kPointRegressorFraction * largest) continue;
    const auto [delta_raw, sigma_raw] = WindowEstimate(w, coefficient, regressor);
    if (!(sigma_raw > 0.0)) continue;  // no noise measured: no error bar to draw
    const int axis = coefficient - kScaleCoefficient;
    const double curve =
        scale_change ? ScaleChangePpm(cal.model, nullptr, sensor, axis, w.temp_c).value
                     : EngineeringCoefficient(cal.model, nullptr, sensor, coefficient, w.temp_c).value;
    const double factor = scale_change ? ScaleChangePpmPerRaw(cal.model, sensor, axis)
                                       : EngineeringFactor(cal.model, sensor, coefficient, w.temp_c);
    points.push_back({w.temp_c, curve + factor * delta_raw, std::abs(factor) * sigma_raw, w.segment});
  }
  return points;
}

std::vector<CoefficientGroup> CoefficientCurves(const Calibration& cal,
                                                const std::vector<SensorWindow>& gyro_windows,
                                                const std::vector<SensorWindow>& accel_windows) {
  const double lo = cal.fit_temp_range_c[0], hi = cal.fit_temp_range_c[1];
  const SensorModel* sigma = cal.sigma ? &*cal.sigma : nullptr;
  std::vector<CoefficientGroup> groups;
  const auto group = [&](const char* title, Sensor sensor, int first, int count, bool scale_change,
                         bool grid) {
    CoefficientGroup g;
    g.title = title;
    g.unit = scale_change ? "ppm" : EngineeringUnit(sensor, first);
    g.grid = grid;
    for (int i = 0; i < count; ++i) {
      CoefficientCurve curve;
      curve.axis = kCoefficientNames[first + i].axis;
      for (int p = 0; p < kCurvePoints; ++p) {
        const double t = lo + (hi - lo) * p / (kCurvePoints - 1);
        const EngineeringValue v = scale_change
                                       ? ScaleChangePpm(cal.model, sigma, sensor, i, t)
                                       : EngineeringCoefficient(cal.model, sigma, sensor, first + i, t);
        const double s = std::max(v.sigma, 0.0);
        curve.temp_c.push_back(t);
        curve.value.push_back(v.value);
        curve.lo.push_back(v.value - s);
        curve.hi.push_back(v.value + s);
      }
      curve.points = WindowPoints(cal, sensor == Sensor::kGyro ? gyro_windows : accel_windows, sensor,
                                  first + i, scale_change);
      g.curves.push_back(std::move(curve));
    }
    groups.push_back(std::move(g));
  };
  group("Gyro bias", Sensor::kGyro, kBiasCoefficient, 3, false, false);
  group("Gyro scale factor change from 25 degC", Sensor::kGyro, kScaleCoefficient, 3, true, false);
  group("Gyro misalignment", Sensor::kGyro, kMisalignmentCoefficient, 6, false, false);
  group("Gyro g-sensitivity", Sensor::kGyro, kGSensitivityCoefficient, 9, false, true);
  group("Accelerometer bias", Sensor::kAccel, kBiasCoefficient, 3, false, false);
  group("Accelerometer scale factor change from 25 degC", Sensor::kAccel, kScaleCoefficient, 3, true, false);
  group("Accelerometer misalignment", Sensor::kAccel, kMisalignmentCoefficient, 6, false, false);
  return groups;
}

// The raw outputs divided by the unit's own 25 degC scale factors only (no bias, misalignment,
// g-sensitivity or temperature dependence): what the calibration fixes.
SensorModel ScaleOnly(const Calibration& cal) {
  SensorModel scale_only = SensorModel::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    const int c0 = (kScaleCoefficient + axis) * kPolynomialTerms;
    const double x = cal.model.basis.Argument(kFigureTempC);
    scale_only.gyro[c0] = EvaluateTemperaturePolynomial(cal.model.gyro.data() + c0, x);
    scale_only.accel[c0] = EvaluateTemperaturePolynomial(cal.model.accel.data() + c0, x);
  }
  return scale_only;
}

WindowResiduals Residuals(const Calibration& cal, const Plan& plan, const std::vector<Window>& windows,
                          const std::vector<WindowError>& after, const std::vector<WindowError>& before) {
  WindowResiduals r;
  std::vector<double> gyro_normalised, accel_normalised;
  for (size_t i = 0; i < after.size(); ++i) {
    const WindowError& e = after[i];
    const Window& w = windows[e.window];
    const TableSegment* segment = plan.Find(e.segment);
    r.time_s.push_back(0.5 * (w.start_s + w.end_s));
    r.temp_c.push_back(e.temp_c);
    r.segment.push_back(e.segment);
    r.is_static.push_back(segment != nullptr && segment->IsStatic());
    const Eigen::Vector3d gyro_noise_raw = w.NoiseOfMean(true), accel_noise_raw = w.NoiseOfMean(false);
    const double x = cal.model.basis.Argument(w.temp_c);
    for (int axis = 0; axis < 3; ++axis) {
      const double gyro_scale = EvaluateTemperaturePolynomial(
          cal.model.gyro.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
      const double accel_scale = EvaluateTemperaturePolynomial(
          cal.model.accel.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
      const double gyro_noise = DpsFromRadps(gyro_noise_raw(axis) / std::abs(gyro_scale));
      const double accel_noise = MgFromMps2(accel_noise_raw(axis) / std::abs(accel_scale));
      r.gyro_dps[axis].push_back(DpsFromRadps(e.gyro_radps(axis)));
      r.gyro_before_dps[axis].push_back(DpsFromRadps(before[i].gyro_radps(axis)));
      r.gyro_noise_dps[axis].push_back(gyro_noise);
      const double unknown = std::numeric_limits<double>::quiet_NaN();
      r.accel_mg[axis].push_back(e.specific_force_known ? MgFromMps2(e.accel_mps2(axis)) : unknown);
      r.accel_before_mg[axis].push_back(e.specific_force_known ? MgFromMps2(before[i].accel_mps2(axis))
                                                               : unknown);
      r.accel_noise_mg[axis].push_back(accel_noise);
      if (gyro_noise > 0.0) gyro_normalised.push_back(r.gyro_dps[axis].back() / gyro_noise);
      if (accel_noise > 0.0 && e.specific_force_known)
        accel_normalised.push_back(r.accel_mg[axis].back() / accel_noise);
    }
  }
  const double bin = 2.0 * kHistogramHalfWidth / kHistogramBins;
  r.gyro_histogram.assign(kHistogramBins, 0.0);
  r.accel_histogram.assign(kHistogramBins, 0.0);
  for (int b = 0; b < kHistogramBins; ++b)
    r.histogram_center.push_back(-kHistogramHalfWidth + (b + 0.5) * bin);
  const auto fill = [&](const std::vector<double>& values, std::vector<double>* counts, double* rms) {
    double sum = 0.0;
    for (double v : values) {
      sum += v * v;
      const int b = static_cast<int>(std::floor(
          (std::clamp(v, -kHistogramHalfWidth, kHistogramHalfWidth - 1e-9) + kHistogramHalfWidth) / bin));
      (*counts)[std::clamp(b, 0, kHistogramBins - 1)] += 1.0;
    }
    *rms = values.empty() ? 0.0 : std::sqrt(sum / values.size());
  };
  fill(gyro_normalised, &r.gyro_histogram, &r.normalised_gyro_rms);
  fill(accel_normalised, &r.accel_histogram, &r.normalised_accel_rms);
  return r;
}

std::vector<ResidualRow> ResidualTable(const Plan& plan, const std::vector<WindowError>& after,
                                       const std::vector<WindowError>& before) {
  std::vector<ErrorStats> stats = ErrorsBySegment(after);
  stats.push_back(SummariseErrors(after));
  std::vector<ErrorStats> stats_before = ErrorsBySegment(before);
  stats_before.push_back(SummariseErrors(before));
  std::vector<ResidualRow> rows;
  for (size_t i = 0; i < stats.size(); ++i) {
    const ErrorStats& s = stats[i];
    const ErrorStats& b = stats_before[i];  // the same segments, in the same order
    ResidualRow row;
    row.segment = s.segment;
    if (const TableSegment* seg = s.segment < 0 ? nullptr : plan.Find(s.segment)) {
      row.up = DirectionText(seg->up);
      row.rate_dps = DpsFromRadps(seg->rate_radps);
      row.motion = MotionText(*seg);
    }
    row.windows = s.windows;
    row.accel_windows = s.accel_windows;
    row.gyro_rms_before_dps = DpsFromRadps(b.gyro_rms_radps);
    row.gyro_rms_dps = DpsFromRadps(s.gyro_rms_radps);
    row.gyro_max_dps = DpsFromRadps(s.gyro_max_radps);
    row.accel_rms_before_mg = MgFromMps2(b.accel_rms_mps2);
    row.accel_rms_mg = MgFromMps2(s.accel_rms_mps2);
    row.accel_max_mg = MgFromMps2(s.accel_max_mps2);
    rows.push_back(row);
  }
  return rows;
}

// The rows the certificate prints (Certificate::residual_table_printed).
std::vector<ResidualRow> PrintedResidualRows(const std::vector<ResidualRow>& table, int* omitted) {
  *omitted = 0;
  const int segments = static_cast<int>(table.size()) - 1;  // the last row is "all"
  if (segments <= kMostResidualRowsPrinted) return table;
  const ResidualRow& all = table.back();
  const auto relative = [&](const ResidualRow& r) {
    return std::max(all.gyro_rms_dps > 0.0 ? r.gyro_rms_dps / all.gyro_rms_dps : 0.0,
                    all.accel_rms_mg > 0.0 ? r.accel_rms_mg / all.accel_rms_mg : 0.0);
  };
  std::vector<size_t> order(segments);
  for (int i = 0; i < segments; ++i) order[i] = i;
  const int kept = kMostResidualRowsPrinted - 1;
  std::partial_sort(order.begin(), order.begin() + kept, order.end(),
                    [&](size_t a, size_t b) { return relative(table[a]) > relative(table[b]); });
  order.resize(kept);
  std::sort(order.begin(), order.end());
  std::vector<ResidualRow> rows;
  for (size_t i : order) rows.push_back(table[i]);
  rows.push_back(all);
  *omitted = segments - kept;
  return rows;
}

// The Allan deviation of the gyro over the longest static stretch of the run (raw outputs over the
// scale factor at the stretch's temperature: rad/s), with the IEEE 952 fit's ARW and bias
// instability.
NoiseSection GyroNoise(const Calibration& cal, const StaticStretch& stretch) {
  NoiseSection section;
  section.duration_s = stretch.duration_s();
  if (section.duration_s < kMinAllanStretchS) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the longest static stretch is %.1f s, and the Allan deviation needs at least "
                  "%.0f s (imufit allan measures the noise on a long static log)",
                  section.duration_s, kMinAllanStretchS);
    section.why_not = text;
    return section;
  }
  section.computed = true;
  section.segment = stretch.segment;
  section.temp_c = stretch.mean_temp_c();
  const double tau0_s = section.duration_s / (stretch.size() - 1);
  std::vector<int64_t> factors;
  AveragingFactors(TauSpec(), AllanEstimator::kOadev, static_cast<int64_t>(stretch.size()), tau0_s, &factors);
  AllanOptions options;
  options.threads = 1;
  const double x = cal.model.basis.Argument(section.temp_c);
  const char* axes[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const double scale = EvaluateTemperaturePolynomial(
        cal.model.gyro.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
    std::vector<double> rates;
    rates.reserve(stretch.gyro[axis].size());
    for (double raw : stretch.gyro[axis]) rates.push_back(raw / scale);
    ColumnAnalysis analysis = AnalyseColumn(std::string("gyro_") + axes[axis], ColumnKind::kGyro,
                                            std::move(rates), tau0_s, factors, options);
    NoiseAxis a;
    a.axis = axes[axis];
    const NoiseFitSummary& fit = analysis.fit;
    a.fitted = fit.fitted;
    a.why_not = fit.message;
    if (fit.fitted) {
      a.points = fit.points_used;
      a.arw_deg_per_sqrt_hr = DegPerSqrtHrFromRadPerSqrtS(fit.value[kRandomWalk]);
      a.arw_sigma = DegPerSqrtHrFromRadPerSqrtS(fit.sigma[kRandomWalk]);
      a.arw_resolved = IsResolved(fit, kRandomWalk);
      a.bias_instability_dph = DphFromRadps(fit.value[kBiasInstability]);
      a.bias_instability_sigma = DphFromRadps(fit.sigma[kBiasInstability]);
      a.bias_instability_resolved = IsResolved(fit, kBiasInstability);
    }
    section.axes.push_back(std::move(a));
    section.columns.push_back(std::move(analysis));
  }
  return section;
}

// Plan segments the run never visited: a warning each.
void CoverageWarnings(const RunSummary& run, std::vector<std::string>* warnings) {
  for (int id : run.segments_without_windows) {
    warnings->push_back("plan segment " + std::to_string(id) +
                        " has no usable window in the samples (never occurs, or every occurrence is shorter "
                        "than the trim and the minimum window)");
  }
}

// The station's reference equipment must have been within its calibration when the unit was
// calibrated (ISO dates compare as text).
void StationWarnings(const Station& station, const std::string& calibrated_utc,
                     const std::string& written_utc, std::vector<std::string>* warnings) {
  if (station.reference_calibration_due.empty()) return;
  const std::string when = (calibrated_utc.size() >= 10 ? calibrated_utc : written_utc).substr(0, 10);
  if (station.reference_calibration_due < when) {
    warnings->push_back("the station's reference equipment was due for calibration on " +
                        station.reference_calibration_due + ", before this unit was calibrated (" + when +
                        ")");
  }
}

}  // namespace

Certificate MakeCertificate(const CertificateSources& sources) {
  const Calibration& cal = sources.calibration;
  Certificate c;
  c.serial = cal.serial;
  c.unit = sources.unit;
  c.calibrated_utc = cal.created_utc;
  c.written_utc = UtcNow();
  c.calibration_software = cal.software;
  c.report_software = sources.software;
  c.git_revision = IMUFIT_GIT_REVISION;
  c.reference_temp_c = cal.model.basis.center_c;
  std::vector<ReportInput> inputs = sources.inputs;
  if (sources.station && std::none_of(inputs.begin(), inputs.end(),
                                      [](const ReportInput& in) { return in.role == "station"; })) {
    inputs.push_back({"station", sources.station->path, ""});
  }
  for (ReportInput input : inputs) {
    if (input.path.empty()) continue;
    if (input.sha256.empty()) input.sha256 = Sha256OfFile(input.path);
    c.inputs.push_back(input);
  }
  if (c.serial.empty()) {
    c.warnings.push_back(
        "no serial: neither --serial, the calibration, the samples file's '# serial:' header line nor the "
        "plan names the unit");
  }
  for (const std::string& w : sources.warnings) c.warnings.push_back(w);
  c.station = sources.station;
  if (c.station) StationWarnings(*c.station, c.calibrated_utc, c.written_utc, &c.warnings);
  c.run = SummariseRun(cal, sources.plan, sources.run);
  CoverageWarnings(c.run, &c.warnings);
  c.settings = Settings(cal, sources.windows);

  for (const Figure& f : KeyFigures(cal)) {
    // Coefficients have a path in the model ("gyro.bias.x"); the others are the fit's diagnostics
    // ("fit.gyro_residual_rms", "fit.missing_segments") and noise figures ("noise.gyro_x.arw...").
    const bool is_coefficient = f.coefficient.rfind("gyro.", 0) == 0 || f.coefficient.rfind("accel.", 0) == 0;
    c.figures.push_back({f.name, f.unit, is_coefficient, f.value, f.sigma,
                         f.sigma >= 0.0 ? kCoverageFactor * f.sigma : -1.0});
  }
  const std::vector<WindowError> after =
      PredictWindows(cal.model, sources.run.windows, sources.plan.site, sources.plan.segments);
  c.curves =
      CoefficientCurves(cal, SensorWindows(cal, sources.plan, sources.run.windows, after, Sensor::kGyro),
                        SensorWindows(cal, sources.plan, sources.run.windows, after, Sensor::kAccel));
  const std::vector<WindowError> before =
      PredictWindows(ScaleOnly(cal), sources.run.windows, sources.plan.site, sources.plan.segments);
  c.residuals = Residuals(cal, sources.plan, sources.run.windows, after, before);
  c.residual_table = ResidualTable(sources.plan, after, before);
  c.residual_table_printed = PrintedResidualRows(c.residual_table, &c.residual_rows_omitted);

  c.noise.why_not = "no samples file given";
  for (const ReportInput& in : c.inputs) {
    if (in.role != "samples") continue;
    try {
      // The stretch the run's reading kept, else read from the file now.
      c.noise = GyroNoise(cal, sources.run.static_stretch
                                   ? *sources.run.static_stretch
                                   : ReadStaticStretch(sources.plan, in.path, sources.samples_input,
                                                       sources.run.segmentation));
    } catch (const std::exception& e) {
      c.noise = NoiseSection();
      c.noise.why_not = e.what();
    }
  }
  c.verdict = sources.verdict;
  if (sources.limits) c.verdict = EvaluateLimits(*sources.limits, cal, MeasuredFigures(c));
  for (const HeldOutGroup& g : sources.folds) {
    ValidationRow row;
    row.temp_c = g.temp_c;
    row.fitted = g.fitted;
    row.why_not = g.why_not;
    row.windows = g.errors.windows;
    row.gyro_rms_dps = DpsFromRadps(g.errors.gyro_rms_radps);
    row.gyro_max_dps = DpsFromRadps(g.errors.gyro_max_radps);
    row.accel_rms_mg = MgFromMps2(g.errors.accel_rms_mps2);
    row.accel_max_mg = MgFromMps2(g.errors.accel_max_mps2);
    row.gyro_temp_order = g.gyro_temp_order;
    row.accel_temp_order = g.accel_temp_order;
    row.order_lowered = g.order_lowered;
    c.validation.push_back(row);
  }
  return c;
}

std::vector<Figure> MeasuredFigures(const Certificate& certificate) {
  std::vector<Figure> figures;
  for (const NoiseAxis& a : certificate.noise.axes) {
    if (!a.fitted) continue;
    if (a.arw_resolved) {
      figures.push_back({"gyro_arw_deg_per_sqrt_hr." + a.axis, "certificate.gyro_" + a.axis + ".arw",
                         "deg/sqrt(h)", a.arw_deg_per_sqrt_hr, a.arw_sigma});
    }
    if (a.bias_instability_resolved) {
      figures.push_back({"gyro_bias_instability_dph." + a.axis,
                         "certificate.gyro_" + a.axis + ".bias_instability", "deg/h", a.bias_instability_dph,
                         a.bias_instability_sigma});
    }
  }
  return figures;
}

std::vector<std::string> InputMismatches(const Calibration& calibration, const std::string& plan_path,
                                         const std::string& samples_path) {
  std::vector<std::string> mismatches;
  const auto check = [&](const std::optional<std::string>& recorded, const char* role, const std::string& path) {
    if (!recorded || recorded->empty() || path.empty()) return;
    const std::string actual = Sha256OfFile(path);
    if (actual != *recorded) {
      mismatches.push_back(std::string("the calibration was fitted to a ") + role + " with SHA-256 " +
                           recorded->substr(0, 16) + "..., not " + path + " (" + actual.substr(0, 16) +
                           "...)");
    }
  };
  if (!calibration.fit) return mismatches;
  check(calibration.fit->plan_sha256, "plan", plan_path);
  check(calibration.fit->samples_sha256, "samples file", samples_path);
  return mismatches;
}

// ---------------------------------------------------------------- the lot page

std::vector<RobustZ> RobustZScores(const std::vector<double>& values, const std::vector<double>& sigmas) {
  std::vector<RobustZ> scores(values.size());
  if (values.size() < 3) return scores;
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  const double m = median(values);
  std::vector<double> deviations;
  for (double v : values) deviations.push_back(std::abs(v - m));
  const double mad = median(deviations);
  for (size_t i = 0; i < values.size(); ++i) {
    if (!(mad > 0.0)) continue;  // half the lot identical: no spread to judge by
    scores[i].z = 0.6745 * (values[i] - m) / mad;
    const bool beyond_own_sigma =
        i >= sigmas.size() || !(sigmas[i] > 0.0) || std::abs(values[i] - m) > kOutlierOwnSigmas * sigmas[i];
    scores[i].outlier = std::abs(scores[i].z) > kOutlierRobustZ && beyond_own_sigma;
  }
  return scores;
}

namespace {

// The longest prefix every name shares, cut back to a boundary (after a character that is not a
// letter or digit, or between a letter and a digit) and leaving every name at least one character:
// "unit-01", "unit-02" -> "unit-"; "SN1001", "SN1002" -> "SN"; "a", "b" -> "".
std::string SharedPrefix(const std::vector<std::string>& names) {
  if (names.size() < 2) return "";
  size_t length = names.front().size();
  for (const std::string& n : names) {
    length = std::min(length, n.size() - (n.empty() ? 0 : 1));
    size_t i = 0;
    while (i < length && n[i] == names.front()[i]) ++i;
    length = i;
  }
  const std::string& first = names.front();
  const auto alnum = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  while (length > 0) {
    const char before = first[length - 1];
    const char after = first[length];
    if (!alnum(before) || (!digit(before) && digit(after))) break;
    --length;
  }
  return first.substr(0, length);
}

}  // namespace

LotSummary MakeLotSummary(const std::string& lot, const BatchResult& batch, const std::string& software,
                          const std::optional<Limits>& limits) {
  LotSummary s;
  s.lot = lot;
  s.written_utc = UtcNow();
  s.software = software;
  s.git_revision = IMUFIT_GIT_REVISION;
  if (limits) s.limits_name = limits->name.empty() ? limits->path : limits->name;
  s.units = static_cast<int>(batch.units.size());
  s.passed = batch.passed;
  s.failed = batch.failed;
  s.not_fitted = batch.not_fitted;
  s.errors = batch.errors;
  s.yield_pct = s.units > 0 ? 100.0 * batch.passed / s.units : 0.0;
  std::vector<std::string> names;
  for (const UnitOutcome& u : batch.units) names.push_back(u.unit);
  s.unit_prefix = SharedPrefix(names);
  for (const UnitOutcome& u : batch.units) {
    s.rows.push_back({u.unit, u.serial, u.status, u.verdict, u.message, u.status == "fitted",
                      u.unit.substr(s.unit_prefix.size())});
  }
  for (const std::string& name : kSummaryFigures) {
    LotFigure f;
    f.name = name;
    if (limits) f.limits = FigureLimits(name, *limits);
    for (size_t row = 0; row < batch.units.size(); ++row) {
      const UnitOutcome& u = batch.units[row];
      const Figure* figure = FindFigure(u.figures, name);
      if (figure == nullptr) continue;
      f.unit = figure->unit;
      f.units.push_back(u.unit);
      f.row.push_back(static_cast<int>(row));
      f.value.push_back(figure->value);
      f.sigma.push_back(figure->sigma);
      f.failed.push_back(u.verdict == "FAIL");
      f.outside_limits.push_back(f.limits && ((f.limits->lower && !(figure->value > *f.limits->lower)) ||
                                              (f.limits->upper && !(figure->value < *f.limits->upper))));
    }
    if (f.value.empty()) continue;
    f.z = RobustZScores(f.value, f.sigma);
    const MeanSigma m = MeanAndSigma(f.value);
    f.mean = m.mean;
    f.stdev = m.sigma;
    f.three_sigma = {f.mean - 3.0 * f.stdev, f.mean + 3.0 * f.stdev};
    f.stdev_within = WithinSigma(f.value);
    if (f.limits) {
      f.ppk = Capability(f.mean, f.stdev, *f.limits);
      f.cpk = Capability(f.mean, f.stdev_within, *f.limits);
    }
    const auto [low, high] = std::minmax_element(f.value.begin(), f.value.end());
    f.view = ViewWithLimits(std::min(*low, f.three_sigma[0]), std::max(*high, f.three_sigma[1]), f.limits);
    for (size_t i = 0; i < f.value.size(); ++i) {
      if (!f.z[i].outlier) continue;
      const UnitOutcome& owner = batch.units[f.row[i]];
      s.outliers.push_back({f.units[i], owner.serial, name, f.unit, f.value[i], f.z[i].z});
    }
    s.figures.push_back(std::move(f));
  }
  return s;
}

}  // namespace imufit
