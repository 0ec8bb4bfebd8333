// imufit — the shared correction model (docs/spec.md section 1).
//
// Gyro (VectorNav's linear gyro model) and accelerometer:
//
//   omega_hat = M_g * diag(1/S_g) * (B - V_g - H * a)        [rad/s]
//   a_hat     = M_a * diag(1/S_a) * (A - V_a)                [m/s^2]
//
// and the forward (simulation) form that inverts them exactly:
//
//   B = diag(S_g) * inv(M_g) * omega + V_g + H * a
//   A = diag(S_a) * inv(M_a) * a + V_a
//
// B, A  raw gyro / accelerometer output (the unit's own numbers, "raw")
// V     bias, raw                    S  scale factor, raw per rad/s or raw per m/s^2
// M     misalignment, unit diagonal, maps the sensor frame into the body frame (R_b_s-like)
// H     gyro g-sensitivity, raw per m/s^2; `a` is the specific force in the body frame, m/s^2
//
// Every coefficient is a cubic in temperature (temperature_polynomial.h). Parameter layout of
// one sensor, a flat array of coefficients, each followed by its kPolynomialTerms terms c0..c3:
//
//   index  gyro (kGyroParameters = 84)        accel (kAccelParameters = 48)
//   0..2   bias x, y, z                       bias x, y, z
//   3..5   scale x, y, z                      scale x, y, z
//   6..11  misalignment xy xz yx yz zx zy     misalignment xy xz yx yz zx zy
//   12..20 g_sensitivity xx xy xz yx yy yz zx zy zz   (gyro only)
//
// so term k of coefficient i is params[i * kPolynomialTerms + k]. M_xy is row x, column y.
//
// Everything here is a function template over the scalar T: the fitter instantiates it with
// ceres::Jet and differentiates it, `imufit apply` and every consumer run it with double. Stored
// doubles are lifted with T(...); nothing here can fail.
#ifndef IMUFIT_MODEL_SENSOR_MODEL_H_
#define IMUFIT_MODEL_SENSOR_MODEL_H_

#include <array>

#include <Eigen/Core>
#include <Eigen/LU>

#include "imufit/model/temperature_polynomial.h"

namespace imufit {

template <typename T>
using Vector3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;

// Coefficient indices within one sensor's parameter array (multiply by kPolynomialTerms).
inline constexpr int kBiasCoefficient = 0;           // 3 coefficients: x, y, z
inline constexpr int kScaleCoefficient = 3;          // 3 coefficients: x, y, z
inline constexpr int kMisalignmentCoefficient = 6;   // 6 coefficients: xy xz yx yz zx zy
inline constexpr int kGSensitivityCoefficient = 12;  // 9 coefficients: row-major xx..zz
inline constexpr int kGyroCoefficients = 21;
inline constexpr int kAccelCoefficients = 12;
inline constexpr int kGyroParameters = kGyroCoefficients * kPolynomialTerms;    // 84
inline constexpr int kAccelParameters = kAccelCoefficients * kPolynomialTerms;  // 48

// Row and column of the six off-diagonal misalignment terms, in parameter order.
inline constexpr int kMisalignmentRow[6] = {0, 0, 1, 1, 2, 2};
inline constexpr int kMisalignmentCol[6] = {1, 2, 0, 2, 0, 1};

// The name of each coefficient, as the calibration file spells it: group and axis, in parameter
// order (the accelerometer uses the first kAccelCoefficients).
struct CoefficientName {
  const char* group;
  const char* axis;
};
inline constexpr CoefficientName kCoefficientNames[kGyroCoefficients] = {
    {"bias", "x"},           {"bias", "y"},           {"bias", "z"},           {"scale", "x"},
    {"scale", "y"},          {"scale", "z"},          {"misalignment", "xy"},  {"misalignment", "xz"},
    {"misalignment", "yx"},  {"misalignment", "yz"},  {"misalignment", "zx"},  {"misalignment", "zy"},
    {"g_sensitivity", "xx"}, {"g_sensitivity", "xy"}, {"g_sensitivity", "xz"}, {"g_sensitivity", "yx"},
    {"g_sensitivity", "yy"}, {"g_sensitivity", "yz"}, {"g_sensitivity", "zx"}, {"g_sensitivity", "zy"},
    {"g_sensitivity", "zz"}};

// The coefficients of one sensor evaluated at one temperature.
template <typename T>
struct SensorCoefficients {
  Vector3<T> bias;           // V, raw
  Vector3<T> scale;          // S, raw per SI unit
  Matrix3<T> misalignment;   // M, unit diagonal
  Matrix3<T> g_sensitivity;  // H, raw per m/s^2 (zero for the accelerometer)
};

// Evaluates the coefficients of a sensor whose parameters start at `params` (layout above) at
// the polynomial argument x. `coefficients` is kGyroCoefficients or kAccelCoefficients; the
// accelerometer's g-sensitivity is zero.
template <typename T>
SensorCoefficients<T> CoefficientsAt(const T* params, int coefficients, const T& x) {
  const auto coefficient = [&](int i) {
    return EvaluateTemperaturePolynomial(params + i * kPolynomialTerms, x);
  };
  SensorCoefficients<T> c;
  for (int axis = 0; axis < 3; ++axis) {
    c.bias(axis) = coefficient(kBiasCoefficient + axis);
    c.scale(axis) = coefficient(kScaleCoefficient + axis);
  }
  c.misalignment.setIdentity();
  for (int m = 0; m < 6; ++m) {
    c.misalignment(kMisalignmentRow[m], kMisalignmentCol[m]) = coefficient(kMisalignmentCoefficient + m);
  }
  c.g_sensitivity.setZero();
  if (coefficients == kGyroCoefficients) {
    for (int h = 0; h < 9; ++h) {
      c.g_sensitivity(h / 3, h % 3) = coefficient(kGSensitivityCoefficient + h);
    }
  }
  return c;
}

// omega_hat or a_hat = M * diag(1/S) * (raw - V - H * specific_force_mps2). For the
// accelerometer H is zero and specific_force_mps2 is ignored.
template <typename T>
Vector3<T> CorrectSensor(const SensorCoefficients<T>& c, const Vector3<T>& raw,
                         const Vector3<T>& specific_force_mps2) {
  const Vector3<T> unbiased = raw - c.bias - c.g_sensitivity * specific_force_mps2;
  return c.misalignment * unbiased.cwiseQuotient(c.scale);
}

// raw = diag(S) * inv(M) * truth + V + H * specific_force_mps2: the exact inverse of
// CorrectSensor() for the same coefficients.
template <typename T>
Vector3<T> ForwardSensor(const SensorCoefficients<T>& c, const Vector3<T>& truth,
                         const Vector3<T>& specific_force_mps2) {
  const Vector3<T> sensor_frame = c.misalignment.partialPivLu().solve(truth);
  return c.scale.cwiseProduct(sensor_frame) + c.bias + c.g_sensitivity * specific_force_mps2;
}

// Both sensors' coefficients at one temperature: what the correction of a sample evaluates. A
// consumer correcting many samples at one temperature (a thermometer updates far more slowly than
// the samples come) evaluates them once and corrects each sample with CorrectWith().
template <typename T>
struct UnitCoefficients {
  SensorCoefficients<T> gyro;
  SensorCoefficients<T> accel;
};

// `gyro_params` and `accel_params` follow the layout above in the given temperature basis.
template <typename T>
UnitCoefficients<T> UnitCoefficientsAt(const T* gyro_params, const T* accel_params,
                                       const TemperatureBasis& basis, const T& temp_c) {
  const T x = basis.Argument(temp_c);
  return {CoefficientsAt(gyro_params, kGyroCoefficients, x),
          CoefficientsAt(accel_params, kAccelCoefficients, x)};
}

// The complete correction of one sample: the accelerometer first, then the gyro, whose
// g-sensitivity term uses the corrected specific force of the same sample (docs/spec.md).
template <typename T>
void CorrectWith(const UnitCoefficients<T>& c, const Vector3<T>& gyro_m, const Vector3<T>& accel_m,
                 Vector3<T>* omega_hat_radps, Vector3<T>* a_hat_mps2) {
  *a_hat_mps2 = CorrectSensor(c.accel, accel_m, Vector3<T>::Zero().eval());
  *omega_hat_radps = CorrectSensor(c.gyro, gyro_m, *a_hat_mps2);
}

// CorrectWith() the coefficients at `temp_c`.
template <typename T>
void CorrectSample(const T* gyro_params, const T* accel_params, const TemperatureBasis& basis,
                   const T& temp_c, const Vector3<T>& gyro_m, const Vector3<T>& accel_m,
                   Vector3<T>* omega_hat_radps, Vector3<T>* a_hat_mps2) {
  CorrectWith(UnitCoefficientsAt(gyro_params, accel_params, basis, temp_c), gyro_m, accel_m, omega_hat_radps,
              a_hat_mps2);
}

// The raw outputs a unit with these coefficients produces for a true angular rate and specific
// force (body frame, SI): the exact inverse of CorrectSample().
template <typename T>
void ForwardSample(const T* gyro_params, const T* accel_params, const TemperatureBasis& basis,
                   const T& temp_c, const Vector3<T>& omega_true_radps, const Vector3<T>& a_true_mps2,
                   Vector3<T>* gyro_m, Vector3<T>* accel_m) {
  const T x = basis.Argument(temp_c);
  const SensorCoefficients<T> accel = CoefficientsAt(accel_params, kAccelCoefficients, x);
  *accel_m = ForwardSensor(accel, a_true_mps2, Vector3<T>::Zero().eval());
  const SensorCoefficients<T> gyro = CoefficientsAt(gyro_params, kGyroCoefficients, x);
  *gyro_m = ForwardSensor(gyro, omega_true_radps, a_true_mps2);
}

// The calibration of one unit in double precision, as every consumer holds it: the parameters
// of both sensors (layout above) and the temperature basis they are written in.
struct SensorModel {
  std::array<double, kGyroParameters> gyro{};
  std::array<double, kAccelParameters> accel{};
  TemperatureBasis basis = TemperatureBasis::Reference();

  // The model whose correction is the identity: unit scale, no bias, misalignment or
  // g-sensitivity, at every temperature.
  static SensorModel Identity() {
    SensorModel model;
    for (int axis = 0; axis < 3; ++axis) {
      model.gyro[(kScaleCoefficient + axis) * kPolynomialTerms] = 1.0;
      model.accel[(kScaleCoefficient + axis) * kPolynomialTerms] = 1.0;
    }
    return model;
  }

  void Correct(double temp_c, const Eigen::Vector3d& gyro_m, const Eigen::Vector3d& accel_m,
               Eigen::Vector3d* omega_hat_radps, Eigen::Vector3d* a_hat_mps2) const {
    CorrectSample(gyro.data(), accel.data(), basis, temp_c, gyro_m, accel_m, omega_hat_radps, a_hat_mps2);
  }

  // Both sensors' coefficients at `temp_c`, for CorrectWith().
  UnitCoefficients<double> CoefficientsAtTemperature(double temp_c) const {
    return UnitCoefficientsAt(gyro.data(), accel.data(), basis, temp_c);
  }

  void Forward(double temp_c, const Eigen::Vector3d& omega_true_radps, const Eigen::Vector3d& a_true_mps2,
               Eigen::Vector3d* gyro_m, Eigen::Vector3d* accel_m) const {
    ForwardSample(gyro.data(), accel.data(), basis, temp_c, omega_true_radps, a_true_mps2, gyro_m, accel_m);
  }
};

}  // namespace imufit

#endif  // IMUFIT_MODEL_SENSOR_MODEL_H_
