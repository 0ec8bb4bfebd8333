// The solving stages of the thermal fit (thermal_fit_state.h): the Ceres problem, the least-squares
// pass, the robust pass, the solver's verdict and the rank backstop (its SVD in thermal_fit_rank.cc).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <glog/logging.h>

#include "imufit/model/check.h"
#include "thermal_fit_state.h"
#include "window_cost_create.h"

namespace imufit::internal {
namespace {

// The robust spread of normalised residuals from their median absolute value (Gaussian).
constexpr double kMadToSigma = 1.4826;
// The robust spread of the normalised residuals is never taken below one measured noise.
constexpr double kMinRobustSpread = 1.0;

// The solver's own log (glog: a warning per residual block that does not evaluate, an error on
// termination) never reaches a terminal or a notebook: what it says comes back through the
// summary, in the fit's words (CheckConvergence).
void SilenceSolverLog() {
  static const bool silenced = [] {
    FLAGS_minloglevel = google::GLOG_FATAL;
    FLAGS_logtostderr = false;
    FLAGS_stderrthreshold = google::GLOG_FATAL;
    return true;
  }();
  static_cast<void>(silenced);
}

// Both passes solve with the same options: Levenberg-Marquardt on a dense QR (132 parameters at
// most), tight tolerances (the start is close; the covariance wants the minimum), silently.
ceres::Solver::Options SolverOptions(const FitOptions& options) {
  SilenceSolverLog();
  ceres::Solver::Options solver_options;
  solver_options.logging_type = ceres::SILENT;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.function_tolerance = 1e-10;
  solver_options.parameter_tolerance = 1e-10;
  return solver_options;
}

// The Jacobian of the sensor's normalised residuals (no loss) in its free q at the solution, kept
// in `sensor->jacobian` (the bias-stability covariance uses it) with its column -> parameter map
// in `sensor->free`.
void EvaluateJacobian(const FitOptions& options, ceres::Problem* problem, SensorProblem* sensor) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = {sensor->q};
  evaluate.residual_blocks = sensor->blocks;
  evaluate.apply_loss_function = false;
  evaluate.num_threads = options.num_threads;
  ceres::CRSMatrix crs;
  problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int e = crs.rows[r]; e < crs.rows[r + 1]; ++e) jacobian(r, crs.cols[e]) = crs.values[e];
  }
  for (int i = 0; i < sensor->parameters; ++i) {
    if (!sensor->IsHeld(i)) sensor->free.push_back(i);
  }
  IMUFIT_CHECK(static_cast<int>(sensor->free.size()) == jacobian.cols(),
               "one Jacobian column per free parameter");
  sensor->jacobian = jacobian;
}

}  // namespace

std::vector<double> NormalisedResidualNorms(const ceres::Problem& problem, const SensorProblem& sensor) {
  std::vector<double> norms;
  for (ceres::ResidualBlockId block : sensor.blocks) {
    double residual[3];
    double cost = 0.0;
    problem.EvaluateResidualBlock(block, /*apply_loss_function=*/false, &cost, residual, nullptr);
    norms.push_back(Eigen::Map<const Eigen::Vector3d>(residual).norm());
  }
  return norms;
}

// Stage: problem. One residual block per window and sensor (window_cost.h), gyro first, each
// sensor's behind its own loss wrapper: empty (least squares) until the robust pass sets it. The
// held parameters stay at p0 through a subset manifold on q; a sensor held whole is constant.
void BuildProblem(ThermalFitState* fit) {
  for (SensorProblem* sensor : fit->Sensors()) {
    sensor->loss = new ceres::LossFunctionWrapper(nullptr, ceres::TAKE_OWNERSHIP);
    const bool gyro = sensor->is_gyro;
    const auto create = gyro ? &CreateGyroWindowCost : &CreateAccelWindowCost;
    for (size_t w = 0; w < sensor->windows.size(); ++w) {
      const FitWindow& fw = sensor->windows[w];
      ceres::CostFunction* cost = create(RawFor(fw, gyro), TruthFor(fw, gyro), fw.truth.a_mps2, fw.x,
                                         sensor->sigma_raw[w], sensor->p0.data(), sensor->step.data());
      sensor->blocks.push_back(fit->problem.AddResidualBlock(cost, sensor->loss, sensor->q));
    }
    if (sensor->IsFullyHeld()) {
      fit->problem.SetParameterBlockConstant(sensor->q);  // every group held (SensorFit::kNone)
    } else if (!sensor->held.empty()) {
      fit->problem.SetManifold(sensor->q, new ceres::SubsetManifold(sensor->parameters, sensor->held));
    }
  }
}

// Stage: least squares, the first pass. Its residuals measure the run's spread for the robust pass.
ceres::Solver::Summary SolveLeastSquares(const FitOptions& options, ThermalFitState* fit,
                                         FitSummary* summary) {
  ceres::Solver::Summary pass;
  ceres::Solve(SolverOptions(options), &fit->problem, &pass);
  summary->iterations = static_cast<int>(pass.iterations.size()) - 1;
  summary->initial_cost = pass.initial_cost;
  return pass;
}

// Stage: robust pass (FitOptions::loss, after a converged first pass). Each sensor's loss starts
// at loss_scale times the robust spread of one residual component, 1.4826 x the median of
// |r_w| / sqrt(3) over its windows (r_w the window's normalised 3-vector, whose norm the loss
// sees), never below 1: the residuals are in units of each window's measured noise, and a smaller
// median comes from windows the fit matches exactly (few windows for the parameters, e.g. one turn
// per axis setting the scale), so the loss must not act on ordinary noise. A sensor held whole
// moves no estimate and keeps least squares.
ceres::Solver::Summary RobustPass(const FitOptions& options, ThermalFitState* fit, FitSummary* summary) {
  for (SensorProblem* sensor : fit->Sensors()) {
    if (sensor->IsFullyHeld()) continue;
    std::vector<double> components;
    for (double norm : NormalisedResidualNorms(fit->problem, *sensor))
      components.push_back(norm / std::sqrt(3.0));
    const double spread = std::max(kMadToSigma * Median(components), kMinRobustSpread);
    sensor->loss_threshold = options.loss_scale * spread;
    if (options.loss == RobustLoss::kHuber) {
      sensor->loss->Reset(new ceres::HuberLoss(sensor->loss_threshold), ceres::TAKE_OWNERSHIP);
    } else {
      sensor->loss->Reset(new ceres::CauchyLoss(sensor->loss_threshold), ceres::TAKE_OWNERSHIP);
    }
  }
  ceres::Solver::Summary pass;
  ceres::Solve(SolverOptions(options), &fit->problem, &pass);
  summary->iterations += static_cast<int>(pass.iterations.size()) - 1;
  return pass;
}

// Stage: termination. The last pass's cost and words; a pass that stopped without converging
// (iterations, a failed step) ends the fit as kNotConverged.
bool CheckConvergence(const ceres::Solver::Summary& last_pass, FitSummary* summary) {
  summary->final_cost = last_pass.final_cost;
  summary->termination = last_pass.message;
  if (last_pass.termination_type == ceres::CONVERGENCE) return true;
  summary->status = FitStatus::kNotConverged;
  if (!std::isfinite(last_pass.final_cost) ||
      last_pass.message.find("evaluation failed") != std::string::npos) {
    summary->termination =
        "the model's residuals are not finite numbers: a raw channel that never changes (dead, stuck or at "
        "its rail) or a non-finite reading leaves a scale factor at zero";
    return false;
  }
  summary->termination =
      std::string(ceres::TerminationTypeToString(last_pass.termination_type)) + ": " + last_pass.message;
  return false;
}

// Stage: rank backstop. The coverage check works group by group before the solve; a combination
// of parameters that it does not foresee shows here, per sensor, as a null direction of the
// column-normalised Jacobian at the solution, named by its parameters.
bool CheckRank(const FitOptions& options, ThermalFitState* fit, FitSummary* summary) {
  for (SensorProblem* sensor : fit->Sensors()) {
    if (sensor->IsFullyHeld()) continue;
    EvaluateJacobian(options, &fit->problem, sensor);
    for (std::string& finding : UndeterminedDirections(options, *sensor)) {
      summary->undetermined.push_back(std::move(finding));
    }
  }
  if (summary->undetermined.empty()) return true;
  MarkUndetermined(summary);
  return false;
}

}  // namespace imufit::internal
