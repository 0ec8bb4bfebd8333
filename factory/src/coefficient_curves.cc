#include <algorithm>
#include <cmath>
#include <utility>

#include "certificate_sections.h"
#include "imufit/report/engineering_units.h"

// The coefficients against temperature (Certificate::curves), with each window's own estimate.
//
// A window w at temperature T_w, corrected through the shared model (validation.h: accelerometer
// first, the gyro's g-sensitivity from the corrected specific force a^), leaves the error
// e = corrected - truth (SI) and, mapped to raw units as the fit weighs it (fit/src/window_cost.h),
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
// estimate is stated in the group's unit by the same factor as the polynomial at T_w
// (engineering_units.h).
// Windows used: the truth must be exact (the accelerometer: a constant specific force); biases and
// g-sensitivity from static windows only (in a rate window the rate times the scale factor's own
// error would dominate); and a slope (x_i, a^_j, u_j) at least kPointRegressorFraction of its
// largest magnitude in the run, so that no point's error bar is more than 1 / fraction of the best.

namespace imufit::internal {
namespace {

constexpr int kCurvePoints = 61;  // temperatures at which the coefficient curves are drawn
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

}  // namespace

std::vector<CoefficientGroup> CoefficientCurves(const Calibration& cal, const Plan& plan,
                                                const std::vector<Window>& windows,
                                                const std::vector<WindowError>& errors) {
  const std::vector<SensorWindow> gyro_windows = SensorWindows(cal, plan, windows, errors, Sensor::kGyro);
  const std::vector<SensorWindow> accel_windows = SensorWindows(cal, plan, windows, errors, Sensor::kAccel);
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

}  // namespace imufit::internal
