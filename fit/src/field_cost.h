// imufit — the residuals the field fit minimises (fit/field_fit.h, step 3), each through the shared
// model (model/sensor_model.h: CoefficientsAt, CorrectSensor, CorrectWith) and the attitude
// integrator (model/attitude_integration.h), templated on the scalar so that Ceres differentiates
// exactly what `imufit apply` runs.
//
// Parameters are scaled for the solver, p = p0 + step .* q (window_cost.h), in blocks:
//
//   gyro   kGyroBlock  = kGyroCoefficients x kTerms   every gyro coefficient, terms c0..c(kTerms-1)
//   accel  kAccelBlock = kAccelFree x kTerms          the accelerometer's coefficients but the three
//                                                     misalignments the body frame holds at 0
//   pose   2                                          gravity's direction at a pose, u = (u0 + d1 e1
//                                                     + d2 e2) / |...|, d = kPoseStep q
//
// and expanded into the model's layout (term k of coefficient i at i * kPolynomialTerms + k).
// kTerms = 1 is the fit at one temperature; the temperature argument x of each residual is that of
// its pose or turn, so a higher kTerms needs no other change here.
// Header-only so that tests can instantiate the costs with ceres::Jet and with double.
#ifndef IMUFIT_FIT_SRC_FIELD_COST_H_
#define IMUFIT_FIT_SRC_FIELD_COST_H_

#include <array>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>

#include "imufit/fit/field_fit.h"
#include "imufit/model/attitude_integration.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

// Where the solver's q lives in the model's parameters (see above).
struct FieldLayout {
  static constexpr int kTerms = 1;
  static constexpr int kAccelFree = 9;
  static constexpr int kGyroBlock = kGyroCoefficients * kTerms;
  static constexpr int kAccelBlock = kAccelFree * kTerms;
  static constexpr double kPoseStep = 1e-3;  // rad per unit of a pose's q
  // The accelerometer coefficients fitted: bias x y z, scale x y z, misalignment yx zx zy.
  static constexpr int kAccelFreeCoefficient[kAccelFree] = {0, 1, 2, 3, 4, 5, 8, 10, 11};

  std::array<double, kGyroParameters> gyro0{};  // p0, the model's layout
  std::array<double, kAccelParameters> accel0{};
  std::array<double, kGyroBlock> gyro_step{};
  std::array<double, kAccelBlock> accel_step{};
  // Each residual group's noise as a multiple of the log's white noise (1 until the fit finds the
  // group's residuals larger than that noise explains: field_fit.cc, NoiseScales()). Indexed by
  // kAccelGroup, kGyroGroup, kTurnGroup; a residual is divided by its group's.
  static constexpr int kAccelGroup = 0;
  static constexpr int kGyroGroup = 1;
  static constexpr int kTurnGroup = 2;
  std::array<double, 3> noise_scale{1.0, 1.0, 1.0};

  template <typename T>
  void Gyro(const T* q, T* p) const {
    for (int i = 0; i < kGyroParameters; ++i) p[i] = T(gyro0[i]);
    for (int c = 0; c < kGyroCoefficients; ++c) {
      for (int k = 0; k < kTerms; ++k) {
        p[c * kPolynomialTerms + k] += T(gyro_step[c * kTerms + k]) * q[c * kTerms + k];
      }
    }
  }
  template <typename T>
  void Accel(const T* q, T* p) const {
    for (int i = 0; i < kAccelParameters; ++i) p[i] = T(accel0[i]);
    for (int f = 0; f < kAccelFree; ++f) {
      const int c = kAccelFreeCoefficient[f];
      for (int k = 0; k < kTerms; ++k) {
        p[c * kPolynomialTerms + k] += T(accel_step[f * kTerms + k]) * q[f * kTerms + k];
      }
    }
  }
  // Both sensors' coefficients at the temperature argument x.
  template <typename T>
  UnitCoefficients<T> CoefficientsAtArgument(const T* gyro_q, const T* accel_q, const T& x) const {
    T gyro[kGyroParameters];
    T accel[kAccelParameters];
    Gyro(gyro_q, gyro);
    Accel(accel_q, accel);
    return {CoefficientsAt(gyro, kGyroCoefficients, x), CoefficientsAt(accel, kAccelCoefficients, x)};
  }
};

// Gravity's direction at a pose: u0 and two unit vectors perpendicular to it.
struct PoseDirection {
  Eigen::Vector3d u0 = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitY();

  explicit PoseDirection(const Eigen::Vector3d& up);
  template <typename T>
  Vector3<T> At(const T* q) const {
    const Vector3<T> v =
        u0.cast<T>() + T(FieldLayout::kPoseStep) * (q[0] * e1.cast<T>() + q[1] * e2.cast<T>());
    return v / v.norm();
  }
};

// K (error): the same error in raw units, diag(S) inv(M) error (window_cost.h).
template <typename T>
Vector3<T> InRawUnits(const SensorCoefficients<T>& c, const Vector3<T>& error) {
  return c.scale.cwiseProduct(c.misalignment.partialPivLu().solve(error));
}

// The accelerometer at a pose: K_a (a_hat - g u) / sigma_raw. Blocks: accel, pose.
class FieldPoseAccelCost {
 public:
  FieldPoseAccelCost(const FieldLayout* layout, const PoseDirection* pose, const Eigen::Vector3d& accel_mean,
                     double x, double gravity_mps2, const Eigen::Vector3d& sigma_raw)
      : layout_(layout),
        pose_(pose),
        accel_mean_(accel_mean),
        x_(x),
        gravity_mps2_(gravity_mps2),
        inverse_sigma_(sigma_raw.cwiseInverse()) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const PoseDirection* pose,
                                     const Eigen::Vector3d& accel_mean, double x, double gravity_mps2,
                                     const Eigen::Vector3d& sigma_raw) {
    return new ceres::AutoDiffCostFunction<FieldPoseAccelCost, 3, FieldLayout::kAccelBlock, 2>(
        new FieldPoseAccelCost(layout, pose, accel_mean, x, gravity_mps2, sigma_raw));
  }

  template <typename T>
  bool operator()(const T* accel_q, const T* pose_q, T* residual) const {
    T accel[kAccelParameters];
    layout_->Accel(accel_q, accel);
    const SensorCoefficients<T> c = CoefficientsAt(accel, kAccelCoefficients, T(x_));
    const Vector3<T> a_hat = CorrectSensor(c, accel_mean_.cast<T>().eval(), Vector3<T>::Zero().eval());
    const Vector3<T> raw_error = InRawUnits(c, (a_hat - T(gravity_mps2_) * pose_->At(pose_q)).eval());
    const double scale = layout_->noise_scale[FieldLayout::kAccelGroup];
    for (int axis = 0; axis < 3; ++axis) residual[axis] = raw_error(axis) * T(inverse_sigma_(axis) / scale);
    return true;
  }

 private:
  const FieldLayout* layout_;
  const PoseDirection* pose_;
  Eigen::Vector3d accel_mean_;
  double x_;
  double gravity_mps2_;
  Eigen::Vector3d inverse_sigma_;
};

// The gyro at rest: K_g omega_hat / sigma_raw, omega_hat = CorrectWith(the pose's means), whose
// g-sensitivity term uses the pose's corrected specific force. Blocks: gyro, accel.
class FieldPoseGyroCost {
 public:
  FieldPoseGyroCost(const FieldLayout* layout, const Eigen::Vector3d& gyro_mean,
                    const Eigen::Vector3d& accel_mean, double x, const Eigen::Vector3d& sigma_raw)
      : layout_(layout),
        gyro_mean_(gyro_mean),
        accel_mean_(accel_mean),
        x_(x),
        inverse_sigma_(sigma_raw.cwiseInverse()) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const Eigen::Vector3d& gyro_mean,
                                     const Eigen::Vector3d& accel_mean, double x,
                                     const Eigen::Vector3d& sigma_raw) {
    return new ceres::AutoDiffCostFunction<FieldPoseGyroCost, 3, FieldLayout::kGyroBlock,
                                           FieldLayout::kAccelBlock>(
        new FieldPoseGyroCost(layout, gyro_mean, accel_mean, x, sigma_raw));
  }

  template <typename T>
  bool operator()(const T* gyro_q, const T* accel_q, T* residual) const {
    const UnitCoefficients<T> c = layout_->CoefficientsAtArgument(gyro_q, accel_q, T(x_));
    Vector3<T> omega_hat;
    Vector3<T> a_hat;
    CorrectWith(c, gyro_mean_.cast<T>().eval(), accel_mean_.cast<T>().eval(), &omega_hat, &a_hat);
    const Vector3<T> raw_error = InRawUnits(c.gyro, omega_hat);
    const double scale = layout_->noise_scale[FieldLayout::kGyroGroup];
    for (int axis = 0; axis < 3; ++axis) residual[axis] = raw_error(axis) * T(inverse_sigma_(axis) / scale);
    return true;
  }

 private:
  const FieldLayout* layout_;
  Eigen::Vector3d gyro_mean_;
  Eigen::Vector3d accel_mean_;
  double x_;
  Eigen::Vector3d inverse_sigma_;
};

// One raw sample of a turn and the time since the sample before (0 for the first).
struct TurnSample {
  double step_s = 0.0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

// The attitude at a turn's end relative to its start (attitude_integration.h): the corrected gyro
// (CorrectWith, each sample with its own corrected specific force) integrated over the samples on
// their times `times_s`.
template <typename T>
Quaternion4<T> IntegrateTurn(const UnitCoefficients<T>& c, const std::vector<TurnSample>& samples,
                             const std::vector<double>& times_s) {
  std::vector<Vector3<T>> omega(samples.size());
  Vector3<T> a_hat;
  for (size_t k = 0; k < samples.size(); ++k) {
    CorrectWith(c, samples[k].gyro.cast<T>().eval(), samples[k].accel.cast<T>().eval(), &omega[k], &a_hat);
  }
  return IntegrateAttitude(times_s.data(), omega.data(), samples.size());
}

// The times of a turn's samples from its first, s.
inline std::vector<double> TurnTimes(const std::vector<TurnSample>& samples) {
  std::vector<double> times_s(samples.size(), 0.0);
  for (size_t k = 1; k < samples.size(); ++k) times_s[k] = times_s[k - 1] + samples[k].step_s;
  return times_s;
}

// Gravity's direction after a turn: integrate the corrected gyro over the turn's samples (their
// own steps), rotate the direction at the pose before into the frame at the end, compare with the
// direction at the pose after along its two perpendicular unit vectors. The coefficients are
// evaluated once, at the turn's mean temperature argument x (a turn lasts seconds). Blocks: gyro,
// accel, pose before, pose after.
class FieldTurnCost {
 public:
  FieldTurnCost(const FieldLayout* layout, const PoseDirection* from, const PoseDirection* to,
                std::vector<TurnSample> samples, double x, double sigma_rad)
      : layout_(layout),
        from_(from),
        to_(to),
        samples_(std::move(samples)),
        times_s_(TurnTimes(samples_)),
        x_(x),
        inverse_sigma_(1.0 / sigma_rad) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const PoseDirection* from,
                                     const PoseDirection* to, std::vector<TurnSample> samples, double x,
                                     double sigma_rad) {
    return new ceres::AutoDiffCostFunction<FieldTurnCost, 2, FieldLayout::kGyroBlock,
                                           FieldLayout::kAccelBlock, 2, 2>(
        new FieldTurnCost(layout, from, to, std::move(samples), x, sigma_rad));
  }

  template <typename T>
  bool operator()(const T* gyro_q, const T* accel_q, const T* from_q, const T* to_q, T* residual) const {
    const UnitCoefficients<T> c = layout_->CoefficientsAtArgument(gyro_q, accel_q, T(x_));
    const Vector3<T> predicted =
        RotateIntoCurrentFrame(IntegrateTurn(c, samples_, times_s_), from_->At(from_q));
    const Vector3<T> error = predicted - to_->At(to_q);
    const double scale = layout_->noise_scale[FieldLayout::kTurnGroup];
    residual[0] = error.dot(to_->e1.cast<T>()) * T(inverse_sigma_ / scale);
    residual[1] = error.dot(to_->e2.cast<T>()) * T(inverse_sigma_ / scale);
    return true;
  }

 private:
  const FieldLayout* layout_;
  const PoseDirection* from_;
  const PoseDirection* to_;
  std::vector<TurnSample> samples_;
  std::vector<double> times_s_;  // of samples_, from the first
  double x_;
  double inverse_sigma_;
};

}  // namespace imufit

#endif  // IMUFIT_FIT_SRC_FIELD_COST_H_
