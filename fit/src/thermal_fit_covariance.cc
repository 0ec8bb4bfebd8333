// The result stages of the thermal fit (thermal_fit_state.h): each window's residual and the
// reduced chi-square, then the coefficients with their covariance, in powers of dT.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "thermal_fit_state.h"

namespace imufit::internal {
// Blocks of windows within which a slowly wandering bias is taken as constant: a new block starts
// when a window starts more than `correlation_s` after the block's first window (or after a
// gap of that length). Returns the block of each window.
std::vector<int> TimeBlocks(const std::vector<FitWindow>& windows, double correlation_s) {
  std::vector<int> order(windows.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return windows[a].window->start_s < windows[b].window->start_s; });
  std::vector<int> block(windows.size(), 0);
  int current = -1;
  double block_start = 0.0;
  for (int w : order) {
    const double start = windows[w].window->start_s;
    if (current < 0 || start - block_start > correlation_s) {
      ++current;
      block_start = start;
    }
    block[w] = current;
  }
  return block;
}

// The covariance (in q, all parameters) that a bias wandering by `stability` (SI, 1-sigma, per
// axis, constant within a time block and independent between blocks) adds to the estimate. The
// fit's own covariance cannot see it: a soak's common offset is absorbed by the temperature
// polynomial, so the residuals do not show it. By linear response, an offset b on axis a of the
// windows of block k moves the estimate by dq = C J^T dr with dr = b / sigma_w on those rows,
// C = (J^T J)^-1 (`unscaled_covariance`); the blocks and axes add up independently.
Eigen::MatrixXd BiasStabilityCovariance(const SensorProblem& sensor,
                                        const Eigen::MatrixXd& unscaled_covariance,
                                        const std::vector<int>& time_blocks, double stability) {
  const int blocks = time_blocks.empty() ? 0 : *std::max_element(time_blocks.begin(), time_blocks.end()) + 1;
  const int n = static_cast<int>(sensor.free.size());
  Eigen::MatrixXd free_covariance(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) free_covariance(i, j) = unscaled_covariance(sensor.free[i], sensor.free[j]);
  }
  Eigen::MatrixXd added = Eigen::MatrixXd::Zero(n, n);
  for (int block = 0; block < blocks; ++block) {
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::VectorXd gradient = Eigen::VectorXd::Zero(n);  // J^T dr
      for (size_t b = 0; b < sensor.windows.size(); ++b) {
        if (time_blocks[sensor.window_index[b]] != block) continue;
        const int row = 3 * static_cast<int>(b) + axis;
        gradient += sensor.jacobian.row(row).transpose() * (stability / sensor.sigma[b](axis));
      }
      const Eigen::VectorXd shift = free_covariance * gradient;
      added += shift * shift.transpose();
    }
  }
  Eigen::MatrixXd ambient = Eigen::MatrixXd::Zero(sensor.parameters, sensor.parameters);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) ambient(sensor.free[i], sensor.free[j]) = added(i, j);
  }
  return ambient;
}

namespace {

// One sensor's residuals (SI, each window's; the weights used) in `summary->residuals`, its RMS
// and its reduced chi-square. The normalised residual r is the raw error over sigma_raw, so
// r .* sigma (the SI noise at the start's scale) is the error in SI to first order. The windows
// the robust loss acts on (|r| above its threshold) are flagged and left out of chi-square and
// of its degrees of freedom: the chi-square measures the windows that weigh fully.
void SensorResiduals(const FitOptions& options, const ceres::Problem& problem, const SensorProblem& sensor,
                     FitSummary* summary) {
  const std::vector<double> norms = NormalisedResidualNorms(problem, sensor);
  double chi2 = 0.0;
  int rows = 0;
  double sum_squares = 0.0;
  for (size_t w = 0; w < sensor.windows.size(); ++w) {
    double residual[3];
    double cost = 0.0;
    problem.EvaluateResidualBlock(sensor.blocks[w], false, &cost, residual, nullptr);
    const Eigen::Vector3d si = Eigen::Map<const Eigen::Vector3d>(residual).cwiseProduct(sensor.sigma[w]);
    WindowResidual& out = summary->residuals[sensor.window_index[w]];
    out.window = sensor.window_index[w];
    (sensor.is_gyro ? out.gyro_radps : out.accel_mps2) = si;
    (sensor.is_gyro ? out.gyro_sigma_radps : out.accel_sigma_mps2) = sensor.sigma[w];
    const bool downweighted =
        options.loss != RobustLoss::kNone && !sensor.IsFullyHeld() && norms[w] > sensor.loss_threshold;
    out.downweighted = out.downweighted || downweighted;
    sum_squares += si.squaredNorm();
    if (!downweighted) {
      chi2 += norms[w] * norms[w];
      rows += 3;
    }
  }
  const int free_parameters = sensor.parameters - static_cast<int>(sensor.held.size());
  const double rms = std::sqrt(sum_squares / (3.0 * std::max<size_t>(sensor.windows.size(), 1)));
  const double reduced_chi2 = rows > free_parameters ? chi2 / (rows - free_parameters) : 1.0;
  (sensor.is_gyro ? summary->gyro_rms_radps : summary->accel_rms_mps2) = rms;
  (sensor.is_gyro ? summary->gyro_reduced_chi2 : summary->accel_reduced_chi2) = reduced_chi2;
  (sensor.is_gyro ? summary->gyro_dof : summary->accel_dof) = std::max(rows - free_parameters, 0);
}

// One sensor's covariance of q: Ceres's (null when it could not be computed, or for a sensor held
// whole: zero), inflated by max(1, reduced chi-square), plus the wandering bias's share. The
// weights are absolute (each window's noise measured from its own samples), so the covariance
// needs no scaling where the model explains the run. The reduced chi-square only inflates it,
// where the residuals say the model or the noise figures fall short (the Particle Data Group's
// scale factor max(1, chi2 / dof)). Scaling it down too would put the chi-square's own scatter
// into every sigma: with the few degrees of freedom of a small run (a hand session: 27 gyro
// residuals, 21 parameters) the z-scores then follow a Student t with 6 degrees of freedom, not a
// normal (measured: z RMS 1.30 over 288 gyro scales, 10 beyond 3 sigma).
Eigen::MatrixXd SensorCovarianceInQ(const FitOptions& options, const ceres::Covariance* covariance,
                                    const SensorProblem& sensor, const std::vector<int>& time_blocks,
                                    double reduced_chi2) {
  Eigen::MatrixXd cov_q = Eigen::MatrixXd::Zero(sensor.parameters, sensor.parameters);
  if (covariance != nullptr && !sensor.IsFullyHeld()) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> block(sensor.parameters,
                                                                                 sensor.parameters);
    covariance->GetCovarianceBlock(sensor.q, sensor.q, block.data());
    cov_q = block;
  }
  const double scale2 = std::max(1.0, reduced_chi2);
  cov_q *= scale2;
  const double stability =
      sensor.is_gyro ? options.gyro_bias_stability_radps : options.accel_bias_stability_mps2;
  if (covariance != nullptr && stability > 0.0 && !sensor.IsFullyHeld()) {
    cov_q += BiasStabilityCovariance(sensor, cov_q / scale2, time_blocks, stability);
  }
  return cov_q;
}

// One sensor's coefficients and sigmas in the summary, in powers of dT = T - 25 degC: p = p0 +
// step .* q, so cov(p) = diag(step) cov(q) diag(step) per coefficient's 4 terms, and the rebase
// R to the reference basis (exact for a cubic) gives R p and R cov(p) R^T. Sigmas are -1 without
// a covariance.
void WriteCoefficients(const SensorProblem& sensor, const Eigen::MatrixXd& cov_q,
                       const Eigen::Matrix4d& to_reference, bool have_covariance, FitSummary* summary) {
  const std::vector<double> p = sensor.Parameters();
  double* model_out = sensor.is_gyro ? summary->model.gyro.data() : summary->model.accel.data();
  double* sigma_out = sensor.is_gyro ? summary->sigma.gyro.data() : summary->sigma.accel.data();
  for (int c = 0; c < sensor.coefficients; ++c) {
    const int first = c * kPolynomialTerms;
    const Eigen::Vector4d coefficients = to_reference * Eigen::Map<const Eigen::Vector4d>(p.data() + first);
    Eigen::Matrix4d cov_p = cov_q.block<4, 4>(first, first);
    const Eigen::Vector4d step = Eigen::Map<const Eigen::Vector4d>(sensor.step.data() + first);
    cov_p = step.asDiagonal() * cov_p * step.asDiagonal();
    const Eigen::Matrix4d cov_reference = to_reference * cov_p * to_reference.transpose();
    for (int k = 0; k < kPolynomialTerms; ++k) {
      model_out[first + k] = coefficients(k);
      sigma_out[first + k] = have_covariance ? std::sqrt(std::max(0.0, cov_reference(k, k))) : -1.0;
    }
  }
}

}  // namespace

// Stage: residuals. Every window's residual in SI, each sensor's RMS and reduced chi-square (the
// covariance's scale), and how many windows the robust loss acted on.
void ComputeResiduals(const FitOptions& options, const ThermalFitState& fit, FitSummary* summary) {
  summary->residuals.resize(fit.windows.size());
  for (const SensorProblem* sensor : fit.Sensors()) SensorResiduals(options, fit.problem, *sensor, summary);
  summary->windows_downweighted =
      static_cast<int>(std::count_if(summary->residuals.begin(), summary->residuals.end(),
                                     [](const WindowResidual& r) { return r.downweighted; }));
}

// Stage: covariance. Ceres's covariance of q at the solution (dense SVD, the loss applied: the
// down-weighted windows count as little as they did in the solve), per sensor to p and to powers
// of dT, with the model itself. Without a covariance (numerically rank deficient) the model is
// written, the sigmas are -1 and the fit ends undetermined.
bool ComputeCovariance(const FitOptions& options, ThermalFitState* fit, FitSummary* summary) {
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = options.num_threads;
  covariance_options.apply_loss_function = true;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> covariance_blocks;
  for (const SensorProblem* sensor : fit->Sensors()) {
    if (!sensor->IsFullyHeld()) covariance_blocks.emplace_back(sensor->q, sensor->q);
  }
  const bool have_covariance = covariance.Compute(covariance_blocks, &fit->problem);
  const std::vector<int> time_blocks = TimeBlocks(fit->windows, options.bias_correlation_s);
  const Eigen::Matrix4d to_reference = RebaseTemperaturePolynomial(fit->basis, TemperatureBasis::Reference());
  summary->model.basis = TemperatureBasis::Reference();
  summary->sigma.basis = TemperatureBasis::Reference();
  for (const SensorProblem* sensor : fit->Sensors()) {
    const double reduced_chi2 = sensor->is_gyro ? summary->gyro_reduced_chi2 : summary->accel_reduced_chi2;
    const Eigen::MatrixXd cov_q = SensorCovarianceInQ(options, have_covariance ? &covariance : nullptr,
                                                      *sensor, time_blocks, reduced_chi2);
    WriteCoefficients(*sensor, cov_q, to_reference, have_covariance, summary);
  }
  if (have_covariance) return true;
  summary->undetermined.push_back(
      "the covariance could not be computed (the problem is numerically rank deficient)");
  MarkUndetermined(summary);
  return false;
}

}  // namespace imufit::internal
