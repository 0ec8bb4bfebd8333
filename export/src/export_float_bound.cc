// FloatRuntimeErrorBound: the float build of the C runtime against the full model, bounded by
// propagating its float32 roundings (docs/export.md states the result in closed form).
#include <array>
#include <cmath>

#include "imufit/export/export.h"

namespace imufit {

// The bound follows the float build's operations one by one under the standard model of
// floating-point arithmetic: fl(x op y) = (x op y)(1 + d), |d| <= u = 2^-24. Each quantity carries
// a bound on its magnitude and on its error; products of two errors (order u^2) are dropped and
// covered by the final factor.
namespace {

constexpr double kFloatUnitRoundoff = 0x1p-24;

// A float quantity: |value| <= magnitude, |computed - exact| <= error.
struct Bounded {
  double magnitude = 0.0;
  double error = 0.0;
};

// A coefficient's cubic evaluated by Horner in float: coefficients rounded to float (u each),
// Horner's roundings (1, 3, 5, 6 for the terms c0..c3), x = T - T_ref rounded (u relative) plus the
// rounding of T_ref itself (`reference_error`): together u (2, 5, 8, 10)|c_k||x|^k + the
// derivative times reference_error.
Bounded Cubic(const double* c, double x, double reference_error) {
  constexpr double kRoundings[kPolynomialTerms] = {2.0, 5.0, 8.0, 10.0};
  Bounded p;
  double power = 1.0;
  for (int k = 0; k < kPolynomialTerms; ++k) {
    p.magnitude += std::abs(c[k]) * power;
    p.error += kFloatUnitRoundoff * kRoundings[k] * std::abs(c[k]) * power;
    if (k > 0) p.error += k * std::abs(c[k]) * std::pow(std::abs(x), k - 1) * reference_error;
    power *= std::abs(x);
  }
  p.magnitude += p.error;
  return p;
}

// a + b or a - b, rounded.
Bounded Add(const Bounded& a, const Bounded& b) {
  const double magnitude = a.magnitude + b.magnitude;
  return {magnitude, a.error + b.error + kFloatUnitRoundoff * magnitude};
}

// a * b, rounded.
Bounded Multiply(const Bounded& a, const Bounded& b) {
  const double magnitude = a.magnitude * b.magnitude;
  return {magnitude, a.magnitude * b.error + b.magnitude * a.error + kFloatUnitRoundoff * magnitude};
}

// a / b, rounded (|b| > its error: a scale factor far from zero).
Bounded Divide(const Bounded& a, const Bounded& b, double b_value) {
  const double smallest = std::abs(b_value) - b.error;
  const double magnitude = a.magnitude / smallest;
  return {magnitude, (a.error + magnitude * b.error) / smallest + kFloatUnitRoundoff * magnitude};
}

// M * diag(1/S) * unbiased, as the runtime's ScaleAndAlign evaluates it.
std::array<Bounded, 3> ScaleAndAlignBound(const double* params, double x, double reference_error,
                                          const std::array<Bounded, 3>& unbiased) {
  std::array<Bounded, 3> scaled, out;
  for (int axis = 0; axis < 3; ++axis) {
    const double* scale = params + (kScaleCoefficient + axis) * kPolynomialTerms;
    scaled[axis] =
        Divide(unbiased[axis], Cubic(scale, x, reference_error), EvaluateTemperaturePolynomial(scale, x));
  }
  for (int row = 0; row < 3; ++row) {
    std::array<Bounded, 3> terms;
    for (int col = 0; col < 3; ++col) terms[col] = scaled[col];  // the unit diagonal: exact
    for (int m = 0; m < 6; ++m) {
      if (kMisalignmentRow[m] != row) continue;
      const int col = kMisalignmentCol[m];
      terms[col] = Multiply(
          Cubic(params + (kMisalignmentCoefficient + m) * kPolynomialTerms, x, reference_error), scaled[col]);
    }
    out[row] = Add(Add(terms[0], terms[1]), terms[2]);
  }
  return out;
}

}  // namespace

FloatRuntimeBound FloatRuntimeErrorBound(const SensorModel& model, double temp_c,
                                         const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw) {
  constexpr double kSecondOrder = 1.001;  // covers the dropped u^2 terms many times over
  const double reference = model.basis.center_c;
  const double reference_error = std::abs(reference - static_cast<double>(static_cast<float>(reference)));
  const double x = temp_c - reference;
  std::array<Bounded, 3> unbiased;
  for (int axis = 0; axis < 3; ++axis) {
    unbiased[axis] =
        Add({std::abs(accel_raw(axis)), 0.0},
            Cubic(model.accel.data() + (kBiasCoefficient + axis) * kPolynomialTerms, x, reference_error));
  }
  const std::array<Bounded, 3> a_hat = ScaleAndAlignBound(model.accel.data(), x, reference_error, unbiased);
  for (int axis = 0; axis < 3; ++axis) {
    const double* h = model.gyro.data() + (kGSensitivityCoefficient + 3 * axis) * kPolynomialTerms;
    const auto term = [&](int col) {
      return Multiply(Cubic(h + col * kPolynomialTerms, x, reference_error), a_hat[col]);
    };
    const Bounded h_a = Add(Add(term(0), term(1)), term(2));
    unbiased[axis] =
        Add(Add({std::abs(gyro_raw(axis)), 0.0},
                Cubic(model.gyro.data() + (kBiasCoefficient + axis) * kPolynomialTerms, x, reference_error)),
            h_a);
  }
  const std::array<Bounded, 3> omega_hat =
      ScaleAndAlignBound(model.gyro.data(), x, reference_error, unbiased);
  FloatRuntimeBound bound;
  for (int axis = 0; axis < 3; ++axis) {
    bound.omega_radps(axis) = kSecondOrder * omega_hat[axis].error;
    bound.a_mps2(axis) = kSecondOrder * a_hat[axis].error;
  }
  return bound;
}

}  // namespace imufit
