// The field fit (field_fit.h): what the session determines, the Ceres problem, its covariance.
#include "imufit/fit/field_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <ceres/ceres.h>
#include <Eigen/Dense>

#include "field_cost.h"
#include "field_start.h"
#include "imufit/base/option_table.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

std::string Format(const char* format, double a, double b = 0.0) {
  char text[160];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

// The session's poses in each of the six directions, and the turns about each gyro axis, judged on
// the start (field_fit.h, step 5): the findings in plain words.
std::vector<std::string> CoverageProblems(const std::vector<FieldPose>& poses,
                                          const std::vector<FieldTurn>& turns,
                                          const std::vector<std::vector<TurnSample>>& turn_samples,
                                          const SensorModel& start, const FieldFitOptions& options) {
  std::vector<std::string> problems;
  const UnitCoefficients<double> c = start.CoefficientsAtTemperature(25.0);
  std::vector<Eigen::Vector3d> ups;
  for (const FieldPose& pose : poses) {
    ups.push_back(CorrectSensor(c.accel, pose.accel_mean, Eigen::Vector3d::Zero().eval()).normalized());
  }
  const char* axes = "xyz";
  const double near = std::cos(options.near_direction_deg * kDegToRad);
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      double best = -1.0;
      for (const Eigen::Vector3d& up : ups) best = std::max(best, sign * up(axis));
      if (best >= near) continue;
      // `up` along +axis: gravity points along -axis and the axis points up.
      problems.push_back(std::string("no pose with gravity near ") + (sign > 0 ? "-" : "+") + axes[axis] +
                         " (the " + axes[axis] + " axis " + (sign > 0 ? "up" : "down") + ")");
    }
  }
  // Gravity moved by turns about each gyro axis: |integrated rate about it| times the sine of
  // gravity's angle to it, summed over the turns.
  Eigen::Vector3d moved = Eigen::Vector3d::Zero();
  for (size_t t = 0; t < turns.size(); ++t) {
    Eigen::Vector3d angle = Eigen::Vector3d::Zero();
    Eigen::Vector3d omega_before;
    Eigen::Vector3d a_hat;
    const std::vector<TurnSample>& samples = turn_samples[t];
    CorrectWith(c, samples[0].gyro, samples[0].accel, &omega_before, &a_hat);
    for (size_t k = 1; k < samples.size(); ++k) {
      Eigen::Vector3d omega;
      CorrectWith(c, samples[k].gyro, samples[k].accel, &omega, &a_hat);
      angle += 0.5 * (omega_before + omega) * samples[k].step_s;
      omega_before = omega;
    }
    const Eigen::Vector3d up = (ups[turns[t].from] + ups[turns[t].to]).normalized();
    for (int axis = 0; axis < 3; ++axis) {
      moved(axis) += std::abs(angle(axis)) * up.cross(Eigen::Vector3d::Unit(axis)).norm();
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (moved(axis) >= options.min_turn_about_axis_rad) continue;
    problems.push_back(std::string("turns about ") + axes[axis] + " too small to fix the gyro's " +
                       axes[axis] + " scale" +
                       Format(" (they moved gravity by %.2f rad about it; needs %.2f)", moved(axis),
                              options.min_turn_about_axis_rad));
  }
  return problems;
}

// The Ceres problem's parameters and what they mean.
struct FieldProblem {
  FieldLayout layout;
  std::vector<PoseDirection> directions;  // one per pose (addresses held by the costs: never resized)
  std::array<double, FieldLayout::kGyroBlock> gyro_q{};
  std::array<double, FieldLayout::kAccelBlock> accel_q{};
  std::vector<std::array<double, 2>> pose_q;
  ceres::Problem problem;
  // The residual blocks of each group (FieldLayout::kAccelGroup, kGyroGroup, kTurnGroup).
  std::array<std::vector<ceres::ResidualBlockId>, 3> groups;

  // The model at the current q.
  SensorModel Model() const {
    SensorModel model;
    layout.Gyro(gyro_q.data(), model.gyro.data());
    layout.Accel(accel_q.data(), model.accel.data());
    return model;
  }
  // Every parameter block in the Jacobian's column order.
  std::vector<double*> Blocks() {
    std::vector<double*> blocks = {gyro_q.data(), accel_q.data()};
    for (std::array<double, 2>& q : pose_q) blocks.push_back(q.data());
    return blocks;
  }
};

// The solver's steps: magnitudes of each parameter, so that every q is O(1) (window_cost.h).
void SetSteps(const SensorModel& start, FieldLayout* layout) {
  layout->gyro0 = start.gyro;
  layout->accel0 = start.accel;
  const auto c0 = [](const auto& p, int i) { return std::abs(p[i * kPolynomialTerms]); };
  const double gyro_scale = (c0(start.gyro, 3) + c0(start.gyro, 4) + c0(start.gyro, 5)) / 3.0;
  const double accel_scale = (c0(start.accel, 3) + c0(start.accel, 4) + c0(start.accel, 5)) / 3.0;
  for (int c = 0; c < kGyroCoefficients; ++c) {
    const double step = c < kScaleCoefficient          ? 1e-3 * gyro_scale   // 1 mrad/s of bias
                        : c < kMisalignmentCoefficient ? 1e-3 * gyro_scale   // 0.1 % of scale
                        : c < kGSensitivityCoefficient ? 1e-3                // 1 mrad
                                                       : 1e-4 * gyro_scale;  // 0.1 mrad/s per m/s^2
    for (int k = 0; k < FieldLayout::kTerms; ++k) layout->gyro_step[c * FieldLayout::kTerms + k] = step;
  }
  for (int f = 0; f < FieldLayout::kAccelFree; ++f) {
    const int c = FieldLayout::kAccelFreeCoefficient[f];
    const double step = c < kScaleCoefficient          ? 1e-2 * accel_scale
                        : c < kMisalignmentCoefficient ? 1e-3 * accel_scale
                                                       : 1e-3;
    for (int k = 0; k < FieldLayout::kTerms; ++k) layout->accel_step[f * FieldLayout::kTerms + k] = step;
  }
}

// The residuals of field_fit.h step 3, one block each per pose and per turn.
void BuildProblem(const std::vector<FieldPose>& poses, const std::vector<FieldTurn>& turns,
                  std::vector<std::vector<TurnSample>> turn_samples,
                  const std::vector<double>& turn_noise_weight_s, const FieldFitSummary& summary,
                  const SensorModel& start, const FieldFitOptions& options, FieldProblem* fp) {
  SetSteps(start, &fp->layout);
  const UnitCoefficients<double> c = start.CoefficientsAtTemperature(25.0);
  fp->directions.reserve(poses.size());
  fp->pose_q.assign(poses.size(), {0.0, 0.0});
  const TemperatureBasis basis = TemperatureBasis::Reference();
  for (size_t p = 0; p < poses.size(); ++p) {
    const double n = static_cast<double>(poses[p].last - poses[p].first + 1);
    fp->directions.emplace_back(CorrectSensor(c.accel, poses[p].accel_mean, Eigen::Vector3d::Zero().eval()));
    const double x = basis.Argument(poses[p].temp_c);
    fp->groups[FieldLayout::kAccelGroup].push_back(fp->problem.AddResidualBlock(
        FieldPoseAccelCost::Create(&fp->layout, &fp->directions[p], poses[p].accel_mean, x,
                                   options.gravity_mps2, summary.accel_noise_raw / std::sqrt(n)),
        nullptr, fp->accel_q.data(), fp->pose_q[p].data()));
    fp->groups[FieldLayout::kGyroGroup].push_back(fp->problem.AddResidualBlock(
        FieldPoseGyroCost::Create(&fp->layout, poses[p].gyro_mean, poses[p].accel_mean, x,
                                  summary.gyro_noise_raw / std::sqrt(n)),
        nullptr, fp->gyro_q.data(), fp->accel_q.data()));
  }
  // The gyro's white noise in rad/s (at the start's scales), integrated over a turn: the angle's
  // random walk, per axis perpendicular to gravity.
  const Eigen::Vector3d gyro_noise_radps = summary.gyro_noise_raw.cwiseQuotient(c.gyro.scale.cwiseAbs());
  const double noise_radps = std::sqrt(gyro_noise_radps.squaredNorm() / 3.0);
  for (size_t t = 0; t < turns.size(); ++t) {
    const double temp_c = 0.5 * (poses[turns[t].from].temp_c + poses[turns[t].to].temp_c);
    const double sigma_rad = noise_radps * turn_noise_weight_s[t];
    fp->groups[FieldLayout::kTurnGroup].push_back(fp->problem.AddResidualBlock(
        FieldTurnCost::Create(&fp->layout, &fp->directions[turns[t].from], &fp->directions[turns[t].to],
                              std::move(turn_samples[t]), basis.Argument(temp_c), std::max(sigma_rad, 1e-12)),
        nullptr, fp->gyro_q.data(), fp->accel_q.data(), fp->pose_q[turns[t].from].data(),
        fp->pose_q[turns[t].to].data()));
  }
  if (!options.fit_g_sensitivity) {
    std::vector<int> held;
    for (int h = 0; h < 9; ++h) {
      for (int k = 0; k < FieldLayout::kTerms; ++k)
        held.push_back((kGSensitivityCoefficient + h) * FieldLayout::kTerms + k);
    }
    fp->problem.SetManifold(fp->gyro_q.data(), new ceres::SubsetManifold(FieldLayout::kGyroBlock, held));
  }
}

// The name of the model parameter behind Jacobian column `column` (Blocks() order, H columns
// absent when not fitted), e.g. "gyro scale z", or "the direction of pose 4".
std::string ColumnName(int column, bool fit_g_sensitivity) {
  const int gyro_columns =
      fit_g_sensitivity ? FieldLayout::kGyroBlock : FieldLayout::kGyroBlock - 9 * FieldLayout::kTerms;
  if (column < gyro_columns) {
    const CoefficientName& name = kCoefficientNames[column / FieldLayout::kTerms];
    return std::string("gyro ") + name.group + " " + name.axis;
  }
  column -= gyro_columns;
  if (column < FieldLayout::kAccelBlock) {
    const CoefficientName& name =
        kCoefficientNames[FieldLayout::kAccelFreeCoefficient[column / FieldLayout::kTerms]];
    return std::string("accel ") + name.group + " " + name.axis;
  }
  return "the direction of pose " + std::to_string((column - FieldLayout::kAccelBlock) / 2 + 1);
}

// The residuals and their Jacobian at the current q, dense, rows in group order (accel, gyro,
// turns), columns in the solver's q (tangent) order; `group_rows` the first row of each group and
// the end.
Eigen::MatrixXd Jacobian(FieldProblem* fp, Eigen::VectorXd* residuals, std::array<int, 4>* group_rows) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = fp->Blocks();
  (*group_rows)[0] = 0;
  for (int g = 0; g < 3; ++g) {
    evaluate.residual_blocks.insert(evaluate.residual_blocks.end(), fp->groups[g].begin(),
                                    fp->groups[g].end());
    int rows = 0;
    for (const ceres::ResidualBlockId id : fp->groups[g])
      rows += fp->problem.GetCostFunctionForResidualBlock(id)->num_residuals();
    (*group_rows)[g + 1] = (*group_rows)[g] + rows;
  }
  std::vector<double> r;
  ceres::CRSMatrix crs;
  fp->problem.Evaluate(evaluate, nullptr, &r, nullptr, &crs);
  IMUFIT_CHECK(crs.num_rows == (*group_rows)[3], "one Jacobian row per residual");
  *residuals = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int i = crs.rows[row]; i < crs.rows[row + 1]; ++i) jacobian(row, crs.cols[i]) = crs.values[i];
  }
  return jacobian;
}

// Each group's residuals against its share of the redundancy: s^2 = sum r^2 / sum (1 - h_ii), h_ii
// the leverage of residual i (J C J^T), which is the variance-component estimate of the group's
// noise as a multiple of the one assumed. Multiplies layout->noise_scale of every group whose s^2
// exceeds 1 beyond chance (1 + 3 sqrt(2 / its redundancy)) by s; returns whether any did. A hand
// session's rests hold tremor and its turns more than white noise; a simulated one holds neither.
bool NoiseScales(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                 const Eigen::MatrixXd& covariance, const std::array<int, 4>& group_rows,
                 FieldLayout* layout) {
  bool changed = false;
  for (int g = 0; g < 3; ++g) {
    double sum_r2 = 0.0;
    double redundancy = 0.0;
    for (int i = group_rows[g]; i < group_rows[g + 1]; ++i) {
      sum_r2 += residuals(i) * residuals(i);
      redundancy += 1.0 - jacobian.row(i).dot(covariance * jacobian.row(i).transpose());
    }
    if (!(redundancy > 0.5)) continue;  // a group its parameters fit exactly tells nothing
    const double s2 = sum_r2 / redundancy;
    if (s2 > 1.0 + 3.0 * std::sqrt(2.0 / redundancy)) {
      layout->noise_scale[g] *= std::sqrt(s2);
      changed = true;
    }
  }
  return changed;
}

// Step 5: the covariance (J^T J)^-1 in q, or the parameter a direction without information moves
// most (then `covariance` is untouched and the name returned).
std::string Covariance(const Eigen::MatrixXd& jacobian, bool fit_g_sensitivity, Eigen::MatrixXd* covariance) {
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  const Eigen::VectorXd diagonal = information.diagonal();
  for (int i = 0; i < diagonal.size(); ++i) {
    if (!(diagonal(i) > 0.0)) return ColumnName(i, fit_g_sensitivity);
  }
  const Eigen::VectorXd d = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = d.asDiagonal() * information * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  constexpr double kRankTolerance = 1e-12;  // relative to the largest eigenvalue (Jacobi-scaled)
  if (!(eigen.eigenvalues()(0) > kRankTolerance * eigen.eigenvalues().maxCoeff())) {
    Eigen::Index largest = 0;
    eigen.eigenvectors().col(0).cwiseAbs().maxCoeff(&largest);
    return ColumnName(static_cast<int>(largest), fit_g_sensitivity);
  }
  *covariance = d.asDiagonal() *
                (eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                 eigen.eigenvectors().transpose()) *
                d.asDiagonal();
  return "";
}

// The 1-sigma of every model parameter from the covariance in q (0 for a held term).
SensorModel Sigmas(const Eigen::MatrixXd& covariance, const FieldLayout& layout, bool fit_g_sensitivity) {
  SensorModel sigma{};
  sigma.basis = TemperatureBasis::Reference();
  int column = 0;
  for (int c = 0; c < kGyroCoefficients; ++c) {
    const bool held = !fit_g_sensitivity && c >= kGSensitivityCoefficient;
    for (int k = 0; k < FieldLayout::kTerms; ++k) {
      if (held) continue;
      const int q = c * FieldLayout::kTerms + k;
      sigma.gyro[c * kPolynomialTerms + k] = layout.gyro_step[q] * std::sqrt(covariance(column, column));
      ++column;
    }
  }
  for (int f = 0; f < FieldLayout::kAccelFree; ++f) {
    for (int k = 0; k < FieldLayout::kTerms; ++k, ++column) {
      sigma.accel[FieldLayout::kAccelFreeCoefficient[f] * kPolynomialTerms + k] =
          layout.accel_step[f * FieldLayout::kTerms + k] * std::sqrt(covariance(column, column));
    }
  }
  return sigma;
}

// Coefficients the session fixes too loosely to be of use, in plain words.
std::vector<std::string> LooseCoefficients(const SensorModel& model, const SensorModel& sigma,
                                           const FieldFitOptions& options) {
  std::vector<std::string> loose;
  const char* axes = "xyz";
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (kScaleCoefficient + axis) * kPolynomialTerms;
    if (sigma.gyro[i] > options.max_relative_scale_sigma * std::abs(model.gyro[i])) {
      loose.push_back(std::string("turns about ") + axes[axis] + " too small to fix the gyro's " +
                      axes[axis] + " scale" +
                      Format(" (1 sigma %.2g %%)", 100.0 * sigma.gyro[i] / std::abs(model.gyro[i])));
    }
    if (sigma.accel[i] > options.max_relative_scale_sigma * std::abs(model.accel[i])) {
      loose.push_back(std::string("poses too few or too close together to fix the accelerometer's ") +
                      axes[axis] + " scale" +
                      Format(" (1 sigma %.2g %%)", 100.0 * sigma.accel[i] / std::abs(model.accel[i])));
    }
  }
  for (int m = 0; m < 6; ++m) {
    const int c = kMisalignmentCoefficient + m;
    const int i = c * kPolynomialTerms;
    if (sigma.gyro[i] > options.max_misalignment_sigma_rad) {
      loose.push_back(std::string("turns too few or too small to fix the gyro's misalignment ") +
                      kCoefficientNames[c].axis + Format(" (1 sigma %.2g mrad)", 1e3 * sigma.gyro[i]));
    }
    if (sigma.accel[i] > options.max_misalignment_sigma_rad) {
      loose.push_back(
          std::string("poses too few or too close together to fix the accelerometer's misalignment ") +
          kCoefficientNames[c].axis + Format(" (1 sigma %.2g mrad)", 1e3 * sigma.accel[i]));
    }
  }
  return loose;
}

// The residuals in physical units after the fit, and each pose's and turn's own figures.
void Residuals(const FieldProblem& fp, const std::vector<std::vector<TurnSample>>& turn_samples,
               const FieldFitOptions& options, FieldFitSummary* summary) {
  const UnitCoefficients<double> c = summary->model.CoefficientsAtTemperature(25.0);
  double accel_sum = 0.0;
  double gyro_sum = 0.0;
  for (size_t p = 0; p < summary->poses.size(); ++p) {
    FieldPose& pose = summary->poses[p];
    Eigen::Vector3d omega_hat;
    Eigen::Vector3d a_hat;
    CorrectWith(c, pose.gyro_mean, pose.accel_mean, &omega_hat, &a_hat);
    pose.up = fp.directions[p].At(fp.pose_q[p].data());
    pose.accel_norm_error_mps2 = a_hat.norm() - options.gravity_mps2;
    accel_sum += pose.accel_norm_error_mps2 * pose.accel_norm_error_mps2;
    gyro_sum += omega_hat.squaredNorm();
  }
  double direction_sum = 0.0;
  int fitted_turns = 0;
  for (size_t t = 0; t < summary->turns.size(); ++t) {
    FieldTurn& turn = summary->turns[t];
    const auto up_of = [&](int pose) {
      Eigen::Vector3d omega_hat;
      Eigen::Vector3d a_hat;
      CorrectWith(c, summary->poses[pose].gyro_mean, summary->poses[pose].accel_mean, &omega_hat, &a_hat);
      return a_hat.normalized().eval();
    };
    const Eigen::Vector3d from = up_of(turn.from);
    const Eigen::Vector3d to = up_of(turn.to);
    const Eigen::Vector3d predicted =
        RotateIntoCurrentFrame(IntegrateTurn(c, turn_samples[t], TurnTimes(turn_samples[t])), from);
    turn.angle_rad = std::atan2(from.cross(to).norm(), from.dot(to));
    turn.direction_error_rad = std::atan2(predicted.cross(to).norm(), predicted.dot(to));
    if (turn.saturated) continue;
    direction_sum += turn.direction_error_rad * turn.direction_error_rad;
    ++fitted_turns;
  }
  const double poses = static_cast<double>(summary->poses.size());
  summary->accel_norm_rms_mps2 = std::sqrt(accel_sum / poses);
  summary->gyro_static_rms_radps = std::sqrt(gyro_sum / (3.0 * poses));
  summary->direction_rms_rad = fitted_turns == 0 ? 0.0 : std::sqrt(direction_sum / fitted_turns);
}

// The turns' samples: of every turn (for the residuals), and of the turns the fit uses (not
// saturated) at most kTurnFitRateHz, with their angle noise weights from every sample.
struct TurnSets {
  std::vector<std::vector<TurnSample>> all_samples;
  std::vector<FieldTurn> fitted;
  std::vector<std::vector<TurnSample>> fitted_samples;
  std::vector<double> fitted_noise_weight_s;
};
TurnSets SplitTurns(const std::vector<Sample>& samples, const std::vector<FieldTurn>& turns) {
  TurnSets sets;
  for (const FieldTurn& turn : turns) {
    sets.all_samples.push_back(TurnSamples(samples, turn));
    if (turn.saturated) continue;
    sets.fitted.push_back(turn);
    sets.fitted_samples.push_back(DecimatedTurn(sets.all_samples.back(), kTurnFitRateHz));
    sets.fitted_noise_weight_s.push_back(TurnNoiseWeightS(sets.all_samples.back()));
  }
  return sets;
}

// Solves; while a group's residuals exceed its noise beyond chance, scales that noise and solves
// again (NoiseScales), so that the covariance describes the session's actual scatter. Sets the
// summary's iterations, termination, noise scales and reduced chi-square; false (with the status
// set) when the solver fails or the problem has a direction without information.
bool Solve(const FieldFitOptions& options, FieldProblem* fp, FieldFitSummary* summary,
           Eigen::MatrixXd* covariance) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-14;
  solver.num_threads = 1;
  constexpr int kMaxNoisePasses = 4;
  summary->iterations = 0;
  for (int pass = 0; pass < kMaxNoisePasses; ++pass) {
    ceres::Solver::Summary solved;
    ceres::Solve(solver, &fp->problem, &solved);
    summary->iterations += static_cast<int>(solved.iterations.size());
    summary->termination = solved.message;
    if (!solved.IsSolutionUsable()) {
      summary->status = FieldFitStatus::kFailed;
      return false;
    }
    Eigen::VectorXd residuals;
    std::array<int, 4> group_rows{};
    const Eigen::MatrixXd jacobian = Jacobian(fp, &residuals, &group_rows);
    if (const std::string missing = Covariance(jacobian, options.fit_g_sensitivity, covariance);
        !missing.empty()) {
      summary->status = FieldFitStatus::kUndetermined;
      summary->undetermined.push_back("the session holds no information on the " + missing);
      return false;
    }
    const double dof = static_cast<double>(jacobian.rows() - jacobian.cols());
    summary->reduced_chi2 = dof > 0 ? 2.0 * solved.final_cost / dof : 0.0;
    summary->noise_scale = fp->layout.noise_scale;
    if (!NoiseScales(jacobian, residuals, *covariance, group_rows, &fp->layout)) break;
  }
  return true;
}

bool AllFinite(const SensorModel& m) {
  return std::all_of(m.gyro.begin(), m.gyro.end(), [](double v) { return std::isfinite(v); }) &&
         std::all_of(m.accel.begin(), m.accel.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

PoseDirection::PoseDirection(const Eigen::Vector3d& up) : u0(up.normalized()) {
  const Eigen::Vector3d trial = std::abs(u0.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = u0.cross(trial).normalized();
  e2 = u0.cross(e1);
}

std::string FieldFitSummary::BriefReport() const {
  const int saturated = static_cast<int>(
      std::count_if(turns.begin(), turns.end(), [](const FieldTurn& t) { return t.saturated; }));
  const std::string counts =
      std::to_string(poses.size()) + " poses, " + std::to_string(turns.size()) + " turns" +
      (saturated > 0 ? " (" + std::to_string(saturated) + " saturated, left out)" : "");
  switch (status) {
    case FieldFitStatus::kNotRun:
      return "not run";
    case FieldFitStatus::kUndetermined: {
      std::string text = "the session does not determine the model (" + counts + "): ";
      for (size_t i = 0; i < undetermined.size(); ++i) text += (i > 0 ? "; " : "") + undetermined[i];
      return text;
    }
    case FieldFitStatus::kFailed:
      return "the fit did not converge (" + counts + "): " + termination;
    case FieldFitStatus::kConverged:
      break;
  }
  return "converged (" + counts + ", " + std::to_string(iterations) + " iterations): |a| - g RMS " +
         Format("%.3g mg", accel_norm_rms_mps2 / kStandardGravityMps2 * 1e3) + ", gravity after the turns " +
         Format("%.3g deg RMS", direction_rms_rad * kRadToDeg) +
         Format(", reduced chi-square %.3g", reduced_chi2) +
         (noise_scale[0] > 1.0 || noise_scale[1] > 1.0 || noise_scale[2] > 1.0
              ? Format("; noise beyond the log's white noise: rests x%.3g accel, ", noise_scale[0],
                       noise_scale[1]) +
                    Format("x%.3g gyro, turns x%.3g", noise_scale[1], noise_scale[2])
              : "");
}

FieldFitSummary FitField(const std::vector<Sample>& samples, const FieldFitOptions& options) {
  IMUFIT_CHECK(options.Validate().empty(), "FieldFitOptions::Validate() first");
  FieldFitSummary summary;
  FindFieldPoses(samples, options, &summary.poses, &summary.turns, &summary.gyro_noise_raw,
                 &summary.accel_noise_raw);
  if (!samples.empty()) {
    const auto [low, high] = std::minmax_element(
        samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.temp_c < b.temp_c; });
    summary.temp_range_c = {low->temp_c, high->temp_c};
  }
  if (static_cast<int>(summary.poses.size()) < options.min_poses) {
    summary.status = FieldFitStatus::kUndetermined;
    summary.undetermined.push_back(
        "found " + std::to_string(summary.poses.size()) + " poses at rest, needs at least " +
        std::to_string(options.min_poses) +
        Format(" (rest %.3g s or longer in each)", options.min_pose_s + options.detection.window_s));
    return summary;
  }
  TurnSets turns = SplitTurns(samples, summary.turns);
  const SensorModel start = FieldStart(summary.poses, turns.fitted, turns.fitted_samples, options);
  summary.undetermined = CoverageProblems(summary.poses, turns.fitted, turns.fitted_samples, start, options);
  if (!summary.undetermined.empty()) {
    summary.status = FieldFitStatus::kUndetermined;
    return summary;
  }
  FieldProblem fp;
  BuildProblem(summary.poses, turns.fitted, std::move(turns.fitted_samples), turns.fitted_noise_weight_s,
               summary, start, options, &fp);
  Eigen::MatrixXd covariance;
  if (!Solve(options, &fp, &summary, &covariance)) return summary;
  summary.model = fp.Model();
  summary.model.basis = TemperatureBasis::Reference();
  summary.sigma = Sigmas(covariance, fp.layout, options.fit_g_sensitivity);
  if (!AllFinite(summary.model) || !AllFinite(summary.sigma)) {  // never written: docs/spec.md section 4
    summary.status = FieldFitStatus::kFailed;
    summary.termination = "the solution or its covariance is not finite";
    return summary;
  }
  Residuals(fp, turns.all_samples, options, &summary);
  summary.undetermined = LooseCoefficients(summary.model, summary.sigma, options);
  summary.status = summary.undetermined.empty() ? FieldFitStatus::kConverged : FieldFitStatus::kUndetermined;
  return summary;
}

}  // namespace imufit
