// imufit — the thermal fit: every coefficient of the model of docs/spec.md section 1, with its cubic
// temperature dependence, estimated jointly from all windows of a multi-position,
// multi-temperature rate-table run.
//
// Problem. For each window w (windows.h) with true rate omega_w and specific force a_w (from the
// plan, Earth rate and lever arms included, model/rate_table.h) and temperature x_w in the fit
// basis (x = (T - centre) / half range, about [-1, 1] over the run):
//
//   minimise  sum_w rho(|K_g (correct_g(B_w; x_w, a_w) - omega_w) / sigma_g,w|^2)
//                 + rho(|K_a (correct_a(A_w; x_w) - a_w) / sigma_a,w|^2)     [accel: a_w known]
//
// with window_cost.h's residual, the shared model's correction mapped back to raw units by
// K = diag(S) inv(M), and sigma the window's noise of the mean in raw units (fixed weights). A
// turn's window is its whole occurrence with omega_w its mean rate; where gravity turns in the
// body frame the accelerometer is not fitted and a_w is the corrected accelerometer mean. Gyro and
// accelerometer parameters form two blocks (84 and 48); terms above the chosen temperature order, and the
// g-sensitivity when it is left out, are held at zero.
//
// Start. The forward model raw = K(x) truth + V(x) + H(x) a with K = diag(S) inv(M) is linear
// in the polynomial coefficients of K, V and H: a weighted linear least-squares solve gives
// them; S and M follow from K^-1 = M diag(1/S) at Chebyshev nodes, and a cubic fit through
// those. Levenberg-Marquardt then converges in a few iterations.
//
// Observability. Before solving, the coverage of the run is checked coefficient group by group
// (rate about each axis, gravity along +-each axis, distinct temperatures), so that a run that
// cannot determine the model is refused with a message naming what is missing. After solving,
// the rank of the column-normalised Jacobian is checked as a backstop.
//
// Uncertainty. ceres::Covariance at the solution, inflated per sensor by the measured reduced
// chi-square when it exceeds 1 (never shrunk: the weights are absolute noise figures), plus (when the unit's
// bias stability is given) the covariance a bias that wanders between time blocks adds, converted exactly to
// powers of dT = T - 25 degC.
#ifndef IMUFIT_FIT_THERMAL_FIT_H_
#define IMUFIT_FIT_THERMAL_FIT_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/base/robust_loss.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sensor_model.h"
#include "imufit/run/windows.h"

namespace imufit {

// RobustLoss, its names and parser: imufit/base/robust_loss.h.

// How much of one sensor's model a fit estimates; the rest is held (FitOptions::held).
enum class SensorFit {
  kAll,   // every group
  kBias,  // the bias only: scale, misalignment (and the gyro g-sensitivity) held
  kNone,  // nothing: every group held
};

struct FitOptions {
  // What is fitted, per sensor (`imufit fit --fit`): a static-only run determines the accelerometer
  // and the gyro bias but not the gyro scale or misalignment, which need rotation.
  SensorFit gyro_fit = SensorFit::kAll;
  SensorFit accel_fit = SensorFit::kAll;
  // The values of the held groups (reference basis, any order): a prior calibration. Without one,
  // held scales are 1 (raw already in rad/s, m/s^2) and held biases, misalignments and
  // g-sensitivities 0.
  std::optional<SensorModel> held;
  // Order of the temperature polynomial of every gyro / accelerometer coefficient (0..3).
  int gyro_temp_order = 3;
  int accel_temp_order = 3;
  // Fit the gyro g-sensitivity H; when false it is held at zero.
  bool fit_g_sensitivity = true;
  // Robust loss on each window's normalised residual, and where it starts to act, in units of
  // the run's robust residual spread (1.4826 x the median absolute normalised residual).
  RobustLoss loss = RobustLoss::kHuber;
  double loss_scale = 3.0;
  // The unit's in-run bias stability, 1-sigma (rad/s, m/s^2): how far its bias wanders over
  // bias_correlation_s (bias instability and random walk together; `imufit allan` on a long static
  // log measures it). A wandering bias looks like a bias to any estimator; it cannot be removed,
  // but it is added to the reported uncertainty. 0: the uncertainty reflects white noise only.
  double gyro_bias_stability_radps = 0.0;
  double accel_bias_stability_mps2 = 0.0;
  // Windows closer in time than this share one realisation of the wandering bias, s.
  double bias_correlation_s = 100.0;
  // Levenberg-Marquardt iterations at most, per pass.
  int max_iterations = 50;
  // Start from the closed-form solution (true), or from nominal scale factors and nothing else
  // (false: slower; for checking that the solver converges from a poor start).
  bool closed_form_start = true;
  // Threads for Ceres.
  int num_threads = 2;
  // Temperatures within this span count as one when counting distinct temperatures, degC.
  double distinct_temp_c = 1.0;
  // A rate segment excites an axis when its true rate about it is at least this, rad/s.
  double min_excitation_rate_radps = 0.1;
  // The backstop rank check: a direction of the column-normalised Jacobian whose singular value
  // is below this fraction of the largest is undetermined.
  double rank_tolerance = 1e-8;

  // An empty string when usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
  // Whether coefficient `coefficient` (sensor_model.h layout) of the gyro or the accelerometer is
  // fitted (true) or held at its stated value (false).
  bool Fits(bool gyro, int coefficient) const;
  // Every group, named "gyro.bias", "gyro.scale", "gyro.misalignment", "gyro.g_sensitivity",
  // "accel.bias", "accel.scale", "accel.misalignment", that is fitted (true) or held (false).
  std::vector<std::string> Groups(bool fitted) const;
};

// Parses `imufit fit --fit`: a comma-separated list of "all", "gyro", "gyro-bias", "accel",
// "accel-bias" (what is not named is held). On failure returns false and sets `error`.
bool ParseFitGroups(const std::string& list, FitOptions* options, std::string* error);
// The --fit text of what `options` fits: "all", "gyro-bias,accel", ...
std::string FitGroupsText(const FitOptions& options);

// Every option above, described once (model/option_table.h): the command's options, the Python
// keywords, the fingerprint and Validate() derive from it (fit_options.cc).
const OptionTable<FitOptions>& FitOptionTable();

// The residual of one window after the fit, SI units, body frame.
struct WindowResidual {
  int window = 0;  // index into the windows given to the fit
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_sigma_radps = Eigen::Vector3d::Zero();  // the weights used
  Eigen::Vector3d accel_sigma_mps2 = Eigen::Vector3d::Zero();
  bool downweighted = false;  // the robust loss acted on this window
};

enum class FitStatus {
  kNotRun,        // FitThermalModel() has not run
  kConverged,     // solved; the calibration is usable
  kNotConverged,  // the solver stopped without converging
  kUndetermined,  // the data do not determine the model; see `undetermined`
  kRefused,       // solved, but a scale factor is negative or changes sign; see `refusals`
};

struct FitSummary {
  FitStatus status = FitStatus::kNotRun;
  std::string termination = "not run";  // the solver's own words
  int iterations = -1;                  // over all passes
  double initial_cost = -1.0;           // Ceres cost, first pass
  double final_cost = -1.0;             // Ceres cost, last pass
  int windows_used = 0;
  int windows_downweighted = 0;
  // What was fitted per sensor (FitOptions::gyro_fit / accel_fit): the residual RMS of a sensor held
  // whole measures the held values, not a fit.
  SensorFit gyro_fit = SensorFit::kAll;
  SensorFit accel_fit = SensorFit::kAll;
  // What the data do not determine, one readable finding each, with what would determine it.
  std::vector<std::string> undetermined;
  // Why a solved model is refused (kRefused): a scale factor that is negative or changes sign over
  // the run's temperatures, with the sign convention to check.
  std::vector<std::string> refusals;
  // Distinct temperatures of the run (cluster centres), degC, and the range of the readings
  // in its windows (the calibration's fit_temp_range_c).
  std::vector<double> distinct_temps_c;
  std::array<double, 2> temp_range_c{0.0, 0.0};
  // Residual RMS over windows and axes, SI, unweighted.
  double gyro_rms_radps = -1.0;
  double accel_rms_mps2 = -1.0;
  // Reduced chi-square of the normalised residuals, per sensor (the covariance scale when above 1).
  double gyro_reduced_chi2 = -1.0;
  double accel_reduced_chi2 = -1.0;
  // Their degrees of freedom: the rows that weigh fully less the free parameters.
  int gyro_dof = -1;
  int accel_dof = -1;
  // The fitted model in powers of dT = T - 25 degC, and the 1-sigma of every parameter.
  SensorModel model;
  SensorModel sigma;
  std::vector<WindowResidual> residuals;

  bool IsSolutionUsable() const { return status == FitStatus::kConverged; }
  // One line: status, residuals, iterations.
  std::string BriefReport() const;
  // Several lines: the brief report, windows, temperatures, findings, termination.
  std::string FullReport() const;
};

// Fits the model to `windows` of a run on `site` whose segments are `segments` (every window's
// segment id must be among them: a programmer error otherwise).
FitSummary FitThermalModel(const std::vector<Window>& windows, const TableSite& site,
                           const std::vector<TableSegment>& segments, const FitOptions& options);

// Clusters temperatures: sorted, a new cluster whenever a value lies more than `span_c` above
// the first of the current cluster. Returns the cluster means.
std::vector<double> DistinctTemperatures(std::vector<double> temps_c, double span_c);

}  // namespace imufit

#endif  // IMUFIT_FIT_THERMAL_FIT_H_
