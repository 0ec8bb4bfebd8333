// imufit — the information a planned run gives the thermal fit, before the run: the estimator's
// own problem (window_cost.h: its residuals, its weights, its parameters and their basis) set up on
// windows whose raw means are the nominal unit's (thermal_fit_state.h's SetUpFit()), and its Jacobian
// at the start, without solving and without simulating noise.
//
//   F = J^T J (free parameters q of each sensor; rows are the windows' normalised residuals),
//   C = F^-1 + the covariance a wandering bias adds (FitOptions::*_bias_stability_*),
//
// the covariance the fit will report for a run of the plan with the noise the windows carry (its
// reduced chi-square near 1). Parameters are reported in powers of dT = T - 25 degC (the
// calibration file's basis) through the exact map p_ref = R diag(step) q of each coefficient.
#ifndef IMUFIT_FIT_PLAN_INFORMATION_H_
#define IMUFIT_FIT_PLAN_INFORMATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/fit/thermal_fit.h"

namespace imufit {

// One sensor's share: everything in its free parameters q (the fit's solver variables).
struct SensorInformation {
  bool is_gyro = false;
  std::vector<int> free;  // column -> parameter (sensor_model.h layout)
  // The Jacobian of the normalised residuals in q: 3 rows per window of this sensor, and the run's
  // window (index into the windows given) of each row triple.
  Eigen::MatrixXd jacobian;
  std::vector<int> window_index;
  // q -> parameters in powers of dT: p_ref = to_reference * q (rows: every parameter of the layout).
  Eigen::MatrixXd to_reference;
  // Covariance of q: white noise alone (F^-1) and with the wandering bias.
  Eigen::MatrixXd covariance_white;
  Eigen::MatrixXd covariance;
};

struct PlanInformation {
  // The fit's findings: what the plan does not determine (coverage and rank, the fit's own words),
  // and the weak directions (singular value of the column-normalised Jacobian below weak_tolerance
  // of the largest) in the same words. Nothing else is set when `undetermined` is not empty.
  std::vector<std::string> undetermined;
  std::vector<std::string> weak;
  TemperatureBasis basis;  // the fit basis the plan's temperatures give
  SensorInformation gyro;
  SensorInformation accel;
};

// The information of `windows` (a planned run: raw means of the nominal unit, noise figures of the
// planned noise) for the fit of `options`.
PlanInformation ComputePlanInformation(const std::vector<Window>& windows, const TableSite& site,
                                       const std::vector<TableSegment>& segments, const FitOptions& options,
                                       double weak_tolerance);

}  // namespace imufit

#endif  // IMUFIT_FIT_PLAN_INFORMATION_H_
