// The start stage of the thermal fit (thermal_fit_state.h): each sensor's windows, their weights,
// the closed-form start p0, the SI noise figures at the start's scale, the solver's steps and the
// held parameters.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "imufit/model/check.h"
#include "imufit/model/constants.h"
#include "thermal_fit_state.h"

namespace imufit::internal {
namespace {

// Chebyshev nodes used to turn the closed-form K(x) into S(x) and M(x).
constexpr int kStartNodes = 9;
// Floor on a window's noise, as a fraction of the median window noise of its sensor: a window
// whose samples happen to be all equal must not get an infinite weight.
constexpr double kSigmaFloorFraction = 0.1;

// The polynomials (fit basis, one column per power of x, zero above the order) of the forward
// model raw_i = sum_j K_ij(x) truth_j + V_i(x) + sum_j H_ij(x) a_j: rows of K and H are ij.
struct ForwardPolynomials {
  Eigen::Matrix<double, 9, 4> K = Eigen::Matrix<double, 9, 4>::Zero();
  Eigen::Matrix<double, 3, 4> V = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix<double, 9, 4> H = Eigen::Matrix<double, 9, 4>::Zero();
};

// The forward model is linear in the polynomial coefficients of K, V and H: per axis i, one
// weighted linear least-squares solve (rows weighted by 1 / sigma_raw, columns normalised so that
// the orthogonal decomposition sees a well-scaled design).
ForwardPolynomials FitForwardPolynomials(const SensorProblem& sensor) {
  const std::vector<FitWindow>& windows = sensor.windows;
  const int terms = sensor.order + 1;
  const int blocks = 4 + (sensor.with_g_sensitivity ? 3 : 0);  // K row (3), V (1), H row (3)
  const int n = blocks * terms;
  const int m = static_cast<int>(windows.size());
  ForwardPolynomials forward;
  for (int i = 0; i < 3; ++i) {
    Eigen::MatrixXd design(m, n);
    Eigen::VectorXd rhs(m);
    for (int r = 0; r < m; ++r) {
      const FitWindow& w = windows[r];
      const double weight = 1.0 / sensor.sigma_raw[r](i);
      Eigen::Matrix<double, 7, 1> regressor;
      regressor << TruthFor(w, sensor.is_gyro), 1.0, w.truth.a_mps2;
      double power = 1.0;
      for (int k = 0; k < terms; ++k, power *= w.x) {
        for (int b = 0; b < blocks; ++b) design(r, b * terms + k) = weight * regressor(b) * power;
      }
      rhs(r) = weight * RawFor(w, sensor.is_gyro)(i);
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
      for (int j = 0; j < 3; ++j) forward.K(3 * i + j, k) = solution(j * terms + k);
      forward.V(i, k) = solution(3 * terms + k);
      if (sensor.with_g_sensitivity) {
        for (int j = 0; j < 3; ++j) forward.H(3 * i + j, k) = solution((4 + j) * terms + k);
      }
    }
  }
  return forward;
}

// S and M are not polynomial in K's coefficients: K^-1 = M diag(1/S) gives them at kStartNodes
// Chebyshev nodes over the run's temperatures, and a polynomial of `terms` through those values
// (least squares) their start. Returns terms x 9: S x, y, z, M xy, xz, yx, yz, zx, zy.
Eigen::MatrixXd ScaleAndMisalignmentPolynomials(const Eigen::Matrix<double, 9, 4>& K,
                                                const std::vector<FitWindow>& windows, int terms) {
  double x_min = windows.front().x;
  double x_max = x_min;
  for (const FitWindow& w : windows) {
    x_min = std::min(x_min, w.x);
    x_max = std::max(x_max, w.x);
  }
  Eigen::MatrixXd vandermonde(kStartNodes, terms);
  Eigen::MatrixXd values(kStartNodes, 9);
  for (int node = 0; node < kStartNodes; ++node) {
    const double x =
        0.5 * (x_min + x_max) + 0.5 * (x_max - x_min) * std::cos(kPi * (node + 0.5) / kStartNodes);
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
  return vandermonde.colPivHouseholderQr().solve(values);
}

// The closed-form start of a sensor whose every group is fitted: K, V, H by linear least squares,
// then S and M from K.
void LinearStart(SensorProblem* sensor) {
  const int terms = sensor->order + 1;
  const ForwardPolynomials forward = FitForwardPolynomials(*sensor);
  const Eigen::MatrixXd fitted = ScaleAndMisalignmentPolynomials(forward.K, sensor->windows, terms);
  sensor->p0.assign(sensor->parameters, 0.0);
  const auto set = [&](int coefficient, int k, double value) {
    sensor->p0[coefficient * kPolynomialTerms + k] = value;
  };
  for (int k = 0; k < terms; ++k) {
    for (int i = 0; i < 3; ++i) {
      set(kBiasCoefficient + i, k, forward.V(i, k));
      set(kScaleCoefficient + i, k, fitted(k, i));
    }
    for (int m_index = 0; m_index < 6; ++m_index)
      set(kMisalignmentCoefficient + m_index, k, fitted(k, 3 + m_index));
    if (sensor->with_g_sensitivity) {
      for (int h = 0; h < 9; ++h) set(kGSensitivityCoefficient + h, k, forward.H(h, k));
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
void BiasStart(SensorProblem* sensor) {
  const std::vector<FitWindow>& windows = sensor->windows;
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
      const Eigen::Vector3d predicted = ForwardSensor(c, TruthFor(w, sensor->is_gyro), w.truth.a_mps2);
      double power = 1.0;
      for (int k = 0; k < terms; ++k, power *= w.x) design(r, k) = weight * power;
      rhs(r) = weight * (RawFor(w, sensor->is_gyro)(i) - predicted(i));
    }
    const Eigen::VectorXd bias = design.completeOrthogonalDecomposition().solve(rhs);
    for (int k = 0; k < kPolynomialTerms; ++k) {
      sensor->p0[(kBiasCoefficient + i) * kPolynomialTerms + k] = k < terms ? bias(k) : 0.0;
    }
  }
}

// FitOptions::closed_form_start false: only the nominal scale factors (each scale's constant
// term) are kept, so that the solver has to find everything else itself.
void KeepOnlyNominalScales(SensorProblem* sensor) {
  for (int i = 0; i < sensor->parameters; ++i) {
    const int c = i / kPolynomialTerms;
    const bool nominal_scale =
        c >= kScaleCoefficient && c < kMisalignmentCoefficient && i % kPolynomialTerms == 0;
    if (!nominal_scale) sensor->p0[i] = 0.0;
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

// The first of the two noise figures of each window, set before the start: the weights. The noise
// of the window's raw mean (windows.h), per axis, floored at kSigmaFloorFraction of the sensor's
// median window noise. They are in raw units, so they do not move with the parameters: the
// closed-form start weighs its least squares with them and the cost (window_cost.h) divides by
// them.
void SetWeightsForStart(SensorProblem* sensor) {
  const size_t count = sensor->windows.size();
  sensor->sigma_raw.assign(count, Eigen::Vector3d::Ones());
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (size_t w = 0; w < count; ++w) {
      sensor->sigma_raw[w](axis) = sensor->windows[w].window->NoiseOfMean(sensor->is_gyro)(axis);
      values.push_back(sensor->sigma_raw[w](axis));
    }
    const double floor = kSigmaFloorFraction * Median(values);
    for (size_t w = 0; w < count; ++w) {
      double& s = sensor->sigma_raw[w](axis);
      s = floor > 0.0 ? std::max(s, floor) : 1.0;
    }
  }
}

// The second, set from the start once it is final: the weights in SI, sigma = sigma_raw / |S0|
// with S0 the start's constant scale factor of the axis (the SI noise to first order). The
// residuals are reported with them and the bias-stability covariance converts SI offsets to
// normalised residuals with them; they stay fixed while the solver moves the scale.
void SetSiSigmasFromStart(SensorProblem* sensor) {
  IMUFIT_CHECK(static_cast<int>(sensor->p0.size()) == sensor->parameters, "the start comes first");
  const size_t count = sensor->windows.size();
  sensor->sigma.assign(count, Eigen::Vector3d::Ones());
  for (int axis = 0; axis < 3; ++axis) {
    const double scale = std::abs(sensor->p0[(kScaleCoefficient + axis) * kPolynomialTerms]);
    for (size_t w = 0; w < count; ++w) {
      sensor->sigma[w](axis) = sensor->sigma_raw[w](axis) / (scale > 0.0 ? scale : 1.0);
    }
  }
}

// What the sensor is and how much of it `options` fits.
void DescribeSensor(bool is_gyro, const FitOptions& options, SensorProblem* sensor) {
  sensor->name = is_gyro ? "gyro" : "accel";
  sensor->is_gyro = is_gyro;
  sensor->parameters = is_gyro ? kGyroParameters : kAccelParameters;
  sensor->coefficients = is_gyro ? kGyroCoefficients : kAccelCoefficients;
  sensor->order = is_gyro ? options.gyro_temp_order : options.accel_temp_order;
  sensor->with_g_sensitivity = is_gyro && options.Fits(true, kGSensitivityCoefficient);
}

// One sensor's start, its windows chosen: the weights first (the start's least squares uses them),
// then p0 (closed form for a sensor fitted whole, the held values with a closed-form bias for a
// bias-only one, the held values alone for one held whole), the held groups put back at their
// stated values, then what depends on p0: the SI noise figures and the steps. Terms above the
// order and the groups not fitted are held.
void StartSensor(const FitOptions& options, const TemperatureBasis& basis, SensorProblem* sensor) {
  SetWeightsForStart(sensor);
  const SensorFit mode = sensor->is_gyro ? options.gyro_fit : options.accel_fit;
  const std::vector<double> held = HeldParameters(options, sensor->is_gyro, basis);
  if (mode == SensorFit::kAll) {
    LinearStart(sensor);
  } else {
    sensor->p0 = held;
    if (mode == SensorFit::kBias) BiasStart(sensor);
  }
  if (!options.closed_form_start) KeepOnlyNominalScales(sensor);
  for (int i = 0; i < sensor->parameters; ++i) {
    if (!options.Fits(sensor->is_gyro, i / kPolynomialTerms)) sensor->p0[i] = held[i];
  }
  SetSiSigmasFromStart(sensor);
  SetSteps(sensor);
  std::fill(sensor->q, sensor->q + sensor->parameters, 0.0);
  for (int c = 0; c < sensor->coefficients; ++c) {
    for (int k = 0; k < kPolynomialTerms; ++k) {
      if (k > sensor->order || !options.Fits(sensor->is_gyro, c))
        sensor->held.push_back(c * kPolynomialTerms + k);
    }
  }
}

}  // namespace

// Stage: start. The accelerometer first: where gravity turns in the body frame (a turn or a rate
// about a non-vertical axis) the gyro's g-sensitivity term sees the window's corrected
// accelerometer mean, at the accelerometer's start (which differs from its fit by far less than
// the noise of that mean). The accelerometer's windows are those whose specific force is known;
// the gyro has them all.
void StartSensors(const FitOptions& options, ThermalFitState* fit) {
  SensorProblem& gyro = fit->gyro;
  SensorProblem& accel = fit->accel;
  DescribeSensor(/*is_gyro=*/true, options, &gyro);
  DescribeSensor(/*is_gyro=*/false, options, &accel);
  accel.q = fit->q.data();
  gyro.q = fit->q.data() + kAccelParameters;
  for (size_t w = 0; w < fit->windows.size(); ++w) {
    if (!fit->windows[w].accel_known) continue;
    accel.windows.push_back(fit->windows[w]);
    accel.window_index.push_back(static_cast<int>(w));
  }
  StartSensor(options, fit->basis, &accel);
  for (size_t w = 0; w < fit->windows.size(); ++w) {
    FitWindow fw = fit->windows[w];
    if (!fw.accel_known) {
      const SensorCoefficients<double> c = CoefficientsAt(accel.p0.data(), kAccelCoefficients, fw.x);
      fw.truth.a_mps2 = CorrectSensor(c, fw.window->accel_mean, Eigen::Vector3d::Zero().eval());
    }
    gyro.windows.push_back(fw);
    gyro.window_index.push_back(static_cast<int>(w));
  }
  StartSensor(options, fit->basis, &gyro);
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

}  // namespace imufit::internal
