// imufit — temperature polynomials of the calibration coefficients.
//
// Every coefficient C of the sensor model (a bias, a scale factor, a misalignment or a
// g-sensitivity term) is a cubic in temperature:
//
//   C(T) = c0 + c1 x + c2 x^2 + c3 x^3,   x = (T - center_c) / half_range_c.
//
// The exported calibration (docs/spec.md section 3) uses center_c = 25 degC and half_range_c = 1,
// so that x = dT = T - 25 degC and c0..c3 are the coefficients of powers of dT. The fitter
// uses the same function with a centre and half range that map the run's temperatures to about
// [-1, 1] (a well-conditioned basis), and converts exactly to powers of dT on export with
// RebaseTemperaturePolynomial(). Temperatures are in degC; the coefficient's unit is the unit of
// C itself (x is dimensionless when half_range_c carries the unit degC).
#ifndef IMUFIT_MODEL_TEMPERATURE_POLYNOMIAL_H_
#define IMUFIT_MODEL_TEMPERATURE_POLYNOMIAL_H_

#include <cmath>

#include <Eigen/Core>

namespace imufit {

// Number of polynomial terms per coefficient: c0..c3 (a cubic).
inline constexpr int kPolynomialTerms = 4;

// The reference temperature of the exported coefficients, degC.
inline constexpr double kReferenceTempC = 25.0;

// Maps a temperature reading to the polynomial's argument x = (T - center_c) / half_range_c.
struct TemperatureBasis {
  double center_c = kReferenceTempC;  // temperature at which x = 0, degC
  double half_range_c = 1.0;          // temperature step that changes x by one, degC

  // The basis of the exported calibration file: x = T - 25 degC.
  static TemperatureBasis Reference() { return TemperatureBasis{}; }

  template <typename T>
  T Argument(const T& temp_c) const {
    return (temp_c - T(center_c)) / T(half_range_c);
  }
};

// Evaluates c[0] + c[1] x + c[2] x^2 + c[3] x^3 (Horner). `c` points to kPolynomialTerms values.
template <typename T>
T EvaluateTemperaturePolynomial(const T* c, const T& x) {
  return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}

// The smallest and largest value of a cubic in x = T - center_c (the calibration's basis) over
// [low_c, high_c], and where they occur. A cubic is monotonic between the ends of the range and
// the roots of its derivative c1 + 2 c2 x + 3 c3 x^2 inside it, so its extremes are among them.
struct PolynomialExtremes {
  double min_value = 0.0;
  double min_at_c = 0.0;
  double max_value = 0.0;
  double max_at_c = 0.0;
};
inline PolynomialExtremes ExtremesOverRange(const double* c, double center_c, double low_c, double high_c) {
  double candidates[4] = {low_c, high_c, low_c, low_c};
  int count = 2;
  const double a = 3.0 * c[3], b = 2.0 * c[2], d = c[1];
  const auto add = [&](double x) {
    if (std::isfinite(x) && x + center_c > low_c && x + center_c < high_c) candidates[count++] = x + center_c;
  };
  if (a == 0.0) {
    if (b != 0.0) add(-d / b);
  } else if (const double disc = b * b - 4.0 * a * d; disc >= 0.0) {
    add((-b + std::sqrt(disc)) / (2.0 * a));
    add((-b - std::sqrt(disc)) / (2.0 * a));
  }
  PolynomialExtremes extremes;
  for (int i = 0; i < count; ++i) {
    const double value = EvaluateTemperaturePolynomial(c, candidates[i] - center_c);
    if (i == 0 || value < extremes.min_value) extremes.min_value = value, extremes.min_at_c = candidates[i];
    if (i == 0 || value > extremes.max_value) extremes.max_value = value, extremes.max_at_c = candidates[i];
  }
  return extremes;
}

// The 4x4 matrix L that converts coefficients in basis `from` into coefficients in basis `to`,
// exactly (binomial expansion): c_to = L * c_from. Because the map is linear, a covariance
// converts as L * Sigma * L^T.
//
// With x_f = (T - a_f) / h_f and x_t = (T - a_t) / h_t we have x_f = (h_t x_t + a_t - a_f) / h_f
// = s x_t + d, and (s x_t + d)^k = sum_j binom(k, j) s^j d^(k-j) x_t^j.
inline Eigen::Matrix4d RebaseTemperaturePolynomial(const TemperatureBasis& from, const TemperatureBasis& to) {
  const double s = to.half_range_c / from.half_range_c;
  const double d = (to.center_c - from.center_c) / from.half_range_c;
  Eigen::Matrix4d binomial = Eigen::Matrix4d::Zero();
  for (int k = 0; k < kPolynomialTerms; ++k) {
    binomial(k, 0) = 1.0;
    for (int j = 1; j <= k; ++j) {
      binomial(k, j) = binomial(k - 1, j - 1) + (j <= k - 1 ? binomial(k - 1, j) : 0.0);
    }
  }
  Eigen::Matrix4d L = Eigen::Matrix4d::Zero();
  for (int k = 0; k < kPolynomialTerms; ++k) {
    for (int j = 0; j <= k; ++j) {
      double term = binomial(k, j);
      for (int i = 0; i < j; ++i) term *= s;
      for (int i = 0; i < k - j; ++i) term *= d;
      L(j, k) = term;  // contribution of c_from[k] to c_to[j]
    }
  }
  return L;
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_TEMPERATURE_POLYNOMIAL_H_
