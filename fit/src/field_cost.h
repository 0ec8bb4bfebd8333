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
// and expanded into the model's layout (term k of coefficient i at i * kPolynomialTerms + k, in
// the fit's temperature basis FieldLayout::basis). Terms a fit does not estimate (above its
// temperature orders, H when not fitted) are held by a SubsetManifold. Each residual is written
// in the coefficients' values at its pose's or turn's temperature argument x and wrapped in
// FieldTermsCost, which maps the term blocks to those values (a linear map), so that the Jets are
// as small at order 3 as at order 0.
// Header-only so that tests can instantiate the costs with ceres::Jet and with double.
#ifndef IMUFIT_FIT_SRC_FIELD_COST_H_
#define IMUFIT_FIT_SRC_FIELD_COST_H_

#include <array>
#include <memory>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <Eigen/Core>

#include "imufit/fit/field_fit.h"
#include "imufit/model/attitude_integration.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

// Where the solver's q lives in the model's parameters (see above).
struct FieldLayout {
  static constexpr int kTerms = kPolynomialTerms;
  static constexpr int kAccelFree = 9;
  static constexpr int kGyroBlock = kGyroCoefficients * kTerms;
  static constexpr int kAccelBlock = kAccelFree * kTerms;
  static constexpr double kPoseStep = 1e-3;  // rad per unit of a pose's q
  // The accelerometer coefficients fitted: bias x y z, scale x y z, misalignment yx zx zy.
  static constexpr int kAccelFreeCoefficient[kAccelFree] = {0, 1, 2, 3, 4, 5, 8, 10, 11};

  // The fit's temperature basis: the session's temperatures to about [-1, 1] (the model's
  // parameters below are in it; the calibration is rebased to powers of dT after the fit).
  TemperatureBasis basis = TemperatureBasis::Reference();
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

  void Gyro(const double* q, double* p) const {
    for (int i = 0; i < kGyroParameters; ++i) p[i] = gyro0[i];
    for (int c = 0; c < kGyroCoefficients; ++c) {
      for (int k = 0; k < kTerms; ++k)
        p[c * kPolynomialTerms + k] += gyro_step[c * kTerms + k] * q[c * kTerms + k];
    }
  }
  void Accel(const double* q, double* p) const {
    for (int i = 0; i < kAccelParameters; ++i) p[i] = accel0[i];
    for (int f = 0; f < kAccelFree; ++f) {
      const int c = kAccelFreeCoefficient[f];
      for (int k = 0; k < kTerms; ++k)
        p[c * kPolynomialTerms + k] += accel_step[f * kTerms + k] * q[f * kTerms + k];
    }
  }
  // The values at argument x of the coefficients a block holds (gyro: all kGyroCoefficients;
  // accel: the kAccelFree fitted), and d value / d q (`derivative`, one per q, may be null).
  void GyroAt(const double* q, double x, double* at, double* derivative) const {
    double p[kGyroParameters];
    Gyro(q, p);
    for (int c = 0; c < kGyroCoefficients; ++c) {
      at[c] = EvaluateTemperaturePolynomial(p + c * kPolynomialTerms, x);
      if (derivative == nullptr) continue;
      double power = 1.0;
      for (int k = 0; k < kTerms; ++k, power *= x)
        derivative[c * kTerms + k] = gyro_step[c * kTerms + k] * power;
    }
  }
  void AccelAt(const double* q, double x, double* at, double* derivative) const {
    double p[kAccelParameters];
    Accel(q, p);
    for (int f = 0; f < kAccelFree; ++f) {
      at[f] = EvaluateTemperaturePolynomial(p + kAccelFreeCoefficient[f] * kPolynomialTerms, x);
      if (derivative == nullptr) continue;
      double power = 1.0;
      for (int k = 0; k < kTerms; ++k, power *= x)
        derivative[f * kTerms + k] = accel_step[f * kTerms + k] * power;
    }
  }
};

// A sensor's coefficients from their values at one temperature (gyro: kGyroCoefficients values;
// accel: the kAccelFree fitted, the body frame's three misalignments 0).
template <typename T>
SensorCoefficients<T> GyroCoefficientsFromValues(const T* at) {
  T p[kGyroParameters];
  for (int i = 0; i < kGyroParameters; ++i) p[i] = T(0.0);
  for (int c = 0; c < kGyroCoefficients; ++c) p[c * kPolynomialTerms] = at[c];
  return CoefficientsAt(p, kGyroCoefficients, T(0.0));
}
template <typename T>
SensorCoefficients<T> AccelCoefficientsFromValues(const T* at) {
  T p[kAccelParameters];
  for (int i = 0; i < kAccelParameters; ++i) p[i] = T(0.0);
  for (int f = 0; f < FieldLayout::kAccelFree; ++f)
    p[FieldLayout::kAccelFreeCoefficient[f] * kPolynomialTerms] = at[f];
  return CoefficientsAt(p, kAccelCoefficients, T(0.0));
}

// A residual written in the coefficients' values at its temperature (blocks: gyro values
// [kGyroCoefficients] and/or accel values [kAccelFree], then blocks passed through), evaluated as
// a function of the solver's term blocks (kGyroBlock, kAccelBlock): value = sum_k (p0 + step q)_k
// x^k is linear in q, so the Jacobian is the inner one times step_k x^k. The autodiff Jets stay
// as small as a fit at one temperature.
class FieldTermsCost : public ceres::CostFunction {
 public:
  FieldTermsCost(const FieldLayout* layout, ceres::CostFunction* inner, bool gyro, bool accel, double x)
      : layout_(layout), inner_(inner), gyro_(gyro), accel_(accel), x_(x) {
    set_num_residuals(inner->num_residuals());
    const std::vector<int32_t>& sizes = inner->parameter_block_sizes();
    for (size_t b = 0; b < sizes.size(); ++b) {
      const bool is_gyro = gyro_ && b == 0;
      const bool is_accel = accel_ && b == (gyro_ ? 1u : 0u);
      mutable_parameter_block_sizes()->push_back(is_gyro    ? FieldLayout::kGyroBlock
                                                 : is_accel ? FieldLayout::kAccelBlock
                                                            : sizes[b]);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const size_t blocks = parameter_block_sizes().size();
    const int rows = num_residuals();
    double gyro_at[kGyroCoefficients];
    double accel_at[FieldLayout::kAccelFree];
    double gyro_d[FieldLayout::kGyroBlock];
    double accel_d[FieldLayout::kAccelBlock];
    std::vector<const double*> inner_parameters(parameters, parameters + blocks);
    size_t b = 0;
    if (gyro_) {
      layout_->GyroAt(parameters[b], x_, gyro_at, gyro_d);
      inner_parameters[b++] = gyro_at;
    }
    if (accel_) {
      layout_->AccelAt(parameters[b], x_, accel_at, accel_d);
      inner_parameters[b++] = accel_at;
    }
    if (jacobians == nullptr) return inner_->Evaluate(inner_parameters.data(), residuals, nullptr);
    std::vector<double> gyro_j(gyro_ ? rows * kGyroCoefficients : 0);
    std::vector<double> accel_j(accel_ ? rows * FieldLayout::kAccelFree : 0);
    std::vector<double*> inner_jacobians(jacobians, jacobians + blocks);
    b = 0;
    if (gyro_) {
      inner_jacobians[b] = jacobians[b] != nullptr ? gyro_j.data() : nullptr;
      ++b;
    }
    if (accel_) inner_jacobians[b] = jacobians[b] != nullptr ? accel_j.data() : nullptr;
    if (!inner_->Evaluate(inner_parameters.data(), residuals, inner_jacobians.data())) return false;
    b = 0;
    if (gyro_) Chain(gyro_j.data(), gyro_d, kGyroCoefficients, rows, jacobians[b++]);
    if (accel_) Chain(accel_j.data(), accel_d, FieldLayout::kAccelFree, rows, jacobians[b++]);
    return true;
  }

 private:
  // d r / d q[c, k] = d r / d value[c] * d value[c] / d q[c, k], row-major.
  static void Chain(const double* inner, const double* derivative, int values, int rows, double* out) {
    if (out == nullptr) return;
    constexpr int kTerms = FieldLayout::kTerms;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < values; ++c) {
        for (int k = 0; k < kTerms; ++k) {
          out[(r * values + c) * kTerms + k] = inner[r * values + c] * derivative[c * kTerms + k];
        }
      }
    }
  }

  const FieldLayout* layout_;
  std::unique_ptr<ceres::CostFunction> inner_;
  bool gyro_;
  bool accel_;
  double x_;
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
                     double gravity_mps2, const Eigen::Vector3d& sigma_raw)
      : layout_(layout),
        pose_(pose),
        accel_mean_(accel_mean),
        gravity_mps2_(gravity_mps2),
        inverse_sigma_(sigma_raw.cwiseInverse()) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const PoseDirection* pose,
                                     const Eigen::Vector3d& accel_mean, double x, double gravity_mps2,
                                     const Eigen::Vector3d& sigma_raw);

  template <typename T>
  bool operator()(const T* accel_at, const T* pose_q, T* residual) const {
    const SensorCoefficients<T> c = AccelCoefficientsFromValues(accel_at);
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
  double gravity_mps2_;
  Eigen::Vector3d inverse_sigma_;
};

// The gyro at rest: K_g omega_hat / sigma_raw, omega_hat = CorrectWith(the pose's means), whose
// g-sensitivity term uses the pose's corrected specific force. Blocks: gyro, accel.
class FieldPoseGyroCost {
 public:
  FieldPoseGyroCost(const FieldLayout* layout, const Eigen::Vector3d& gyro_mean,
                    const Eigen::Vector3d& accel_mean, const Eigen::Vector3d& sigma_raw)
      : layout_(layout),
        gyro_mean_(gyro_mean),
        accel_mean_(accel_mean),
        inverse_sigma_(sigma_raw.cwiseInverse()) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const Eigen::Vector3d& gyro_mean,
                                     const Eigen::Vector3d& accel_mean, double x,
                                     const Eigen::Vector3d& sigma_raw);

  template <typename T>
  bool operator()(const T* gyro_at, const T* accel_at, T* residual) const {
    const UnitCoefficients<T> c{GyroCoefficientsFromValues(gyro_at), AccelCoefficientsFromValues(accel_at)};
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
                std::vector<TurnSample> samples, double sigma_rad)
      : layout_(layout),
        from_(from),
        to_(to),
        samples_(std::move(samples)),
        times_s_(TurnTimes(samples_)),
        inverse_sigma_(1.0 / sigma_rad) {}

  static ceres::CostFunction* Create(const FieldLayout* layout, const PoseDirection* from,
                                     const PoseDirection* to, std::vector<TurnSample> samples, double x,
                                     double sigma_rad);

  template <typename T>
  bool operator()(const T* gyro_at, const T* accel_at, const T* from_q, const T* to_q, T* residual) const {
    const UnitCoefficients<T> c{GyroCoefficientsFromValues(gyro_at), AccelCoefficientsFromValues(accel_at)};
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
  double inverse_sigma_;
};

}  // namespace imufit

#endif  // IMUFIT_FIT_SRC_FIELD_COST_H_
