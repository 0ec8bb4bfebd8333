// The thermal fit's stages and the state they share (see thermal_fit.h for the problem, the start
// and the uncertainty). FitThermalModel() (thermal_fit.cc) runs them in this order:
//
//   options and basis  ChooseBasis           the fit basis x = (T - centre) / half range
//   truth              AttachTruth           each window's truth from its plan segment
//   coverage           CheckRunCoverage      the groups the run cannot determine, by name
//   start              StartSensors          thermal_fit_start.cc: weights, closed-form start, steps
//   problem            BuildProblem          thermal_fit_solve.cc: one residual block per window
//   least squares      SolveLeastSquares     the first pass, without a loss
//   robust pass        RobustPass            again, with the loss scaled by the first pass
//   termination        CheckConvergence      the solver's verdict on the last pass
//   rank backstop      CheckRank             the rank of the column-normalised Jacobian
//   residuals          ComputeResiduals      thermal_fit_covariance.cc: SI residuals, chi-square
//   covariance         ComputeCovariance     the coefficients and their sigmas, powers of dT
//   sign refusal       RefuseNegativeScales  a scale factor negative or changing sign
//
// A stage that ends the fit returns false, with the summary's status and termination set.
#ifndef IMUFIT_FIT_SRC_THERMAL_FIT_STATE_H_
#define IMUFIT_FIT_SRC_THERMAL_FIT_STATE_H_

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "coverage.h"
#include "imufit/fit/thermal_fit.h"

namespace imufit::internal {

// One sensor's share of the problem. The parameters p (sensor_model.h layout, fit basis) are
// p = p0 + step .* q with q the solver's variables (window_cost.h).
struct SensorProblem {
  const char* name = "";
  bool is_gyro = false;
  int parameters = 0;
  int coefficients = 0;
  int order = 3;
  bool with_g_sensitivity = false;
  std::vector<double> p0;    // start, fit basis
  std::vector<double> step;  // scale of each parameter
  double* q = nullptr;       // the solver's variables, `parameters` of them in ThermalFitState::q
  std::vector<int> held;     // parameters held at their start value
  // This sensor's windows (the accelerometer's are those whose specific force is known; the
  // gyro's carry the specific force its g-sensitivity term sees) and their index in the run.
  std::vector<FitWindow> windows;
  std::vector<int> window_index;
  // The two noise figures of each window (thermal_fit_start.cc): set in this order, the second
  // from the first and the start.
  std::vector<Eigen::Vector3d> sigma_raw;  // noise of the mean, raw units: the weights
  std::vector<Eigen::Vector3d> sigma;      // the same in SI at the start's scale
  std::vector<ceres::ResidualBlockId> blocks;
  ceres::LossFunctionWrapper* loss = nullptr;  // owned by the problem
  Eigen::MatrixXd jacobian;                    // of the normalised residuals in q, free parameters only
  std::vector<int> free;                       // jacobian column -> parameter
  double loss_threshold = 0.0;                 // normalised residual norm where the robust loss starts

  std::vector<double> Parameters() const {
    std::vector<double> p(parameters);
    for (int i = 0; i < parameters; ++i) p[i] = p0[i] + step[i] * q[i];
    return p;
  }
  bool IsHeld(int i) const { return std::find(held.begin(), held.end(), i) != held.end(); }
  bool IsFullyHeld() const { return static_cast<int>(held.size()) == parameters; }
};

// Everything the stages share, for one fit. FitThermalModel() makes a fresh one for each call:
// nothing carries over from one fit to the next.
struct ThermalFitState {
  ThermalFitState() = default;
  // Not copied or moved: the sensors and the problem point into `q`.
  ThermalFitState(const ThermalFitState&) = delete;
  ThermalFitState& operator=(const ThermalFitState&) = delete;

  TemperatureBasis basis;          // ChooseBasis
  std::vector<FitWindow> windows;  // AttachTruth: every window given to the fit, in its order
  SensorProblem gyro;              // StartSensors onwards
  SensorProblem accel;
  // Both sensors' q in one buffer, the accelerometer's first (StartSensors points each
  // SensorProblem::q into it). ceres::Covariance orders its parameter blocks by their addresses,
  // and the SVD of its Jacobian rounds differently with the columns in another order: in two
  // allocations the heap decided the order, and the sigmas' last digits changed with the heap
  // (from one run to the next with two threads). The accelerometer first is the order two
  // allocations mostly had (it is started first).
  std::array<double, kGyroParameters + kAccelParameters> q{};
  // BuildProblem onwards. Declared last, so destroyed first: it points into `q` and owns the
  // sensors' loss wrappers.
  ceres::Problem problem;

  // Both sensors, in the order of the problem's residual blocks and of the covariance blocks.
  std::array<SensorProblem*, 2> Sensors() { return {&gyro, &accel}; }
  std::array<const SensorProblem*, 2> Sensors() const { return {&gyro, &accel}; }
};

// What a window's sensor responds to (its truth) and what it read (its raw mean).
inline const Eigen::Vector3d& TruthFor(const FitWindow& w, bool gyro) {
  return gyro ? w.truth.omega_radps : w.truth.a_mps2;
}
inline const Eigen::Vector3d& RawFor(const FitWindow& w, bool gyro) {
  return gyro ? w.window->gyro_mean : w.window->accel_mean;
}

// The median (the upper one of an even count); 0 for no values.
double Median(std::vector<double> values);

// Marks the summary undetermined: the run does not determine the model (the findings say why).
void MarkUndetermined(FitSummary* summary);

// The norm of each window's normalised residual (no loss) at the problem's current parameters.
std::vector<double> NormalisedResidualNorms(const ceres::Problem& problem, const SensorProblem& sensor);

// The stages up to the problem, in order (options and basis, truth, coverage, start, problem):
// false, with the summary's findings, when the run does not determine the model. The fit then
// solves; a planned run's information (plan_information.h) is the problem's Jacobian at the start.
bool SetUpFit(const std::vector<Window>& windows, const TableSite& site,
              const std::vector<TableSegment>& segments, const FitOptions& options, ThermalFitState* fit,
              FitSummary* summary);

// ---------------------------------------------------------------- stages (see the table above)

// thermal_fit_start.cc
void StartSensors(const FitOptions& options, ThermalFitState* fit);

// thermal_fit_solve.cc
void BuildProblem(ThermalFitState* fit);
ceres::Solver::Summary SolveLeastSquares(const FitOptions& options, ThermalFitState* fit,
                                         FitSummary* summary);
ceres::Solver::Summary RobustPass(const FitOptions& options, ThermalFitState* fit, FitSummary* summary);
bool CheckConvergence(const ceres::Solver::Summary& last_pass, FitSummary* summary);
bool CheckRank(const FitOptions& options, ThermalFitState* fit, FitSummary* summary);

// The directions of the sensor's free q whose singular value of the column-normalised Jacobian
// (sensor.jacobian) is below options.rank_tolerance times the largest, each named by its parameters
// ("the run cannot separate gyro bias x, gyro g_sensitivity xz (...)") (thermal_fit_solve.cc).
std::vector<std::string> UndeterminedDirections(const FitOptions& options, const SensorProblem& sensor);

// thermal_fit_covariance.cc
// The time block of each window: windows within `correlation_s` share one wandering bias.
std::vector<int> TimeBlocks(const std::vector<FitWindow>& windows, double correlation_s);
// The covariance in q (all parameters) a bias wandering by `stability` (SI, 1-sigma, one value per
// time block and axis) adds, from the unscaled covariance in q (all parameters) and sensor.jacobian.
Eigen::MatrixXd BiasStabilityCovariance(const SensorProblem& sensor,
                                        const Eigen::MatrixXd& unscaled_covariance,
                                        const std::vector<int>& time_blocks, double stability);
void ComputeResiduals(const FitOptions& options, const ThermalFitState& fit, FitSummary* summary);
bool ComputeCovariance(const FitOptions& options, ThermalFitState* fit, FitSummary* summary);

}  // namespace imufit::internal

#endif  // IMUFIT_FIT_SRC_THERMAL_FIT_STATE_H_
