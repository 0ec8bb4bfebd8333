#include "imufit/fit/thermal_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <numeric>

#include <ceres/ceres.h>
#include <Eigen/Dense>
#include <Eigen/SVD>

#include "coverage.h"
#include "imufit/fit/window_cost.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

using internal::FitWindow;

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr char kAxis[] = "xyz";
// Chebyshev nodes used to turn the closed-form K(x) into S(x) and M(x).
constexpr int kStartNodes = 9;
// Floor on a window's noise, as a fraction of the median window noise of its sensor: a window
// whose samples happen to be all equal must not get an infinite weight.
constexpr double kSigmaFloorFraction = 0.1;
// The robust spread of normalised residuals from their median absolute value (Gaussian).
constexpr double kMadToSigma = 1.4826;
// The robust spread of the normalised residuals is never taken below one measured noise.
constexpr double kMinRobustSpread = 1.0;

// One sensor's share of the problem.
struct SensorProblem {
  const char* name = "";
  int parameters = 0;
  int coefficients = 0;
  int order = 3;
  bool with_g_sensitivity = false;
  std::vector<double> p0;    // start, fit basis
  std::vector<double> step;  // scale of each parameter
  std::vector<double> q;     // the solver's variables
  std::vector<int> held;     // parameters held at their start value
  // This sensor's windows (the accelerometer's are those whose specific force is known; the
  // gyro's carry the specific force its g-sensitivity term sees) and their index in the run.
  std::vector<FitWindow> windows;
  std::vector<int> window_index;
  std::vector<Eigen::Vector3d> sigma_raw;  // per window: noise of the mean, raw units (the weights)
  std::vector<Eigen::Vector3d> sigma;      // the same in SI at the start's scale (for reports)
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

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// What a window's sensor responds to: (truth, specific force) for its rows.
const Eigen::Vector3d& TruthFor(const FitWindow& w, bool gyro) {
  return gyro ? w.truth.omega_radps : w.truth.a_mps2;
}
const Eigen::Vector3d& RawFor(const FitWindow& w, bool gyro) {
  return gyro ? w.window->gyro_mean : w.window->accel_mean;
}
// The noise of a window's mean, raw units (windows.h).
Eigen::Vector3d RawSigmaFor(const FitWindow& w, bool gyro) { return w.window->NoiseOfMean(gyro); }

// The closed-form start of one sensor: raw_i = sum_j K_ij(x) truth_j + V_i(x) + sum_j H_ij(x) a_j
// by weighted linear least squares per axis, then S and M from K^-1 = M diag(1/S).
void LinearStart(const std::vector<FitWindow>& windows, bool gyro, SensorProblem* sensor) {
  const int terms = sensor->order + 1;
  const int blocks = 4 + (sensor->with_g_sensitivity ? 3 : 0);  // K row (3), V (1), H row (3)
  const int n = blocks * terms;
  const int m = static_cast<int>(windows.size());
  // K_ij, V_i, H_ij polynomials in the fit basis.
  Eigen::Matrix<double, 9, 4> K = Eigen::Matrix<double, 9, 4>::Zero();
  Eigen::Matrix<double, 3, 4> V = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix<double, 9, 4> H = Eigen::Matrix<double, 9, 4>::Zero();
  for (int i = 0; i < 3; ++i) {
    Eigen::MatrixXd design(m, n);
    Eigen::VectorXd rhs(m);
    for (int r = 0; r < m; ++r) {
      const FitWindow& w = windows[r];
      const double weight = 1.0 / sensor->sigma_raw[r](i);
      Eigen::Matrix<double, 7, 1> regressor;
      regressor << TruthFor(w, gyro), 1.0, w.truth.a_mps2;
      double power = 1.0;
      for (int k = 0; k < terms; ++k, power *= w.x) {
        for (int b = 0; b < blocks; ++b) design(r, b * terms + k) = weight * regressor(b) * power;
      }
      rhs(r) = weight * RawFor(w, gyro)(i);
    }
    const Eigen::VectorXd column_norm = design.colwise().norm().transpose().cwiseMax(1e-300);
    const Eigen::VectorXd solution = design.array()
                                         .rowwise()
                                         .
                                         operator/(column_norm.transpose().array())
                                         .matrix()
                                         .completeOrthogonalDecomposition()
                                         .solve(rhs)
                                         .cwiseQuotient(column_norm);
    for (int k = 0; k < terms; ++k) {
      for (int j = 0; j < 3; ++j) K(3 * i + j, k) = solution(j * terms + k);
      V(i, k) = solution(3 * terms + k);
      if (sensor->with_g_sensitivity) {
        for (int j = 0; j < 3; ++j) H(3 * i + j, k) = solution((4 + j) * terms + k);
      }
    }
  }
  // S and M at Chebyshev nodes over the run's temperatures, then a polynomial through them.
  double x_min = windows.front().x;
  double x_max = x_min;
  for (const FitWindow& w : windows) {
    x_min = std::min(x_min, w.x);
    x_max = std::max(x_max, w.x);
  }
  Eigen::MatrixXd vandermonde(kStartNodes, terms);
  Eigen::MatrixXd values(kStartNodes, 9);  // S x, y, z, M xy xz yx yz zx zy
  for (int node = 0; node < kStartNodes; ++node) {
    const double x =
        0.5 * (x_min + x_max) + 0.5 * (x_max - x_min) * std::cos(M_PI * (node + 0.5) / kStartNodes);
    Eigen::Matrix3d k_at;
    for (int e = 0; e < 9; ++e) {
      const Eigen::Vector4d c = K.row(e).transpose();
      k_at(e / 3, e % 3) = EvaluateTemperaturePolynomial(c.data(), x);
    }
    const Eigen::Matrix3d k_inverse = k_at.inverse();  // = M diag(1/S)
    for (int j = 0; j < 3; ++j) values(node, j) = 1.0 / k_inverse(j, j);
    for (int m_index = 0; m_index < 6; ++m_index) {
      const int row = kMisalignmentRow[m_index];
      const int col = kMisalignmentCol[m_index];
      values(node, 3 + m_index) = k_inverse(row, col) * values(node, col);
    }
    double power = 1.0;
    for (int k = 0; k < terms; ++k, power *= x) vandermonde(node, k) = power;
  }
  const Eigen::MatrixXd fitted = vandermonde.colPivHouseholderQr().solve(values);  // terms x 9

  sensor->p0.assign(sensor->parameters, 0.0);
  const auto set = [&](int coefficient, int k, double value) {
    sensor->p0[coefficient * kPolynomialTerms + k] = value;
  };
  for (int k = 0; k < terms; ++k) {
    for (int i = 0; i < 3; ++i) {
      set(kBiasCoefficient + i, k, V(i, k));
      set(kScaleCoefficient + i, k, fitted(k, i));
    }
    for (int m_index = 0; m_index < 6; ++m_index)
      set(kMisalignmentCoefficient + m_index, k, fitted(k, 3 + m_index));
    if (sensor->with_g_sensitivity) {
      for (int h = 0; h < 9; ++h) set(kGSensitivityCoefficient + h, k, H(h, k));
    }
  }
}

// The stated values of one sensor's groups in the fit basis `basis`: the prior calibration's, or
// scale 1 and everything else 0 (FitOptions::held).
std::vector<double> HeldParameters(const FitOptions& options, bool gyro, const TemperatureBasis& basis) {
  const int coefficients = gyro ? kGyroCoefficients : kAccelCoefficients;
  std::vector<double> p(coefficients * kPolynomialTerms, 0.0);
  if (!options.held) {
    for (int axis = 0; axis < 3; ++axis) p[(kScaleCoefficient + axis) * kPolynomialTerms] = 1.0;
    return p;
  }
  const Eigen::Matrix4d rebase = RebaseTemperaturePolynomial(options.held->basis, basis);
  const double* prior = gyro ? options.held->gyro.data() : options.held->accel.data();
  for (int c = 0; c < coefficients; ++c) {
    Eigen::Map<Eigen::Vector4d>(p.data() + c * kPolynomialTerms) =
        rebase * Eigen::Map<const Eigen::Vector4d>(prior + c * kPolynomialTerms);
  }
  return p;
}

// The start of a bias-only sensor whose other groups are held at `sensor->p0`: the bias
// polynomial by weighted linear least squares on raw - ForwardSensor(held groups, truth).
void BiasStart(const std::vector<FitWindow>& windows, bool gyro, SensorProblem* sensor) {
  const int terms = sensor->order + 1;
  const int m = static_cast<int>(windows.size());
  std::vector<double> held = sensor->p0;
  for (int i = 0; i < 3 * kPolynomialTerms; ++i) held[kBiasCoefficient * kPolynomialTerms + i] = 0.0;
  for (int i = 0; i < 3; ++i) {
    Eigen::MatrixXd design(m, terms);
    Eigen::VectorXd rhs(m);
    for (int r = 0; r < m; ++r) {
      const FitWindow& w = windows[r];
      const double weight = 1.0 / sensor->sigma_raw[r](i);
      const SensorCoefficients<double> c = CoefficientsAt(held.data(), sensor->coefficients, w.x);
      const Eigen::Vector3d predicted = ForwardSensor(c, TruthFor(w, gyro), w.truth.a_mps2);
      double power = 1.0;
      for (int k = 0; k < terms; ++k, power *= w.x) design(r, k) = weight * power;
      rhs(r) = weight * (RawFor(w, gyro)(i) - predicted(i));
    }
    const Eigen::VectorXd bias = design.completeOrthogonalDecomposition().solve(rhs);
    for (int k = 0; k < kPolynomialTerms; ++k) {
      sensor->p0[(kBiasCoefficient + i) * kPolynomialTerms + k] = k < terms ? bias(k) : 0.0;
    }
  }
}

// Parameter magnitudes for the solver's scaling: about 1 mrad/s (gyro) or 1 mm/s^2 (accel) of
// bias, 1e-3 of scale, 1 mrad of misalignment, 1e-4 rad/s per m/s^2 of g-sensitivity.
void SetSteps(SensorProblem* sensor) {
  sensor->step.assign(sensor->parameters, 1.0);
  for (int c = 0; c < sensor->coefficients; ++c) {
    double step = 1e-3;
    const int row = c < kMisalignmentCoefficient    ? (c % 3)
                    : c >= kGSensitivityCoefficient ? (c - kGSensitivityCoefficient) / 3
                                                    : 0;
    const double scale = std::abs(sensor->p0[(kScaleCoefficient + row) * kPolynomialTerms]);
    if (c < kMisalignmentCoefficient)
      step = 1e-3 * scale;  // bias, scale
    else if (c >= kGSensitivityCoefficient)
      step = 1e-4 * scale;  // g-sensitivity
    for (int k = 0; k < kPolynomialTerms; ++k)
      sensor->step[c * kPolynomialTerms + k] = step > 0.0 ? step : 1e-3;
  }
}

// Window noise: the noise of the raw mean (the weights, fixed: they do not move with the
// parameters), floored, and the same in SI at the start's scale factor (for reports and the
// bias-stability covariance).
void SetSigmas(bool gyro, SensorProblem* sensor) {
  const size_t count = sensor->windows.size();
  sensor->sigma_raw.assign(count, Eigen::Vector3d::Ones());
  sensor->sigma.assign(count, Eigen::Vector3d::Ones());
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (size_t w = 0; w < count; ++w) {
      sensor->sigma_raw[w](axis) = RawSigmaFor(sensor->windows[w], gyro)(axis);
      values.push_back(sensor->sigma_raw[w](axis));
    }
    const double floor = kSigmaFloorFraction * Median(values);
    const double scale =
        std::abs(sensor->p0.empty() ? 1.0 : sensor->p0[(kScaleCoefficient + axis) * kPolynomialTerms]);
    for (size_t w = 0; w < count; ++w) {
      double& s = sensor->sigma_raw[w](axis);
      s = floor > 0.0 ? std::max(s, floor) : 1.0;
      sensor->sigma[w](axis) = s / (scale > 0.0 ? scale : 1.0);
    }
  }
}

std::string ParameterName(const SensorProblem& sensor, int parameter) {
  const CoefficientName& name = kCoefficientNames[parameter / kPolynomialTerms];
  const int k = parameter % kPolynomialTerms;
  return std::string(sensor.name) + " " + name.group + " " + name.axis +
         (k == 0   ? ""
          : k == 1 ? " (linear term)"
          : k == 2 ? " (quadratic term)"
                   : " (cubic term)");
}

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

}  // namespace

std::vector<double> DistinctTemperatures(std::vector<double> temps_c, double span_c) {
  std::sort(temps_c.begin(), temps_c.end());
  std::vector<double> centres;
  size_t begin = 0;
  for (size_t i = 1; i <= temps_c.size(); ++i) {
    if (i == temps_c.size() || temps_c[i] > temps_c[begin] + span_c) {
      if (i > begin) {
        centres.push_back(std::accumulate(temps_c.begin() + begin, temps_c.begin() + i, 0.0) /
                          static_cast<double>(i - begin));
      }
      begin = i;
    }
  }
  return centres;
}

FitSummary FitThermalModel(const std::vector<Window>& windows, const TableSite& site,
                           const std::vector<TableSegment>& segments, const FitOptions& options) {
  const std::string invalid_options = options.Validate();
  IMUFIT_CHECK(invalid_options.empty(), invalid_options.c_str());
  FitSummary summary;
  summary.gyro_fit = options.gyro_fit;
  summary.accel_fit = options.accel_fit;

  // Truth and temperature basis.
  std::vector<double> temps;
  for (const Window& w : windows) temps.push_back(w.temp_c);
  summary.distinct_temps_c = DistinctTemperatures(temps, options.distinct_temp_c);
  TemperatureBasis basis;
  if (!temps.empty()) {
    const auto [lo, hi] = std::minmax_element(temps.begin(), temps.end());
    summary.temp_range_c = {windows.front().min_temp_c, windows.front().max_temp_c};
    for (const Window& w : windows) {
      summary.temp_range_c[0] = std::min(summary.temp_range_c[0], w.min_temp_c);
      summary.temp_range_c[1] = std::max(summary.temp_range_c[1], w.max_temp_c);
    }
    basis.center_c = 0.5 * (*lo + *hi);
    basis.half_range_c = std::max(0.5 * (*hi - *lo), 1.0);
  }
  std::vector<FitWindow> fit_windows;
  for (const Window& w : windows) {
    const auto segment = std::find_if(segments.begin(), segments.end(),
                                      [&](const TableSegment& s) { return s.id == w.segment; });
    IMUFIT_CHECK(segment != segments.end(), "every window's segment must be in the plan");
    // A turn's truth is its whole occurrence's mean rate: the window must be that occurrence.
    // Windows built without the plan would bias the fit.
    IMUFIT_CHECK(!segment->IsTurn() || w.whole_occurrence,
                 "a window of a turn segment must be its whole occurrence");
    const SegmentTruth truth =
        segment->IsTurn() ? TurnTruth(site, *segment, w.DurationS()) : TruthOf(site, *segment);
    fit_windows.push_back(FitWindow{&w, truth, basis.Argument(w.temp_c), segment->SpecificForceIsKnown()});
  }
  summary.windows_used = static_cast<int>(fit_windows.size());

  summary.undetermined = internal::CheckCoverage(fit_windows, site.gravity_mps2, options);
  if (!summary.undetermined.empty()) {
    summary.status = FitStatus::kUndetermined;
    summary.termination = "the run does not determine the model";
    return summary;
  }

  SensorProblem gyro;
  gyro.name = "gyro";
  gyro.parameters = kGyroParameters;
  gyro.coefficients = kGyroCoefficients;
  gyro.order = options.gyro_temp_order;
  gyro.with_g_sensitivity = options.Fits(true, kGSensitivityCoefficient);
  SensorProblem accel;
  accel.name = "accel";
  accel.parameters = kAccelParameters;
  accel.coefficients = kAccelCoefficients;
  accel.order = options.accel_temp_order;
  // The accelerometer first: where gravity turns in the body frame (a turn or a rate about a
  // non-vertical axis) the gyro's g-sensitivity term sees the window's corrected accelerometer
  // mean, at the accelerometer's closed-form start (which differs from its fit by far less than
  // the noise of that mean).
  for (size_t w = 0; w < fit_windows.size(); ++w) {
    if (!fit_windows[w].accel_known) continue;
    accel.windows.push_back(fit_windows[w]);
    accel.window_index.push_back(static_cast<int>(w));
  }
  for (SensorProblem* sensor : {&accel, &gyro}) {
    const bool is_gyro = sensor == &gyro;
    if (is_gyro) {
      for (size_t w = 0; w < fit_windows.size(); ++w) {
        FitWindow fw = fit_windows[w];
        if (!fw.accel_known) {
          const SensorCoefficients<double> c = CoefficientsAt(accel.p0.data(), kAccelCoefficients, fw.x);
          fw.truth.a_mps2 = CorrectSensor(c, fw.window->accel_mean, Eigen::Vector3d::Zero().eval());
        }
        gyro.windows.push_back(fw);
        gyro.window_index.push_back(static_cast<int>(w));
      }
    }
    SetSigmas(is_gyro, sensor);
    const SensorFit mode = is_gyro ? options.gyro_fit : options.accel_fit;
    const std::vector<double> held = HeldParameters(options, is_gyro, basis);
    if (mode == SensorFit::kAll) {
      LinearStart(sensor->windows, is_gyro, sensor);
    } else {
      sensor->p0 = held;
      SetSigmas(is_gyro, sensor);  // the weights at the held scale
      if (mode == SensorFit::kBias) BiasStart(sensor->windows, is_gyro, sensor);
    }
    if (!options.closed_form_start) {
      // Keep only the nominal scale factors: the solver must find everything else itself.
      for (int i = 0; i < sensor->parameters; ++i) {
        const int c = i / kPolynomialTerms;
        const bool nominal_scale =
            c >= kScaleCoefficient && c < kMisalignmentCoefficient && i % kPolynomialTerms == 0;
        if (!nominal_scale) sensor->p0[i] = 0.0;
      }
    }
    for (int i = 0; i < sensor->parameters; ++i) {
      if (!options.Fits(is_gyro, i / kPolynomialTerms)) sensor->p0[i] = held[i];
    }
    SetSigmas(is_gyro, sensor);  // the SI figures at the start's scale
    SetSteps(sensor);
    sensor->q.assign(sensor->parameters, 0.0);
    for (int c = 0; c < sensor->coefficients; ++c) {
      for (int k = 0; k < kPolynomialTerms; ++k) {
        if (k > sensor->order || !options.Fits(is_gyro, c)) sensor->held.push_back(c * kPolynomialTerms + k);
      }
    }
  }

  // One problem, solved twice: least squares, then (if asked) with the robust loss scaled by the
  // spread of the first pass's residuals.
  ceres::Problem problem;
  for (SensorProblem* sensor : {&gyro, &accel}) {
    sensor->loss = new ceres::LossFunctionWrapper(nullptr, ceres::TAKE_OWNERSHIP);
    for (size_t w = 0; w < sensor->windows.size(); ++w) {
      const FitWindow& fw = sensor->windows[w];
      ceres::CostFunction* cost = nullptr;
      if (sensor == &gyro) {
        cost = new ceres::AutoDiffCostFunction<WindowCost<kGyroParameters>, 3, kGyroParameters>(
            new WindowCost<kGyroParameters>(RawFor(fw, true), TruthFor(fw, true), fw.truth.a_mps2, fw.x,
                                            sensor->sigma_raw[w], sensor->p0.data(), sensor->step.data()));
      } else {
        cost = new ceres::AutoDiffCostFunction<WindowCost<kAccelParameters>, 3, kAccelParameters>(
            new WindowCost<kAccelParameters>(RawFor(fw, false), TruthFor(fw, false), fw.truth.a_mps2, fw.x,
                                             sensor->sigma_raw[w], sensor->p0.data(), sensor->step.data()));
      }
      sensor->blocks.push_back(problem.AddResidualBlock(cost, sensor->loss, sensor->q.data()));
    }
    if (static_cast<int>(sensor->held.size()) == sensor->parameters) {
      problem.SetParameterBlockConstant(sensor->q.data());  // every group held (SensorFit::kNone)
    } else if (!sensor->held.empty()) {
      problem.SetManifold(sensor->q.data(), new ceres::SubsetManifold(sensor->parameters, sensor->held));
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.function_tolerance = 1e-10;
  solver_options.parameter_tolerance = 1e-10;
  ceres::Solver::Summary solver_summary;
  ceres::Solve(solver_options, &problem, &solver_summary);
  summary.iterations = static_cast<int>(solver_summary.iterations.size()) - 1;
  summary.initial_cost = solver_summary.initial_cost;
  const auto normalised_norms = [&](const SensorProblem& sensor) {
    std::vector<double> norms;
    for (ceres::ResidualBlockId block : sensor.blocks) {
      double residual[3];
      double cost = 0.0;
      problem.EvaluateResidualBlock(block, /*apply_loss_function=*/false, &cost, residual, nullptr);
      norms.push_back(Eigen::Map<const Eigen::Vector3d>(residual).norm());
    }
    return norms;
  };
  if (options.loss != RobustLoss::kNone && solver_summary.termination_type == ceres::CONVERGENCE) {
    for (SensorProblem* sensor : {&gyro, &accel}) {
      if (sensor->IsFullyHeld()) continue;  // nothing to protect: its residuals move no estimate
      // The robust spread of one residual component; a window's 3-vector norm is compared with
      // loss_scale times it.
      std::vector<double> components;
      for (double norm : normalised_norms(*sensor)) components.push_back(norm / std::sqrt(3.0));
      // The residuals are in units of each window's measured noise, so the spread is at least 1: a
      // smaller median comes from windows the fit matches exactly (few windows for the parameters,
      // e.g. one turn per axis setting the scale), and the loss must not act on ordinary noise.
      const double spread = std::max(kMadToSigma * Median(components), kMinRobustSpread);
      sensor->loss_threshold = options.loss_scale * spread;
      if (options.loss == RobustLoss::kHuber) {
        sensor->loss->Reset(new ceres::HuberLoss(sensor->loss_threshold), ceres::TAKE_OWNERSHIP);
      } else {
        sensor->loss->Reset(new ceres::CauchyLoss(sensor->loss_threshold), ceres::TAKE_OWNERSHIP);
      }
    }
    ceres::Solve(solver_options, &problem, &solver_summary);
    summary.iterations += static_cast<int>(solver_summary.iterations.size()) - 1;
  }
  summary.final_cost = solver_summary.final_cost;
  summary.termination = solver_summary.message;
  if (solver_summary.termination_type != ceres::CONVERGENCE) {
    summary.status = FitStatus::kNotConverged;
    summary.termination = std::string(ceres::TerminationTypeToString(solver_summary.termination_type)) +
                          ": " + solver_summary.message;
    return summary;
  }

  // Backstop: the rank of the column-normalised Jacobian at the solution, per sensor.
  for (SensorProblem* sensor : {&gyro, &accel}) {
    if (sensor->IsFullyHeld()) continue;
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = {sensor->q.data()};
    evaluate.residual_blocks = sensor->blocks;
    evaluate.apply_loss_function = false;
    evaluate.num_threads = options.num_threads;
    ceres::CRSMatrix crs;
    problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int e = crs.rows[r]; e < crs.rows[r + 1]; ++e) jacobian(r, crs.cols[e]) = crs.values[e];
    }
    std::vector<int>& free = sensor->free;  // tangent column -> parameter
    for (int i = 0; i < sensor->parameters; ++i) {
      if (!sensor->IsHeld(i)) free.push_back(i);
    }
    IMUFIT_CHECK(static_cast<int>(free.size()) == jacobian.cols(), "one Jacobian column per free parameter");
    sensor->jacobian = jacobian;
    const Eigen::VectorXd column_norm = jacobian.colwise().norm().transpose();
    for (int c = 0; c < jacobian.cols(); ++c) {
      if (column_norm(c) > 0.0) jacobian.col(c) /= column_norm(c);
    }
    const Eigen::BDCSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
    const Eigen::VectorXd& singular = svd.singularValues();
    for (int d = 0; d < singular.size(); ++d) {
      if (singular(d) > options.rank_tolerance * singular(0)) continue;
      const Eigen::VectorXd direction = svd.matrixV().col(d);
      std::string names;
      for (int c = 0; c < direction.size(); ++c) {
        if (std::abs(direction(c)) < 0.3) continue;
        names += (names.empty() ? "" : ", ") + ParameterName(*sensor, free[c]);
      }
      summary.undetermined.push_back("the run cannot separate " + names +
                                     " (a combination of them does not change any residual)");
    }
  }
  if (!summary.undetermined.empty()) {
    summary.status = FitStatus::kUndetermined;
    summary.termination = "the run does not determine the model";
    return summary;
  }

  // Residuals, the covariance scale and the robust loss's verdicts.
  summary.residuals.resize(fit_windows.size());
  for (SensorProblem* sensor : {&gyro, &accel}) {
    const bool is_gyro = sensor == &gyro;
    const std::vector<double> norms = normalised_norms(*sensor);
    double chi2 = 0.0;
    int rows = 0;
    double sum_squares = 0.0;
    for (size_t w = 0; w < sensor->windows.size(); ++w) {
      double residual[3];
      double cost = 0.0;
      problem.EvaluateResidualBlock(sensor->blocks[w], false, &cost, residual, nullptr);
      // Raw error over the start's scale: the error in SI to first order.
      const Eigen::Vector3d si = Eigen::Map<const Eigen::Vector3d>(residual).cwiseProduct(sensor->sigma[w]);
      WindowResidual& out = summary.residuals[sensor->window_index[w]];
      out.window = sensor->window_index[w];
      (is_gyro ? out.gyro_radps : out.accel_mps2) = si;
      (is_gyro ? out.gyro_sigma_radps : out.accel_sigma_mps2) = sensor->sigma[w];
      const bool downweighted =
          options.loss != RobustLoss::kNone && !sensor->IsFullyHeld() && norms[w] > sensor->loss_threshold;
      out.downweighted = out.downweighted || downweighted;
      sum_squares += si.squaredNorm();
      if (!downweighted) {
        chi2 += norms[w] * norms[w];
        rows += 3;
      }
    }
    const int free_parameters = sensor->parameters - static_cast<int>(sensor->held.size());
    const double rms = std::sqrt(sum_squares / (3.0 * std::max<size_t>(sensor->windows.size(), 1)));
    const double reduced_chi2 = rows > free_parameters ? chi2 / (rows - free_parameters) : 1.0;
    (is_gyro ? summary.gyro_rms_radps : summary.accel_rms_mps2) = rms;
    (is_gyro ? summary.gyro_reduced_chi2 : summary.accel_reduced_chi2) = reduced_chi2;
  }
  summary.windows_downweighted =
      static_cast<int>(std::count_if(summary.residuals.begin(), summary.residuals.end(),
                                     [](const WindowResidual& r) { return r.downweighted; }));

  // Covariance of q, to p (times step), inflated by the reduced chi-square, to powers of dT.
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = options.num_threads;
  covariance_options.apply_loss_function = true;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> covariance_blocks;
  for (const SensorProblem* sensor : {&gyro, &accel}) {
    if (!sensor->IsFullyHeld()) covariance_blocks.emplace_back(sensor->q.data(), sensor->q.data());
  }
  const bool have_covariance = covariance.Compute(covariance_blocks, &problem);
  const std::vector<int> time_blocks = TimeBlocks(fit_windows, options.bias_correlation_s);
  const Eigen::Matrix4d to_reference = RebaseTemperaturePolynomial(basis, TemperatureBasis::Reference());
  summary.model.basis = TemperatureBasis::Reference();
  summary.sigma.basis = TemperatureBasis::Reference();
  for (SensorProblem* sensor : {&gyro, &accel}) {
    const bool is_gyro = sensor == &gyro;
    const std::vector<double> p = sensor->Parameters();
    Eigen::MatrixXd cov_q = Eigen::MatrixXd::Zero(sensor->parameters, sensor->parameters);
    if (have_covariance && !sensor->IsFullyHeld()) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> block(sensor->parameters,
                                                                                   sensor->parameters);
      covariance.GetCovarianceBlock(sensor->q.data(), sensor->q.data(), block.data());
      cov_q = block;
    }
    // The weights are absolute (each window's noise measured from its own samples), so the
    // covariance needs no scaling where the model explains the run. The reduced chi-square only
    // inflates it, where the residuals say the model or the noise figures fall short (the Particle
    // Data Group's scale factor max(1, chi2 / dof)). Scaling it down too would put the chi-square's
    // own scatter into every sigma: with the few degrees of freedom of a small run (a hand session:
    // 27 gyro residuals, 21 parameters) the z-scores then follow a Student t with 6 degrees of
    // freedom, not a normal (measured: z RMS 1.30 over 288 gyro scales, 10 beyond 3 sigma).
    const double scale2 = std::max(1.0, is_gyro ? summary.gyro_reduced_chi2 : summary.accel_reduced_chi2);
    cov_q *= scale2;
    const double stability = is_gyro ? options.gyro_bias_stability_radps : options.accel_bias_stability_mps2;
    if (have_covariance && stability > 0.0 && !sensor->IsFullyHeld()) {
      cov_q += BiasStabilityCovariance(*sensor, cov_q / scale2, time_blocks, stability);
    }
    double* model_out = is_gyro ? summary.model.gyro.data() : summary.model.accel.data();
    double* sigma_out = is_gyro ? summary.sigma.gyro.data() : summary.sigma.accel.data();
    for (int c = 0; c < sensor->coefficients; ++c) {
      const int first = c * kPolynomialTerms;
      const Eigen::Vector4d coefficients = to_reference * Eigen::Map<const Eigen::Vector4d>(p.data() + first);
      Eigen::Matrix4d cov_p = cov_q.block<4, 4>(first, first);
      const Eigen::Vector4d step = Eigen::Map<const Eigen::Vector4d>(sensor->step.data() + first);
      cov_p = step.asDiagonal() * cov_p * step.asDiagonal();
      const Eigen::Matrix4d cov_reference = to_reference * cov_p * to_reference.transpose();
      for (int k = 0; k < kPolynomialTerms; ++k) {
        model_out[first + k] = coefficients(k);
        sigma_out[first + k] = have_covariance ? std::sqrt(std::max(0.0, cov_reference(k, k))) : -1.0;
      }
    }
  }
  if (!have_covariance) {
    summary.undetermined.push_back(
        "the covariance could not be computed (the problem is numerically rank deficient)");
    summary.status = FitStatus::kUndetermined;
    summary.termination = "the run does not determine the model";
    return summary;
  }
  // A negative scale factor corrects every reading of its axis with the wrong sign: the unit's
  // (or the plan's) sign convention is the opposite of the body frame's. Refuse it by name.
  for (const bool is_gyro : {true, false}) {
    const double* params = is_gyro ? summary.model.gyro.data() : summary.model.accel.data();
    for (int axis = 0; axis < 3; ++axis) {
      const double* c = params + (kScaleCoefficient + axis) * kPolynomialTerms;
      const PolynomialExtremes e = ExtremesOverRange(c, summary.model.basis.center_c, summary.temp_range_c[0],
                                                     summary.temp_range_c[1]);
      if (e.min_value > 0.0) continue;
      char text[200];
      std::snprintf(text, sizeof text, "%s scale %c %s over the run's temperatures (%.6g at %.4g degC)",
                    is_gyro ? "gyro" : "accel", kAxis[axis],
                    e.max_value < 0.0 ? "is negative" : "changes sign", e.min_value, e.min_at_c);
      summary.refusals.push_back(std::string(text) + "; " + ScaleSignAdvice(is_gyro, axis));
    }
  }
  if (!summary.refusals.empty()) {
    summary.status = FitStatus::kRefused;
    summary.termination = "a scale factor is negative or changes sign";
    return summary;
  }
  summary.status = FitStatus::kConverged;
  return summary;
}

std::string FitSummary::BriefReport() const {
  char text[512];
  switch (status) {
    case FitStatus::kNotRun:
      return "fit not run";
    case FitStatus::kUndetermined:
      std::snprintf(text, sizeof text, "fit refused: the run does not determine the model (%zu finding%s)",
                    undetermined.size(), undetermined.size() == 1 ? "" : "s");
      return text;
    case FitStatus::kNotConverged:
      return "fit did not converge: " + termination;
    case FitStatus::kRefused: {
      std::string text = "fit refused: ";
      for (size_t i = 0; i < refusals.size(); ++i) text += (i ? "; and " : "") + refusals[i];
      return text;
    }
    case FitStatus::kConverged:
      break;
  }
  // A sensor held whole was not fitted: its residual says how far the held values are from the run.
  const char* gyro_note = gyro_fit == SensorFit::kNone ? " (gyro held, not fitted)" : "";
  const char* accel_note = accel_fit == SensorFit::kNone ? " (accel held, not fitted)" : "";
  std::snprintf(text, sizeof text,
                "converged in %d iterations; residual RMS gyro %.3g deg/s%s, accel %.3g mg%s; %d windows (%d "
                "down-weighted) over %zu temperatures",
                iterations, gyro_rms_radps * kRadToDeg, gyro_note, accel_rms_mps2 / 9.80665 * 1e3, accel_note,
                windows_used, windows_downweighted, distinct_temps_c.size());
  return text;
}

std::string FitSummary::FullReport() const {
  std::string report = BriefReport() + "\n";
  char line[512];
  std::snprintf(line, sizeof line, "  windows: %d used, %d down-weighted by the robust loss\n", windows_used,
                windows_downweighted);
  report += line;
  report += "  temperatures: " + std::to_string(distinct_temps_c.size()) + " distinct (" +
            internal::FormatTemperatures(distinct_temps_c) + ")\n";
  if (status == FitStatus::kConverged) {
    std::snprintf(line, sizeof line, "  reduced chi-square: gyro %.3g, accel %.3g (covariance scale)\n",
                  gyro_reduced_chi2, accel_reduced_chi2);
    report += line;
  }
  for (const std::string& finding : undetermined) report += "  undetermined: " + finding + "\n";
  report += "  termination: " + termination + "\n";
  return report;
}

}  // namespace imufit
