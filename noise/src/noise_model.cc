#include "imufit/noise/noise_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "imufit/base/enum_names.h"
#include "imufit/model/constants.h"

namespace imufit {
namespace {

// sqrt(2 ln 2 / pi): the flicker floor of the Allan deviation is 0.664 B.
const double kFlickerFloor = std::sqrt(2.0 * std::log(2.0) / kPi);
// A read-out slope must be within kReadoutSlopeTolerance of its target (-1/2 or +1/2) to count;
// within kReadoutSlopeNear the best-determined such segment is taken.
constexpr double kReadoutSlopeTolerance = 0.25;
constexpr double kReadoutSlopeNear = 0.05;

struct Point {
  double tau_s;
  double variance;
  double edf;
  int alpha;
};

// Correlation of the overlapping Allan variance estimates at two taus, as a function of their
// ratio r = tau_long / tau_short and the noise type:
//
//   rho = a + (1 - a) exp(-c (log2 r)^p)
//
// calibrated by simulation (400 records of 2^15 samples, octave taus; correlations of the log
// estimates at r = 2, 4, 8): white FM 0.53, 0.19, 0.07; random-walk FM 0.88, 0.66, 0.46; white PM
// about 0.45 at every r (the phase noise enters every tau alike). Flicker noises lie between their
// neighbours. exp(-c |x|^p) with p <= 2 is a valid correlation function, so the matrix stays
// positive definite (a ridge guards the mixed-noise case).
struct CorrelationModel {
  double a, c, p;
};
CorrelationModel CorrelationFor(int alpha) {
  switch (alpha) {
    case 2:
      return {0.45, 10.0, 1.5};
    case 1:
      return {0.30, 0.60, 1.5};
    case 0:
      return {0.0, 0.63, 1.4};
    case -1:
      return {0.0, 0.30, 1.55};
    default:
      return {0.0, 0.128, 1.7};
  }
}

double Correlation(const Point& i, const Point& j) {
  if (i.tau_s == j.tau_s) return 1.0;
  const CorrelationModel u = CorrelationFor(i.alpha);
  const CorrelationModel v = CorrelationFor(j.alpha);
  const double a = 0.5 * (u.a + v.a);
  const double c = 0.5 * (u.c + v.c);
  const double p = 0.5 * (u.p + v.p);
  const double octaves = std::fabs(std::log2(j.tau_s / i.tau_s));
  return a + (1.0 - a) * std::exp(-c * std::pow(octaves, p));
}

// The whitened problem: with C = L L^T the covariance of the variance estimates (standard
// deviations sigma_model^2 sqrt(2 / edf), correlations above), rows L^-1 [basis | data] turn the
// generalized least-squares problem into an ordinary one.
struct Whitened {
  Eigen::MatrixXd design;  // rows x 5
  Eigen::VectorXd data;
};

Whitened Whiten(const std::vector<Point>& points, const std::vector<double>& model) {
  const int rows = static_cast<int>(points.size());
  Eigen::MatrixXd covariance(rows, rows);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < rows; ++j) {
      const double si = model[i] * std::sqrt(2.0 / points[i].edf);
      const double sj = model[j] * std::sqrt(2.0 / points[j].edf);
      covariance(i, j) = si * sj * Correlation(points[i], points[j]);
    }
  }
  Eigen::LLT<Eigen::MatrixXd> cholesky(covariance);
  for (double ridge = 1e-9; cholesky.info() != Eigen::Success && ridge < 1.0; ridge *= 10.0) {
    Eigen::MatrixXd shrunk = covariance * (1.0 - ridge);
    shrunk.diagonal() = covariance.diagonal();
    cholesky.compute(shrunk);
  }
  Eigen::MatrixXd basis(rows, kNoiseTerms);
  Eigen::VectorXd data(rows);
  for (int i = 0; i < rows; ++i) {
    for (int k = 0; k < kNoiseTerms; ++k) basis(i, k) = NoiseTermBasis(k, points[i].tau_s);
    data(i) = points[i].variance;
  }
  Whitened whitened;
  whitened.design = cholesky.matrixL().solve(basis);
  whitened.data = cholesky.matrixL().solve(data);
  return whitened;
}

// Least squares on the terms of `mask`; returns false when rank-deficient. `c` gets all five
// coefficients (zeros outside the mask), `covariance` the 5x5 covariance (zeros outside).
bool SolveSubset(const Whitened& problem, unsigned mask, Eigen::Matrix<double, 5, 1>* c,
                 Eigen::Matrix<double, 5, 5>* covariance, double* cost) {
  std::vector<int> terms;
  for (int k = 0; k < kNoiseTerms; ++k) {
    if (mask & (1u << k)) terms.push_back(k);
  }
  const int rows = static_cast<int>(problem.data.size());
  const int cols = static_cast<int>(terms.size());
  if (cols == 0 || rows < cols) return false;
  Eigen::MatrixXd a(rows, cols);
  // Unit-norm columns: the basis spans tau^-2 .. tau^2 over many decades.
  Eigen::VectorXd scale(cols);
  for (int j = 0; j < cols; ++j) {
    a.col(j) = problem.design.col(terms[j]);
    scale(j) = a.col(j).norm();
    if (!(scale(j) > 0.0)) return false;
    a.col(j) /= scale(j);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < cols) return false;
  const Eigen::VectorXd x = qr.solve(problem.data);
  const Eigen::MatrixXd inverse = (a.transpose() * a).inverse();
  c->setZero();
  covariance->setZero();
  for (int j = 0; j < cols; ++j) {
    (*c)(terms[j]) = x(j) / scale(j);
    for (int l = 0; l < cols; ++l) (*covariance)(terms[j], terms[l]) = inverse(j, l) / (scale(j) * scale(l));
  }
  *cost = (a * x - problem.data).squaredNorm();
  return true;
}

double SqrtSigma(double v, double s) {
  return 0.5 * (std::sqrt(std::max(v, 0.0) + s) - std::sqrt(std::max(v - s, 0.0)));
}

// The points the fit may use: enough averaging intervals in the record, a positive deviation and
// a known edf.
std::vector<Point> UsablePoints(const std::vector<AllanPoint>& all_points, int64_t n_samples,
                                const NoiseFitOptions& options) {
  std::vector<Point> points;
  for (const AllanPoint& p : all_points) {
    const double clusters = static_cast<double>(n_samples) / static_cast<double>(p.m);
    if (clusters < options.min_clusters || !(p.dev > 0.0) || !std::isfinite(p.edf) || !(p.edf > 0.0))
      continue;
    points.push_back({p.tau_s, p.dev * p.dev, p.edf, p.alpha});
  }
  return points;
}

// The classic read-outs of the measured curve (see noise_model.h).
void ReadOut(const std::vector<Point>& points, NoiseFitSummary* summary) {
  if (points.empty()) return;
  const auto lowest = std::min_element(
      points.begin(), points.end(), [](const Point& a, const Point& b) { return a.variance < b.variance; });
  summary->readout_bias_instability = std::sqrt(lowest->variance) / kFlickerFloor;
  summary->readout_bias_tau_s = lowest->tau_s;
  // Among the segments whose slope is near the target, the one with the most degrees of
  // freedom (the shortest tau); failing that, the segment whose slope is nearest within the
  // looser tolerance.
  struct Choice {
    double near_edf = 0.0;
    double near_value = std::nan("");
    double best_distance = kReadoutSlopeTolerance;
    double best_value = std::nan("");
    void Offer(double distance, double edf, double value) {
      if (distance < kReadoutSlopeNear && edf > near_edf) {
        near_edf = edf;
        near_value = value;
      }
      if (distance < best_distance) {
        best_distance = distance;
        best_value = value;
      }
    }
    double Value() const { return std::isfinite(near_value) ? near_value : best_value; }
  };
  Choice arw;
  Choice rrw;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const double slope = 0.5 * std::log(points[i + 1].variance / points[i].variance) /
                         std::log(points[i + 1].tau_s / points[i].tau_s);
    const double dev = std::sqrt(points[i].variance);
    const double edf = std::min(points[i].edf, points[i + 1].edf);
    arw.Offer(std::fabs(slope + 0.5), edf, dev * std::sqrt(points[i].tau_s));        // sigma = N / sqrt(tau)
    rrw.Offer(std::fabs(slope - 0.5), edf, dev * std::sqrt(3.0 / points[i].tau_s));  // sigma = K sqrt(tau/3)
  }
  summary->readout_random_walk = arw.Value();
  summary->readout_rate_random_walk = rrw.Value();
}

// Why the model cannot be fitted at all ("" when it can be tried).
std::string WhyNoFit(const std::vector<AllanPoint>& all_points, size_t usable,
                     const NoiseFitOptions& options) {
  const bool constant = !all_points.empty() && std::all_of(all_points.begin(), all_points.end(),
                                                           [](const AllanPoint& p) { return p.dev == 0.0; });
  if (constant) {
    return "the column is constant: every deviation is zero (a stuck sensor, or a signal finer than one "
           "quantization step?)";
  }
  if (usable < 2) {
    return "too few points for a noise fit (" + std::to_string(usable) + " with at least " +
           std::to_string(static_cast<int>(options.min_clusters)) + " averaging intervals in the record)";
  }
  return "";
}

// The best feasible subset of the enabled terms (mask 0: none), after reweighting iterations, and
// the whitened problem of the last iteration.
struct SubsetFit {
  unsigned mask = 0;
  double cost = 0.0;
  Eigen::Matrix<double, 5, 1> c = Eigen::Matrix<double, 5, 1>::Zero();
  Eigen::Matrix<double, 5, 5> covariance = Eigen::Matrix<double, 5, 5>::Zero();
  Whitened problem;
};

SubsetFit BestSubset(const std::vector<Point>& points, const NoiseFitOptions& options) {
  unsigned enabled_mask = 0;
  for (int k = 0; k < kNoiseTerms; ++k) {
    if (options.enabled[k]) enabled_mask |= 1u << k;
  }
  SubsetFit best;
  std::vector<double> model(points.size());
  for (size_t i = 0; i < points.size(); ++i) model[i] = points[i].variance;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    best.problem = Whiten(points, model);
    best.cost = std::numeric_limits<double>::infinity();
    best.mask = 0;
    for (unsigned mask = 1; mask < (1u << kNoiseTerms); ++mask) {
      if ((mask & enabled_mask) != mask) continue;
      Eigen::Matrix<double, 5, 1> c;
      Eigen::Matrix<double, 5, 5> covariance;
      double cost = 0.0;
      if (!SolveSubset(best.problem, mask, &c, &covariance, &cost)) continue;
      if ((c.array() < 0.0).any()) continue;
      if (cost < best.cost) {
        best.cost = cost;
        best.mask = mask;
        best.c = c;
        best.covariance = covariance;
      }
    }
    if (best.mask == 0) break;
    for (size_t i = 0; i < points.size(); ++i) {
      double v = 0.0;
      for (int k = 0; k < kNoiseTerms; ++k) v += best.c(k) * NoiseTermBasis(k, points[i].tau_s);
      model[i] = std::max(v, 1e-300);
    }
  }
  return best;
}

// The terms and their uncertainties from the best subset; a term left at zero gets the
// uncertainty it would have if freed alongside the others.
void SetTerms(const SubsetFit& best, size_t usable, const NoiseFitOptions& options,
              NoiseFitSummary* summary) {
  int free_terms = 0;
  for (int k = 0; k < kNoiseTerms; ++k) free_terms += (best.mask >> k) & 1u;
  const int dof = static_cast<int>(usable) - free_terms;
  summary->reduced_chi_square = dof > 0 ? best.cost / dof : std::nan("");
  const double inflate = (dof > 0 && summary->reduced_chi_square > 1.0) ? summary->reduced_chi_square : 1.0;
  summary->fitted = true;
  for (int k = 0; k < kNoiseTerms; ++k) {
    summary->free[k] = (best.mask >> k) & 1u;
    summary->variance[k] = best.c(k);
    double variance_of_c = best.covariance(k, k);
    if (!summary->free[k] && options.enabled[k]) {
      Eigen::Matrix<double, 5, 1> c;
      Eigen::Matrix<double, 5, 5> covariance;
      double cost = 0.0;
      variance_of_c = SolveSubset(best.problem, best.mask | (1u << k), &c, &covariance, &cost)
                          ? covariance(k, k)
                          : std::nan("");
    }
    summary->variance_sigma[k] = std::sqrt(std::max(0.0, variance_of_c) * inflate);
    summary->value[k] = std::sqrt(summary->variance[k]);
    summary->sigma[k] =
        options.enabled[k] ? SqrtSigma(summary->variance[k], summary->variance_sigma[k]) : 0.0;
  }
}

}  // namespace

double NoiseTermBasis(int term, double tau_s) {
  switch (term) {
    case kQuantization:
      return 3.0 / (tau_s * tau_s);
    case kRandomWalk:
      return 1.0 / tau_s;
    case kBiasInstability:
      return kFlickerFloor * kFlickerFloor;
    case kRateRandomWalk:
      return tau_s / 3.0;
    case kRateRamp:
      return 0.5 * tau_s * tau_s;
  }
  return 0.0;
}

std::string NoiseFitOptions::Validate() const { return ValidateOptions(NoiseFitOptionTable(), *this); }

double NoiseFitSummary::ModelDeviation(double tau_s) const {
  double sum = 0.0;
  for (int k = 0; k < kNoiseTerms; ++k) sum += variance[k] * NoiseTermBasis(k, tau_s);
  return std::sqrt(sum);
}

double NoiseFitSummary::TermDeviation(int term, double tau_s) const {
  return std::sqrt(variance[term] * NoiseTermBasis(term, tau_s));
}

NoiseFitSummary FitNoiseModel(const std::vector<AllanPoint>& all_points, int64_t n_samples,
                              const NoiseFitOptions& options) {
  NoiseFitSummary summary;
  const std::vector<Point> points = UsablePoints(all_points, n_samples, options);
  summary.points_used = static_cast<int>(points.size());
  ReadOut(points, &summary);
  summary.message = WhyNoFit(all_points, points.size(), options);
  if (!summary.message.empty()) return summary;
  const SubsetFit best = BestSubset(points, options);
  if (best.mask == 0) {
    summary.message = "the noise model could not be fitted (no feasible combination of terms)";
    return summary;
  }
  SetTerms(best, points.size(), options, &summary);
  return summary;
}

}  // namespace imufit
