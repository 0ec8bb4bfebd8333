// imufit — the residual the thermal fit minimises, one window of one sensor at a time.
//
//   r = (correct(mean raw output of the window) - truth) / sigma          [dimensionless]
//
// where correct() is the shared model of model/sensor_model.h (CoefficientsAt + CorrectSensor,
// exactly what `imufit apply` runs), evaluated at the window's mean temperature, and sigma the
// window's measured noise of the mean converted to SI, per axis. The gyro's g-sensitivity term
// is given the true specific force of the window. Parameters are scaled for the solver:
//
//   p = p0 + step .* q,
//
// with p the model's parameters in the fit's temperature basis (layout of sensor_model.h), p0
// the closed-form start and `step` a per-parameter magnitude, so every q is O(1).
// Header-only so that tests can instantiate it with ceres::Jet and with double.
#ifndef IMUFIT_FIT_WINDOW_COST_H_
#define IMUFIT_FIT_WINDOW_COST_H_

#include <array>

#include <Eigen/Core>

#include "imufit/model/sensor_model.h"

namespace imufit {

template <int kParameters>
class WindowCost {
 public:
  static constexpr int kCoefficients = kParameters / kPolynomialTerms;
  static_assert(kParameters == kGyroParameters || kParameters == kAccelParameters);

  // `raw_mean`: the window's mean raw output; `truth`: its true rate (rad/s) or specific force
  // (m/s^2); `a_true`: its true specific force (for the g-sensitivity; ignored for the
  // accelerometer); `x`: its temperature in the fit basis; `sigma`: noise of the mean in SI.
  WindowCost(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth, const Eigen::Vector3d& a_true,
             double x, const Eigen::Vector3d& sigma, const double* p0, const double* step)
      : raw_mean_(raw_mean), truth_(truth), a_true_(a_true), x_(x), inverse_sigma_(sigma.cwiseInverse()) {
    std::copy(p0, p0 + kParameters, p0_.begin());
    std::copy(step, step + kParameters, step_.begin());
  }

  template <typename T>
  bool operator()(const T* q, T* residual) const {
    T p[kParameters];
    for (int i = 0; i < kParameters; ++i) p[i] = T(p0_[i]) + T(step_[i]) * q[i];
    const SensorCoefficients<T> c = CoefficientsAt(p, kCoefficients, T(x_));
    const Vector3<T> corrected =
        CorrectSensor(c, raw_mean_.template cast<T>().eval(), a_true_.template cast<T>().eval());
    for (int axis = 0; axis < 3; ++axis) {
      residual[axis] = (corrected(axis) - T(truth_(axis))) * T(inverse_sigma_(axis));
    }
    return true;
  }

 private:
  Eigen::Vector3d raw_mean_;
  Eigen::Vector3d truth_;
  Eigen::Vector3d a_true_;
  double x_;
  Eigen::Vector3d inverse_sigma_;
  std::array<double, kParameters> p0_;
  std::array<double, kParameters> step_;
};

}  // namespace imufit

#endif  // IMUFIT_FIT_WINDOW_COST_H_
