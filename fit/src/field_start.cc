// The field fit's start in closed form (field_start.h).
#include "field_start.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace imufit {
namespace {

// Coefficient i of a sensor's parameters, term c0.
double& C0(std::array<double, kGyroParameters>& p, int i) { return p[i * kPolynomialTerms]; }
double& C0(std::array<double, kAccelParameters>& p, int i) { return p[i * kPolynomialTerms]; }

// Stage 1: bias and scale of the accelerometer from the axis-aligned ellipsoid through the poses
// (raw means less their centroid, divided by their mean distance from it, for conditioning: raw
// counts of an unsigned converter sit around 32768, far from zero, where A^2 and A are nearly
// collinear). False when the poses do not make an ellipsoid (a negative axis), leaving the model as
// it was.
bool AccelEllipsoid(const std::vector<FieldPose>& poses, double gravity_mps2, SensorModel* model) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const FieldPose& pose : poses) centroid += pose.accel_mean;
  centroid /= static_cast<double>(poses.size());
  double length = 0.0;
  for (const FieldPose& pose : poses) length += (pose.accel_mean - centroid).norm();
  length /= static_cast<double>(poses.size());
  if (!(length > 0.0)) return false;
  Eigen::MatrixXd design(poses.size(), 6);
  for (size_t p = 0; p < poses.size(); ++p) {
    const Eigen::Vector3d a = (poses[p].accel_mean - centroid) / length;
    design.row(p) << a.x() * a.x(), a.y() * a.y(), a.z() * a.z(), a.x(), a.y(), a.z();
  }
  const Eigen::VectorXd theta = design.colPivHouseholderQr().solve(Eigen::VectorXd::Ones(poses.size()));
  double r = 1.0;
  for (int i = 0; i < 3; ++i) {
    if (!(theta(i) > 0.0)) return false;
    r += theta(3 + i) * theta(3 + i) / (4.0 * theta(i));
  }
  for (int i = 0; i < 3; ++i) {
    C0(model->accel, kBiasCoefficient + i) = centroid(i) - length * theta(3 + i) / (2.0 * theta(i));
    C0(model->accel, kScaleCoefficient + i) = length * std::sqrt(r / theta(i)) / gravity_mps2;
  }
  return true;
}

// Stage 2: B_p = V + H a_hat_p over the poses (V alone without H).
void GyroBiasAndGSensitivity(const std::vector<FieldPose>& poses, bool fit_g_sensitivity,
                             SensorModel* model) {
  const UnitCoefficients<double> c = model->CoefficientsAtTemperature(25.0);
  const int unknowns = fit_g_sensitivity ? 4 : 1;
  Eigen::MatrixXd design(poses.size(), unknowns);
  Eigen::MatrixXd observed(poses.size(), 3);
  for (size_t p = 0; p < poses.size(); ++p) {
    const Eigen::Vector3d a_hat = CorrectSensor(c.accel, poses[p].accel_mean, Eigen::Vector3d::Zero().eval());
    design(p, 0) = 1.0;
    if (fit_g_sensitivity) design.block<1, 3>(p, 1) = a_hat.transpose();
    observed.row(p) = poses[p].gyro_mean.transpose();
  }
  const Eigen::MatrixXd solution = design.colPivHouseholderQr().solve(observed);  // unknowns x 3
  for (int axis = 0; axis < 3; ++axis) {
    C0(model->gyro, kBiasCoefficient + axis) = solution(0, axis);
    if (!fit_g_sensitivity) continue;
    for (int column = 0; column < 3; ++column) {
      C0(model->gyro, kGSensitivityCoefficient + 3 * axis + column) = solution(1 + column, axis);
    }
  }
}

// The sum over the turns of |R^T u_from - u_to|^2 for a model.
double TurnMismatch(const SensorModel& model, const std::vector<FieldPose>& poses,
                    const std::vector<FieldTurn>& turns,
                    const std::vector<std::vector<TurnSample>>& turn_samples) {
  double sum = 0.0;
  for (size_t t = 0; t < turns.size(); ++t) {
    const UnitCoefficients<double> c = model.CoefficientsAtTemperature(poses[turns[t].from].temp_c);
    const auto up = [&](int pose) {
      return CorrectSensor(c.accel, poses[pose].accel_mean, Eigen::Vector3d::Zero().eval()).normalized();
    };
    const Eigen::Vector3d predicted = RotateIntoCurrentFrame(
        IntegrateTurn(c, turn_samples[t], TurnTimes(turn_samples[t])), up(turns[t].from));
    sum += (predicted - up(turns[t].to)).squaredNorm();
  }
  return sum;
}

// Stage 3: one gyro scale for every axis, scanned on a logarithmic grid, then refined by golden
// section between the neighbours of the best grid point.
void GyroScale(const std::vector<FieldPose>& poses, const std::vector<FieldTurn>& turns,
               const std::vector<std::vector<TurnSample>>& turn_samples, SensorModel* model) {
  const Eigen::Vector3d bias(C0(model->gyro, kBiasCoefficient), C0(model->gyro, kBiasCoefficient + 1),
                             C0(model->gyro, kBiasCoefficient + 2));
  double largest_raw = 0.0;
  for (const std::vector<TurnSample>& samples : turn_samples) {
    for (const TurnSample& s : samples) largest_raw = std::max(largest_raw, (s.gyro - bias).norm());
  }
  if (!(largest_raw > 0.0)) return;
  const auto mismatch_at = [&](double log_scale) {
    SensorModel trial = *model;
    for (int axis = 0; axis < 3; ++axis) C0(trial.gyro, kScaleCoefficient + axis) = std::exp(log_scale);
    return TurnMismatch(trial, poses, turns, turn_samples);
  };
  constexpr double kSlowestPeakRadps = 0.2;
  constexpr double kFastestPeakRadps = 30.0;
  // Grid points over the 150:1 range of scales: 6.5 % apart, far inside the basin of the true
  // scale (a hand turn's angle is off by a whole turn only at a scale error of order 1), and each
  // point integrates every turn, so the grid is what the start costs.
  constexpr int kGrid = 80;
  const double low = std::log(largest_raw / kFastestPeakRadps);
  const double high = std::log(largest_raw / kSlowestPeakRadps);
  const double step = (high - low) / kGrid;
  int best = 0;
  double best_mismatch = mismatch_at(low);
  for (int i = 1; i <= kGrid; ++i) {
    const double m = mismatch_at(low + step * i);
    if (m < best_mismatch) {
      best_mismatch = m;
      best = i;
    }
  }
  // Golden section between the best point's neighbours, one new evaluation per iteration, to a
  // bracket of 1e-7 in the logarithm of the scale (the solver refines it from there).
  double a = low + step * (best - 1);
  double b = low + step * (best + 1);
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double c = b - ratio * (b - a);
  double d = a + ratio * (b - a);
  double mismatch_c = mismatch_at(c);
  double mismatch_d = mismatch_at(d);
  constexpr double kLogScaleBracket = 1e-7;
  while (b - a > kLogScaleBracket) {
    if (mismatch_c < mismatch_d) {
      b = d, d = c, mismatch_d = mismatch_c;
      c = b - ratio * (b - a);
      mismatch_c = mismatch_at(c);
    } else {
      a = c, c = d, mismatch_c = mismatch_d;
      d = a + ratio * (b - a);
      mismatch_d = mismatch_at(d);
    }
  }
  for (int axis = 0; axis < 3; ++axis) C0(model->gyro, kScaleCoefficient + axis) = std::exp(0.5 * (a + b));
}

}  // namespace

std::vector<TurnSample> TurnSamples(const std::vector<Sample>& samples, const FieldTurn& turn) {
  std::vector<TurnSample> out;
  out.reserve(static_cast<size_t>(turn.last - turn.first + 1));
  for (long long i = turn.first; i <= turn.last; ++i) {
    const double step_s = i == turn.first ? 0.0 : samples[i].time_s - samples[i - 1].time_s;
    out.push_back({step_s, samples[i].gyro, samples[i].accel});
  }
  return out;
}

std::vector<TurnSample> DecimatedTurn(const std::vector<TurnSample>& samples, double max_rate_hz) {
  const std::vector<double> times_s = TurnTimes(samples);
  const double duration_s = times_s.back();
  const size_t count = samples.size();
  const size_t block =
      count > 2 && duration_s > 0.0
          ? static_cast<size_t>(std::ceil(static_cast<double>(count - 1) / duration_s / max_rate_hz))
          : 1;
  if (block <= 1) return samples;
  std::vector<TurnSample> out = {samples.front()};
  double last_time_s = 0.0;
  for (size_t first = 1; first + 1 < count; first += block) {
    const size_t end = std::min(first + block, count - 1);
    TurnSample mean;
    double time_s = 0.0;
    for (size_t k = first; k < end; ++k) {
      mean.gyro += samples[k].gyro;
      mean.accel += samples[k].accel;
      time_s += times_s[k];
    }
    const double n = static_cast<double>(end - first);
    mean.gyro /= n;
    mean.accel /= n;
    mean.step_s = time_s / n - last_time_s;
    last_time_s = time_s / n;
    out.push_back(mean);
  }
  TurnSample last = samples.back();
  last.step_s = duration_s - last_time_s;
  out.push_back(last);
  return out;
}

double TurnNoiseWeightS(const std::vector<TurnSample>& samples) {
  double sum = 0.0;
  for (size_t k = 0; k < samples.size(); ++k) {
    const double before = k > 0 ? samples[k].step_s : 0.0;
    const double after = k + 1 < samples.size() ? samples[k + 1].step_s : 0.0;
    sum += 0.25 * (before + after) * (before + after);
  }
  return std::sqrt(sum);
}

SensorModel FieldStart(const std::vector<FieldPose>& poses, const std::vector<FieldTurn>& turns,
                       const std::vector<std::vector<TurnSample>>& turn_samples,
                       const FieldFitOptions& options) {
  SensorModel model = SensorModel::Identity();
  if (!AccelEllipsoid(poses, options.gravity_mps2, &model)) {
    double length = 0.0;
    for (const FieldPose& pose : poses) length += pose.accel_mean.norm();
    for (int axis = 0; axis < 3; ++axis) {
      C0(model.accel, kScaleCoefficient + axis) =
          length / static_cast<double>(poses.size()) / options.gravity_mps2;
    }
  }
  GyroBiasAndGSensitivity(poses, options.fit_g_sensitivity, &model);
  GyroScale(poses, turns, turn_samples, &model);
  return model;
}

}  // namespace imufit
