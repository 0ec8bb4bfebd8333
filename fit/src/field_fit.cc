// The field fit (field_fit.h): what the session determines, the Ceres problem, its covariance.
#include "imufit/fit/field_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>
#include <tuple>
#include <utility>

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
// `in` (when not empty) keeps the poses judged, and the turns between two of them.
std::vector<std::string> CoverageProblems(const std::vector<FieldPose>& poses,
                                          const std::vector<FieldTurn>& turns,
                                          const std::vector<std::vector<TurnSample>>& turn_samples,
                                          const SensorModel& start, const FieldFitOptions& options,
                                          const std::vector<bool>& in = {}) {
  std::vector<std::string> problems;
  const UnitCoefficients<double> c = start.CoefficientsAtTemperature(25.0);
  std::vector<Eigen::Vector3d> ups;
  for (const FieldPose& pose : poses) {
    ups.push_back(CorrectSensor(c.accel, pose.accel_mean, Eigen::Vector3d::Zero().eval()).normalized());
  }
  const auto kept = [&in](size_t pose) { return in.empty() || in[pose]; };
  const char* axes = "xyz";
  const double near = std::cos(options.near_direction_deg * kDegToRad);
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      double best = -1.0;
      for (size_t p = 0; p < ups.size(); ++p) {
        if (kept(p)) best = std::max(best, sign * ups[p](axis));
      }
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
    if (!kept(turns[t].from) || !kept(turns[t].to)) continue;
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

// What the poses' temperatures cannot determine of the orders asked (field_fit.h, bias_temp_order
// and scale_temp_order), in plain words: too narrow a span, too few distinct temperatures, and
// for the scale factors the coldest and warmest third without a pose near each direction or turns
// about each axis.
std::vector<std::string> TemperatureProblems(const std::vector<FieldPose>& poses,
                                             const std::vector<FieldTurn>& turns,
                                             const std::vector<std::vector<TurnSample>>& turn_samples,
                                             const SensorModel& start, const FieldFitOptions& options) {
  std::vector<std::string> problems;
  if (options.bias_temp_order == 0 && options.scale_temp_order == 0) return problems;
  std::vector<double> temps;
  for (const FieldPose& pose : poses) temps.push_back(pose.temp_c);
  std::sort(temps.begin(), temps.end());
  const double low = temps.front();
  const double high = temps.back();
  int distinct = 1;
  for (size_t i = 1, last = 0; i < temps.size(); ++i) {
    if (temps[i] - temps[last] >= kDistinctTempC) ++distinct, last = i;
  }
  const std::string span =
      Format("the poses span %.3g degC (%.4g", high - low, low) + Format(" .. %.4g degC)", high);
  const auto order_text = [](const char* what, int order) {
    return std::string(what) + " (order " + std::to_string(order) + ")";
  };
  for (const auto& [what, order, min_span] :
       {std::tuple{"the biases", options.bias_temp_order, options.min_bias_temp_span_c},
        {"the scale factors", options.scale_temp_order, options.min_scale_temp_span_c}}) {
    if (order == 0) continue;
    if (high - low < min_span || distinct < order + 1) {
      problems.push_back(span + ", " + std::to_string(distinct) + " distinct" +
                         Format(" (%.2g degC apart): too little to fit ", kDistinctTempC) +
                         order_text(what, order) + " in temperature, which needs " +
                         Format("%.3g degC and ", min_span) + std::to_string(order + 1) +
                         " distinct temperatures: lower the order, or record over a wider warm-up");
    }
  }
  if (options.scale_temp_order == 0 || !problems.empty()) return problems;
  for (const bool cold : {true, false}) {
    std::vector<bool> in(poses.size());
    for (size_t p = 0; p < poses.size(); ++p) {
      in[p] =
          cold ? poses[p].temp_c <= low + (high - low) / 3.0 : poses[p].temp_c >= high - (high - low) / 3.0;
    }
    const std::string where =
        cold ? Format("among the coldest poses (%.4g .. %.4g degC): ", low, low + (high - low) / 3.0)
             : Format("among the warmest poses (%.4g .. %.4g degC): ", high - (high - low) / 3.0, high);
    for (const std::string& problem : CoverageProblems(poses, turns, turn_samples, start, options, in)) {
      problems.push_back(where + problem + ", so the scale factors cannot follow temperature");
    }
  }
  return problems;
}

// Whether the fit estimates term k of a coefficient (field_fit.h: the temperature orders; H only
// when fitted; misalignments and H constant).
bool TermFitted(bool gyro, int coefficient, int k, const FieldFitOptions& options) {
  if (gyro && coefficient >= kGSensitivityCoefficient) return options.fit_g_sensitivity && k == 0;
  if (coefficient < kScaleCoefficient) return k <= options.bias_temp_order;
  if (coefficient < kMisalignmentCoefficient) return k <= options.scale_temp_order;
  return k == 0;
}

// A column of the solver's Jacobian (tangent space): a fitted term, or a pose's direction.
struct FieldColumn {
  bool gyro = true;
  int coefficient = 0;  // the model's index
  int term = 0;         // k, in the fit's basis
  int q = 0;            // index into the block
};

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
  // The fitted terms, in the Jacobian's column order (before the poses').
  std::vector<FieldColumn> columns;

  // The model at the current q, in powers of dT (TemperatureBasis::Reference()).
  SensorModel Model() const {
    SensorModel fitted;
    layout.Gyro(gyro_q.data(), fitted.gyro.data());
    layout.Accel(accel_q.data(), fitted.accel.data());
    const Eigen::Matrix4d rebase = RebaseTemperaturePolynomial(layout.basis, TemperatureBasis::Reference());
    SensorModel model;
    model.basis = TemperatureBasis::Reference();
    for (auto [from, to] :
         {std::pair{fitted.gyro.data(), model.gyro.data()}, {fitted.accel.data(), model.accel.data()}}) {
      const int count = from == fitted.gyro.data() ? kGyroParameters : kAccelParameters;
      for (int i = 0; i < count; i += kPolynomialTerms) {
        Eigen::Map<Eigen::Vector4d>(to + i) = rebase * Eigen::Map<const Eigen::Vector4d>(from + i);
      }
    }
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

// The session pose `pose` (an index into summary.poses) belongs to.
const FieldSessionShare& SessionOfPose(const FieldFitSummary& summary, int pose) {
  for (const FieldSessionShare& session : summary.sessions) {
    if (pose >= session.first_pose && pose < session.first_pose + session.poses) return session;
  }
  IMUFIT_CHECK(false, "every pose belongs to a session");
  return summary.sessions.front();
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
  // The fit's basis: the poses' temperatures to [-1, 1] (at one temperature, x = 0 everywhere).
  const auto [coldest, warmest] = std::minmax_element(
      poses.begin(), poses.end(), [](const FieldPose& a, const FieldPose& b) { return a.temp_c < b.temp_c; });
  fp->layout.basis.center_c = 0.5 * (coldest->temp_c + warmest->temp_c);
  fp->layout.basis.half_range_c = std::max(0.5 * (warmest->temp_c - coldest->temp_c), 1.0);
  const TemperatureBasis& basis = fp->layout.basis;
  for (size_t p = 0; p < poses.size(); ++p) {
    const double n = static_cast<double>(poses[p].last - poses[p].first + 1);
    fp->directions.emplace_back(CorrectSensor(c.accel, poses[p].accel_mean, Eigen::Vector3d::Zero().eval()));
    const double x = basis.Argument(poses[p].temp_c);
    const FieldSessionShare& session = SessionOfPose(summary, static_cast<int>(p));
    fp->groups[FieldLayout::kAccelGroup].push_back(fp->problem.AddResidualBlock(
        FieldPoseAccelCost::Create(&fp->layout, &fp->directions[p], poses[p].accel_mean, x,
                                   options.gravity_mps2, session.accel_noise_raw / std::sqrt(n)),
        nullptr, fp->accel_q.data(), fp->pose_q[p].data()));
    fp->groups[FieldLayout::kGyroGroup].push_back(fp->problem.AddResidualBlock(
        FieldPoseGyroCost::Create(&fp->layout, poses[p].gyro_mean, poses[p].accel_mean, x,
                                  session.gyro_noise_raw / std::sqrt(n)),
        nullptr, fp->gyro_q.data(), fp->accel_q.data()));
  }
  // The gyro's white noise in rad/s (at the start's scales; its session's), integrated over a turn:
  // the angle's random walk, per axis perpendicular to gravity.
  for (size_t t = 0; t < turns.size(); ++t) {
    const Eigen::Vector3d gyro_noise_radps =
        SessionOfPose(summary, turns[t].from).gyro_noise_raw.cwiseQuotient(c.gyro.scale.cwiseAbs());
    const double noise_radps = std::sqrt(gyro_noise_radps.squaredNorm() / 3.0);
    const double temp_c = 0.5 * (poses[turns[t].from].temp_c + poses[turns[t].to].temp_c);
    const double sigma_rad = noise_radps * turn_noise_weight_s[t];
    fp->groups[FieldLayout::kTurnGroup].push_back(fp->problem.AddResidualBlock(
        FieldTurnCost::Create(&fp->layout, &fp->directions[turns[t].from], &fp->directions[turns[t].to],
                              std::move(turn_samples[t]), basis.Argument(temp_c), std::max(sigma_rad, 1e-12)),
        nullptr, fp->gyro_q.data(), fp->accel_q.data(), fp->pose_q[turns[t].from].data(),
        fp->pose_q[turns[t].to].data()));
  }
  // The terms not fitted are held (their q stays 0); the rest are the Jacobian's columns.
  for (const bool gyro : {true, false}) {
    std::vector<int> held;
    const int values = gyro ? kGyroCoefficients : FieldLayout::kAccelFree;
    for (int v = 0; v < values; ++v) {
      const int coefficient = gyro ? v : FieldLayout::kAccelFreeCoefficient[v];
      for (int k = 0; k < FieldLayout::kTerms; ++k) {
        const int q = v * FieldLayout::kTerms + k;
        if (TermFitted(gyro, coefficient, k, options)) {
          fp->columns.push_back({gyro, coefficient, k, q});
        } else {
          held.push_back(q);
        }
      }
    }
    if (held.empty()) continue;
    double* block = gyro ? fp->gyro_q.data() : fp->accel_q.data();
    fp->problem.SetManifold(
        block, new ceres::SubsetManifold(gyro ? FieldLayout::kGyroBlock : FieldLayout::kAccelBlock, held));
  }
}

// The name of the model parameter behind Jacobian column `column` (Blocks() order), e.g. "gyro
// scale z", "accel bias x (its dT^2 term)", or "the direction of pose 4".
std::string ColumnName(int column, const std::vector<FieldColumn>& columns) {
  if (column >= static_cast<int>(columns.size())) {
    return "the direction of pose " + std::to_string((column - static_cast<int>(columns.size())) / 2 + 1);
  }
  const FieldColumn& c = columns[column];
  const CoefficientName& name = kCoefficientNames[c.coefficient];
  return std::string(c.gyro ? "gyro " : "accel ") + name.group + " " + name.axis +
         (c.term == 0   ? ""
          : c.term == 1 ? " (its change with temperature)"
                        : " (its dT^" + std::to_string(c.term) + " term in temperature)");
}

// Threads for evaluating the residuals: the machine's, at most kMaxEvaluationThreads.
int EvaluationThreads() {
  constexpr unsigned kMaxEvaluationThreads = 4;
  return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, kMaxEvaluationThreads));
}

// The residuals and their Jacobian at the current q, dense, rows in group order (accel, gyro,
// turns), columns in the solver's q (tangent) order; `group_rows` the first row of each group and
// the end.
Eigen::MatrixXd Jacobian(FieldProblem* fp, Eigen::VectorXd* residuals, std::array<int, 4>* group_rows) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.num_threads = EvaluationThreads();
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
std::string Covariance(const Eigen::MatrixXd& jacobian, const std::vector<FieldColumn>& columns,
                       Eigen::MatrixXd* covariance) {
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  const Eigen::VectorXd diagonal = information.diagonal();
  for (int i = 0; i < diagonal.size(); ++i) {
    if (!(diagonal(i) > 0.0)) return ColumnName(i, columns);
  }
  const Eigen::VectorXd d = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = d.asDiagonal() * information * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  constexpr double kRankTolerance = 1e-12;  // relative to the largest eigenvalue (Jacobi-scaled)
  if (!(eigen.eigenvalues()(0) > kRankTolerance * eigen.eigenvalues().maxCoeff())) {
    Eigen::Index largest = 0;
    eigen.eigenvectors().col(0).cwiseAbs().maxCoeff(&largest);
    return ColumnName(static_cast<int>(largest), columns);
  }
  *covariance = d.asDiagonal() *
                (eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                 eigen.eigenvectors().transpose()) *
                d.asDiagonal();
  return "";
}

// Each coefficient's covariance over its terms, in the model's units and the fit's basis (4 x 4,
// zero for terms held), from the covariance in q; `visit(gyro, coefficient, covariance)`.
template <typename Visit>
void CoefficientCovariances(const Eigen::MatrixXd& covariance, const FieldProblem& fp, Visit&& visit) {
  size_t first = 0;
  while (first < fp.columns.size()) {
    size_t end = first;
    while (end < fp.columns.size() && fp.columns[end].gyro == fp.columns[first].gyro &&
           fp.columns[end].coefficient == fp.columns[first].coefficient) {
      ++end;
    }
    Eigen::Matrix4d c = Eigen::Matrix4d::Zero();
    for (size_t i = first; i < end; ++i) {
      for (size_t j = first; j < end; ++j) {
        const FieldColumn& a = fp.columns[i];
        const FieldColumn& b = fp.columns[j];
        const double step_a = a.gyro ? fp.layout.gyro_step[a.q] : fp.layout.accel_step[a.q];
        const double step_b = b.gyro ? fp.layout.gyro_step[b.q] : fp.layout.accel_step[b.q];
        c(a.term, b.term) =
            step_a * step_b * covariance(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      }
    }
    visit(fp.columns[first].gyro, fp.columns[first].coefficient, c);
    first = end;
  }
}

// The 1-sigma of every model parameter in powers of dT (0 for a held term), and of each
// coefficient's value at the coldest and warmest pose, from the covariance in q.
void Sigmas(const Eigen::MatrixXd& covariance, const FieldProblem& fp,
            const std::array<double, 2>& pose_temps_c, FieldFitSummary* summary) {
  const Eigen::Matrix4d rebase = RebaseTemperaturePolynomial(fp.layout.basis, TemperatureBasis::Reference());
  for (SensorModel* sigma : {&summary->sigma, &summary->sigma_at_low, &summary->sigma_at_high}) {
    *sigma = SensorModel{};
    sigma->basis = TemperatureBasis::Reference();
  }
  CoefficientCovariances(covariance, fp, [&](bool gyro, int coefficient, const Eigen::Matrix4d& c) {
    const Eigen::Matrix4d reference = rebase * c * rebase.transpose();
    const int i = coefficient * kPolynomialTerms;
    const auto at = [&](double temp_c) {
      const double x = fp.layout.basis.Argument(temp_c);
      const Eigen::Vector4d powers(1.0, x, x * x, x * x * x);
      return std::sqrt(std::max(0.0, powers.dot(c * powers)));
    };
    for (int k = 0; k < kPolynomialTerms; ++k) {
      (gyro ? summary->sigma.gyro.data() : summary->sigma.accel.data())[i + k] =
          std::sqrt(std::max(0.0, reference(k, k)));
    }
    (gyro ? summary->sigma_at_low.gyro.data() : summary->sigma_at_low.accel.data())[i] = at(pose_temps_c[0]);
    (gyro ? summary->sigma_at_high.gyro.data() : summary->sigma_at_high.accel.data())[i] =
        at(pose_temps_c[1]);
  });
}

// Coefficients the session fixes too loosely to be of use (their sigma at the coldest or warmest
// pose), in plain words.
std::vector<std::string> LooseCoefficients(const FieldFitSummary& fit, const FieldFitOptions& options) {
  std::vector<std::string> loose;
  const char* axes = "xyz";
  // The larger of a coefficient's sigmas at the two ends, and where.
  const auto worst = [&](bool gyro, int coefficient, double* temp_c) {
    const int i = coefficient * kPolynomialTerms;
    const double low = (gyro ? fit.sigma_at_low.gyro.data() : fit.sigma_at_low.accel.data())[i];
    const double high = (gyro ? fit.sigma_at_high.gyro.data() : fit.sigma_at_high.accel.data())[i];
    *temp_c = low >= high ? fit.pose_temp_range_c[0] : fit.pose_temp_range_c[1];
    return std::max(low, high);
  };
  const bool over_temperature = fit.pose_temp_range_c[1] > fit.pose_temp_range_c[0] &&
                                (options.bias_temp_order > 0 || options.scale_temp_order > 0);
  const auto at = [&](double temp_c) {
    return over_temperature ? Format(" at %.4g degC", temp_c) : std::string();
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int c = kScaleCoefficient + axis;
    double temp_c = 0.0;
    for (const bool gyro : {true, false}) {
      const double sigma = worst(gyro, c, &temp_c);
      const double* p = (gyro ? fit.model.gyro.data() : fit.model.accel.data()) + c * kPolynomialTerms;
      const double scale = std::abs(EvaluateTemperaturePolynomial(p, temp_c - kReferenceTempC));
      if (sigma <= options.max_relative_scale_sigma * scale) continue;
      loose.push_back(std::string(gyro ? "turns about "
                                       : "poses too few or too close together to fix the accelerometer's ") +
                      (gyro ? std::string(1, axes[axis]) + " too small to fix the gyro's " : std::string()) +
                      axes[axis] + " scale" + Format(" (1 sigma %.2g %%", 100.0 * sigma / scale) +
                      at(temp_c) + ")");
    }
  }
  for (int m = 0; m < 6; ++m) {
    const int c = kMisalignmentCoefficient + m;
    double temp_c = 0.0;
    if (const double sigma = worst(true, c, &temp_c); sigma > options.max_misalignment_sigma_rad) {
      loose.push_back(std::string("turns too few or too small to fix the gyro's misalignment ") +
                      kCoefficientNames[c].axis + Format(" (1 sigma %.2g mrad)", 1e3 * sigma));
    }
    if (const double sigma = worst(false, c, &temp_c); sigma > options.max_misalignment_sigma_rad) {
      loose.push_back(
          std::string("poses too few or too close together to fix the accelerometer's misalignment ") +
          kCoefficientNames[c].axis + Format(" (1 sigma %.2g mrad)", 1e3 * sigma));
    }
  }
  return loose;
}

// The residuals in physical units after the fit, and each pose's and turn's own figures.
void Residuals(const FieldProblem& fp, const std::vector<std::vector<TurnSample>>& turn_samples,
               const FieldFitOptions& options, FieldFitSummary* summary) {
  double accel_sum = 0.0;
  double gyro_sum = 0.0;
  for (size_t p = 0; p < summary->poses.size(); ++p) {
    FieldPose& pose = summary->poses[p];
    const UnitCoefficients<double> c = summary->model.CoefficientsAtTemperature(pose.temp_c);
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
    const UnitCoefficients<double> c = summary->model.CoefficientsAtTemperature(
        0.5 * (summary->poses[turn.from].temp_c + summary->poses[turn.to].temp_c));
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
  // The residuals and their Jacobians (the turns' integrals, most of the time) evaluated on
  // several threads: each block alone, so the solution is the same within the solver's tolerance.
  solver.num_threads = EvaluationThreads();
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
    if (const std::string missing = Covariance(jacobian, fp->columns, covariance); !missing.empty()) {
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
      (sessions.size() > 1 ? std::to_string(sessions.size()) + " sessions, " : std::string()) +
      std::to_string(poses.size()) + " poses, " + std::to_string(turns.size()) + " turns" +
      (saturated > 0 ? " (" + std::to_string(saturated) + " saturated, left out)" : "");
  switch (status) {
    case FieldFitStatus::kNotRun:
      return "not run";
    case FieldFitStatus::kUndetermined: {
      std::string text = (sessions.size() > 1 ? "the sessions do not" : "the session does not") +
                         std::string(" determine the model (") + counts + "): ";
      for (size_t i = 0; i < undetermined.size(); ++i) text += (i > 0 ? "; " : "") + undetermined[i];
      return text;
    }
    case FieldFitStatus::kFailed:
      return "the fit did not converge (" + counts + "): " + termination;
    case FieldFitStatus::kInconsistent: {
      std::string text = "the sessions disagree (" + counts + "): ";
      // The sessions and sensors beyond chance, the most discrepant first.
      std::vector<std::pair<double, std::string>> beyond;
      for (const FieldSessionShare& session : sessions) {
        for (const auto& [sensor, offset] :
             {std::pair{"gyro", &session.gyro_bias}, std::pair{"accelerometer", &session.accel_bias}}) {
          if (!offset->beyond) continue;
          beyond.emplace_back(offset->chi2, session.name + ": its " + sensor + " bias is off the joint fit" +
                                                Format(" (chi-square %.3g for 3, beyond %.3g)", offset->chi2,
                                                       kFieldSessionChi2));
        }
      }
      std::stable_sort(beyond.begin(), beyond.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      std::string named;
      for (const auto& item : beyond) named += (named.empty() ? "" : "; ") + item.second;
      return text + named +
             ": a bias that changed from one power-on to the next (turn-on repeatability), a curve in "
             "temperature of too low an order (--bias-temp-order), or another unit; "
             "fit the sessions one by one (--repeat compares two), or record over one power-on";
    }
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

FieldRepeatability CompareFieldFits(const FieldFitSummary& first, const FieldFitSummary& second) {
  FieldRepeatability out;
  double sum_z2 = 0.0;
  for (const bool gyro : {true, false}) {
    const int coefficients = gyro ? kGyroCoefficients : kAccelCoefficients;
    for (int c = 0; c < coefficients; ++c) {
      const int i = c * kPolynomialTerms;
      const double sigma_a = (gyro ? first.sigma.gyro.data() : first.sigma.accel.data())[i];
      const double sigma_b = (gyro ? second.sigma.gyro.data() : second.sigma.accel.data())[i];
      if (!(sigma_a > 0.0 && sigma_b > 0.0)) continue;  // held in either
      FieldCoefficientDifference d;
      d.gyro = gyro;
      d.coefficient = c;
      d.difference = (gyro ? second.model.gyro.data() : second.model.accel.data())[i] -
                     (gyro ? first.model.gyro.data() : first.model.accel.data())[i];
      d.combined_sigma = std::hypot(sigma_a, sigma_b);
      d.z = d.difference / d.combined_sigma;
      sum_z2 += d.z * d.z;
      out.differences.push_back(d);
      if (std::abs(d.z) > FieldRepeatability::kFieldRepeatZ) out.beyond.push_back(d);
    }
  }
  if (!out.differences.empty()) out.z_rms = std::sqrt(sum_z2 / static_cast<double>(out.differences.size()));
  return out;
}

namespace {

// Step 1 over every session (FitFieldSessions): each session's poses, turns and noise floor, found
// on its own samples, appended with their indices offset (poses, turns and samples counting
// through the sessions), so that a turn never joins two sessions; each session's share; the
// turns' samples. The summary's noise floor is the sessions' pooled over their rests.
TurnSets GatherSessions(const std::vector<const std::vector<Sample>*>& sessions,
                        const std::vector<std::string>& names, const FieldFitOptions& options,
                        FieldFitSummary* summary) {
  TurnSets all;
  long long first_sample = 0;
  Eigen::Vector3d gyro_variance = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_variance = Eigen::Vector3d::Zero();
  double degrees_of_freedom = 0.0;
  for (size_t s = 0; s < sessions.size(); ++s) {
    const std::vector<Sample>& samples = *sessions[s];
    FieldSessionShare share;
    share.name = s < names.size() ? names[s] : "session " + std::to_string(s + 1);
    share.samples = static_cast<long long>(samples.size());
    share.first_pose = static_cast<int>(summary->poses.size());
    share.first_turn = static_cast<int>(summary->turns.size());
    std::vector<FieldPose> poses;
    std::vector<FieldTurn> turns;
    FindFieldPoses(samples, options, &poses, &turns, &share.gyro_noise_raw, &share.accel_noise_raw);
    if (!samples.empty()) {
      const auto [low, high] =
          std::minmax_element(samples.begin(), samples.end(),
                              [](const Sample& a, const Sample& b) { return a.temp_c < b.temp_c; });
      share.temp_range_c = {low->temp_c, high->temp_c};
    }
    TurnSets sets = SplitTurns(samples, turns);
    for (size_t t = 0; t < sets.all_samples.size(); ++t)
      all.all_samples.push_back(std::move(sets.all_samples[t]));
    for (size_t t = 0; t < sets.fitted.size(); ++t) {
      FieldTurn turn = sets.fitted[t];
      turn.from += share.first_pose;
      turn.to += share.first_pose;
      turn.first += first_sample;
      turn.last += first_sample;
      all.fitted.push_back(turn);
      all.fitted_samples.push_back(std::move(sets.fitted_samples[t]));
      all.fitted_noise_weight_s.push_back(sets.fitted_noise_weight_s[t]);
    }
    for (FieldTurn turn : turns) {
      turn.from += share.first_pose;
      turn.to += share.first_pose;
      turn.first += first_sample;
      turn.last += first_sample;
      summary->turns.push_back(turn);
    }
    for (FieldPose pose : poses) {
      const double n = static_cast<double>(pose.last - pose.first);
      gyro_variance += n * share.gyro_noise_raw.cwiseAbs2();
      accel_variance += n * share.accel_noise_raw.cwiseAbs2();
      degrees_of_freedom += n;
      pose.first += first_sample;
      pose.last += first_sample;
      summary->poses.push_back(pose);
    }
    share.poses = static_cast<int>(poses.size());
    share.turns = static_cast<int>(turns.size());
    summary->sessions.push_back(share);
    first_sample += share.samples;
  }
  const FieldSessionShare& first = summary->sessions.front();
  const bool pooled = sessions.size() > 1 && degrees_of_freedom > 0.0;
  summary->gyro_noise_raw =
      pooled ? (gyro_variance / degrees_of_freedom).cwiseSqrt().eval() : first.gyro_noise_raw;
  summary->accel_noise_raw =
      pooled ? (accel_variance / degrees_of_freedom).cwiseSqrt().eval() : first.accel_noise_raw;
  summary->temp_range_c = first.temp_range_c;
  for (const FieldSessionShare& share : summary->sessions) {
    summary->temp_range_c = {std::min(summary->temp_range_c[0], share.temp_range_c[0]),
                             std::max(summary->temp_range_c[1], share.temp_range_c[1])};
  }
  return all;
}

// Each session's biases against the joint fit (field_fit.h, FieldSessionOffset): the score test of
// an offset of its own, per sensor, from the Jacobian at the solution. `fitted_turns` are the
// turns in the problem (their poses name their session).
void SessionOffsets(const std::vector<FieldTurn>& fitted_turns, FieldProblem* fp, FieldFitSummary* summary) {
  Eigen::VectorXd residuals;
  std::array<int, 4> group_rows{};
  const Eigen::MatrixXd jacobian = Jacobian(fp, &residuals, &group_rows);
  Eigen::MatrixXd covariance;
  if (!Covariance(jacobian, fp->columns, &covariance).empty()) return;
  // The session of every row (groups: accel 3 a pose, gyro 3 a pose, turns 2 each).
  std::vector<int> row_session(static_cast<size_t>(jacobian.rows()), -1);
  const auto session_of_pose = [&](int pose) {
    return static_cast<int>(&SessionOfPose(*summary, pose) - summary->sessions.data());
  };
  for (int p = 0; p < static_cast<int>(summary->poses.size()); ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      row_session[group_rows[FieldLayout::kAccelGroup] + 3 * p + axis] = session_of_pose(p);
      row_session[group_rows[FieldLayout::kGyroGroup] + 3 * p + axis] = session_of_pose(p);
    }
  }
  for (size_t t = 0; t < fitted_turns.size(); ++t) {
    for (int k = 0; k < 2; ++k)
      row_session[group_rows[FieldLayout::kTurnGroup] + 2 * t + k] = session_of_pose(fitted_turns[t].from);
  }
  // A session whose offset keeps less than this share of its information on the bias, once the
  // joint fit has taken what it can (the smallest eigenvalue of A against G^T G, Jacobi-scaled),
  // cannot be told from the curve in temperature.
  constexpr double kMinTestableShare = 1e-3;
  for (const bool gyro : {true, false}) {
    std::array<int, 3> columns{-1, -1, -1};
    for (size_t i = 0; i < fp->columns.size(); ++i) {
      const FieldColumn& c = fp->columns[i];
      if (c.gyro == gyro && c.coefficient < kScaleCoefficient && c.term == 0)
        columns[c.coefficient] = static_cast<int>(i);
    }
    if (*std::min_element(columns.begin(), columns.end()) < 0) continue;
    for (size_t s = 0; s < summary->sessions.size(); ++s) {
      Eigen::MatrixXd g = Eigen::MatrixXd::Zero(jacobian.rows(), 3);
      for (Eigen::Index row = 0; row < jacobian.rows(); ++row) {
        if (row_session[static_cast<size_t>(row)] != static_cast<int>(s)) continue;
        for (int axis = 0; axis < 3; ++axis) g(row, axis) = jacobian(row, columns[axis]);
      }
      const Eigen::MatrixXd projected = g - jacobian * (covariance * (jacobian.transpose() * g));
      const Eigen::Matrix3d a = g.transpose() * projected;
      const Eigen::Vector3d d = (g.transpose() * g).diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(d.asDiagonal() * a * d.asDiagonal());
      FieldSessionOffset& out = gyro ? summary->sessions[s].gyro_bias : summary->sessions[s].accel_bias;
      out.tested = eigen.eigenvalues()(0) > kMinTestableShare;
      if (!out.tested) continue;
      const Eigen::Matrix3d a_inverse = a.inverse();
      const Eigen::Vector3d offset_q = -a_inverse * (g.transpose() * residuals);
      out.chi2 = offset_q.dot(a * offset_q);
      out.beyond = out.chi2 > kFieldSessionChi2;
      for (int axis = 0; axis < 3; ++axis) {
        const int q = fp->columns[columns[axis]].q;
        const double step = gyro ? fp->layout.gyro_step[q] : fp->layout.accel_step[q];
        out.offset(axis) = step * offset_q(axis);
        out.sigma(axis) = step * std::sqrt(std::max(0.0, a_inverse(axis, axis)));
      }
    }
  }
}

FieldFitSummary FitSessions(const std::vector<const std::vector<Sample>*>& sessions,
                            const FieldFitOptions& given, const std::vector<std::string>& names) {
  IMUFIT_CHECK(given.Validate().empty(), "FieldFitOptions::Validate() first");
  IMUFIT_CHECK(!sessions.empty(), "at least one session");
  IMUFIT_CHECK(names.empty() || names.size() == sessions.size(), "a name for every session, or none");
  FieldFitOptions options = given;  // gravity resolved once: every stage reads gravity_mps2
  options.gravity_mps2 = given.GravityMps2();
  options.latitude_deg.reset();
  options.height_m = 0.0;
  FieldFitSummary summary;
  TurnSets turns = GatherSessions(sessions, names, options, &summary);
  if (sessions.size() > 1) {
    for (const FieldSessionShare& session : summary.sessions) {
      if (session.poses > 0) continue;
      summary.undetermined.push_back(
          session.name + ": no pose at rest found" +
          Format(" (a rest lasts %.3g s or longer): not a session by hand, or the wrong file",
                 options.min_pose_s + options.detection.window_s));
    }
  }
  if (static_cast<int>(summary.poses.size()) < options.min_poses) {
    summary.status = FieldFitStatus::kUndetermined;
    summary.undetermined.push_back(
        "found " + std::to_string(summary.poses.size()) + " poses at rest, needs at least " +
        std::to_string(options.min_poses) +
        Format(" (rest %.3g s or longer in each)", options.min_pose_s + options.detection.window_s));
    return summary;
  }
  const SensorModel start = FieldStart(summary.poses, turns.fitted, turns.fitted_samples, options);
  for (std::string& problem :
       CoverageProblems(summary.poses, turns.fitted, turns.fitted_samples, start, options)) {
    summary.undetermined.push_back(std::move(problem));
  }
  for (std::string& problem :
       TemperatureProblems(summary.poses, turns.fitted, turns.fitted_samples, start, options)) {
    summary.undetermined.push_back(std::move(problem));
  }
  const auto [coldest, warmest] =
      std::minmax_element(summary.poses.begin(), summary.poses.end(),
                          [](const FieldPose& a, const FieldPose& b) { return a.temp_c < b.temp_c; });
  summary.pose_temp_range_c = {coldest->temp_c, warmest->temp_c};
  if (!summary.undetermined.empty()) {
    summary.status = FieldFitStatus::kUndetermined;
    return summary;
  }
  FieldProblem fp;
  const std::vector<FieldTurn> fitted_turns = turns.fitted;
  BuildProblem(summary.poses, turns.fitted, std::move(turns.fitted_samples), turns.fitted_noise_weight_s,
               summary, start, options, &fp);
  Eigen::MatrixXd covariance;
  if (!Solve(options, &fp, &summary, &covariance)) return summary;
  summary.model = fp.Model();
  Sigmas(covariance, fp, summary.pose_temp_range_c, &summary);
  if (!AllFinite(summary.model) || !AllFinite(summary.sigma)) {  // never written: docs/spec.md section 4
    summary.status = FieldFitStatus::kFailed;
    summary.termination = "the solution or its covariance is not finite";
    return summary;
  }
  Residuals(fp, turns.all_samples, options, &summary);
  summary.undetermined = LooseCoefficients(summary, options);
  summary.status = summary.undetermined.empty() ? FieldFitStatus::kConverged : FieldFitStatus::kUndetermined;
  if (summary.status == FieldFitStatus::kConverged && sessions.size() > 1) {
    SessionOffsets(fitted_turns, &fp, &summary);
    for (const FieldSessionShare& session : summary.sessions) {
      if (session.gyro_bias.beyond || session.accel_bias.beyond)
        summary.status = FieldFitStatus::kInconsistent;
    }
  }
  return summary;
}

}  // namespace

FieldFitSummary FitField(const std::vector<Sample>& samples, const FieldFitOptions& options) {
  return FitSessions({&samples}, options, {});
}

FieldFitSummary FitFieldSessions(const std::vector<std::vector<Sample>>& sessions,
                                 const FieldFitOptions& options, const std::vector<std::string>& names) {
  std::vector<const std::vector<Sample>*> pointers;
  for (const std::vector<Sample>& session : sessions) pointers.push_back(&session);
  return FitSessions(pointers, options, names);
}

}  // namespace imufit
