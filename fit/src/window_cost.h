// imufit — the residual the thermal fit minimises, one window of one sensor at a time.
//
//   r = diag(S) inv(M) (correct(mean raw output of the window) - truth) / sigma_raw
//     = (mean raw output - forward(truth)) / sigma_raw                      [dimensionless]
//
// where correct() is the shared model of model/sensor_model.h (CoefficientsAt + CorrectSensor,
// exactly what `imufit apply` runs), evaluated at the window's mean temperature, and sigma_raw the
// window's noise of the mean in the sensor's raw units, per axis. The error is mapped back to raw
// units through the current K = diag(S) inv(M) because the noise lives there: a residual in SI
// divided by a fixed SI noise figure would shrink as the fitted scale grows, and the solver could
// trade a few scale-setting windows against the normalisation of every other window. In raw
// units the weights do not depend on the parameters. The gyro's g-sensitivity term is given the
// window's specific force (true, or the corrected accelerometer mean where gravity turns in the
// body frame). Parameters are scaled for the solver:
//
//   p = p0 + step .* q,
//
// with p the model's parameters in the fit's temperature basis (layout of sensor_model.h), p0
// the closed-form start and `step` a per-parameter magnitude, so every q is O(1).
// Header-only so that tests can instantiate it with ceres::Jet and with double; Create() gives
// the fit its autodiff cost, the way Ceres's examples build theirs. The fit itself instantiates it
// only through window_cost_create.h: each sensor's autodiff cost in a translation unit of its own
// (window_cost_gyro.cc, window_cost_accel.cc), so that no object of the build takes long to
// compile.
#ifndef IMUFIT_FIT_SRC_WINDOW_COST_H_
#define IMUFIT_FIT_SRC_WINDOW_COST_H_

#include <algorithm>
#include <array>

#include <ceres/autodiff_cost_function.h>
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
  // accelerometer); `x`: its temperature in the fit basis; `sigma_raw`: noise of the mean, raw.
  WindowCost(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth, const Eigen::Vector3d& a_true,
             double x, const Eigen::Vector3d& sigma_raw, const double* p0, const double* step)
      : raw_mean_(raw_mean), truth_(truth), a_true_(a_true), x_(x), inverse_sigma_(sigma_raw.cwiseInverse()) {
    std::copy(p0, p0 + kParameters, p0_.begin());
    std::copy(step, step + kParameters, step_.begin());
  }

  // The window's cost for the solver: 3 residuals over one parameter block, q (kParameters). The
  // arguments are the constructor's; the caller (the ceres::Problem) owns the result.
  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth,
                                     const Eigen::Vector3d& a_true, double x,
                                     const Eigen::Vector3d& sigma_raw, const double* p0, const double* step) {
    return new ceres::AutoDiffCostFunction<WindowCost, 3, kParameters>(
        new WindowCost(raw_mean, truth, a_true, x, sigma_raw, p0, step));
  }

  template <typename T>
  bool operator()(const T* q, T* residual) const {
    Vector3<T> corrected;
    Evaluate(q, &corrected, residual);
    return true;
  }

  // The corrected window mean (SI, what `imufit apply` computes) and the normalised residual.
  template <typename T>
  void Evaluate(const T* q, Vector3<T>* corrected, T* residual) const {
    T p[kParameters];
    for (int i = 0; i < kParameters; ++i) p[i] = T(p0_[i]) + T(step_[i]) * q[i];
    const SensorCoefficients<T> c = CoefficientsAt(p, kCoefficients, T(x_));
    *corrected = CorrectSensor(c, raw_mean_.template cast<T>().eval(), a_true_.template cast<T>().eval());
    const Vector3<T> error = *corrected - truth_.template cast<T>();
    // diag(S) inv(M) error: the same error in raw units.
    const Vector3<T> raw_error = c.scale.cwiseProduct(c.misalignment.partialPivLu().solve(error));
    for (int axis = 0; axis < 3; ++axis) residual[axis] = raw_error(axis) * T(inverse_sigma_(axis));
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

#endif  // IMUFIT_FIT_SRC_WINDOW_COST_H_
