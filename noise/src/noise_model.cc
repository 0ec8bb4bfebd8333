#include "imufit/noise/noise_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "imufit/base/enum_names.h"
#include "imufit/model/constants.h"
#include "imufit/noise/statistics.h"

namespace imufit {
namespace {

// sqrt(2 ln 2 / pi): the flicker floor of the Allan deviation is 0.664 B.
const double kFlickerFloor = std::sqrt(2.0 * std::log(2.0) / kPi);
// Without a run of kReadoutSlopeRun, a read-out takes the single segment whose slope is nearest
// its target within kReadoutSlopeTolerance.
constexpr double kReadoutSlopeTolerance = 0.25;
// A filter's lag-1 autocorrelation has at least halved (kFilterDecay) this many taus later
// (three octaves at octave taus); a scale-invariant noise's has not.
constexpr int kFilterDecayTaus = 3;
constexpr double kFilterDecay = 0.5;
// The read-out's intervals: 95.45 % (2 sigma) for the minimum's interval, 68.27 % (1 sigma) for
// whether the curve rises significantly beside it.
constexpr double kTwoSigmaConfidence = 0.9545;
constexpr double kOneSigmaConfidence = 0.6827;

struct Point {
  double tau_s;
  double variance;
  double edf;
  int alpha;
  double lag1;
  double clusters;
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

Whitened Whiten(const std::vector<Point>& points, const std::vector<double>& model, double model_error) {
  const int rows = static_cast<int>(points.size());
  Eigen::MatrixXd covariance(rows, rows);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < rows; ++j) {
      const double si = model[i] * std::sqrt(2.0 / points[i].edf);
      const double sj = model[j] * std::sqrt(2.0 / points[j].edf);
      covariance(i, j) = si * sj * Correlation(points[i], points[j]);
    }
    // The model-error floor: independent between taus (noise_model.h).
    covariance(i, i) += (model_error * model[i]) * (model_error * model[i]);
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
                                const NoiseFitOptions& options, NoiseFitSummary* summary) {
  std::vector<Point> points;
  for (const AllanPoint& p : all_points) {
    const double clusters = static_cast<double>(n_samples) / static_cast<double>(p.m);
    if (clusters < options.min_clusters) {
      if (!(summary->skipped_tau_s >= p.tau_s)) {
        summary->skipped_tau_s = p.tau_s;
        summary->skipped_clusters = clusters;
      }
      continue;
    }
    if (!(p.dev > 0.0) || !std::isfinite(p.edf) || !(p.edf > 0.0)) continue;
    points.push_back({p.tau_s, p.dev * p.dev, p.edf, p.alpha, p.lag1, clusters});
  }
  return points;
}

// The number of short taus an output filter bends (noise_model.h): 0 when there is no filter.
int FilteredPoints(const std::vector<Point>& points, NoiseFitSummary* summary) {
  if (points.empty()) return 0;
  summary->sample_lag1 = points.front().lag1;
  const auto positive = [](const Point& p) {
    return p.lag1 > kFilterLag1 && p.lag1 > kFilterLag1Sigmas / std::sqrt(p.clusters);
  };
  if (!positive(points.front())) return 0;
  // Decaying: a finite memory. Flicker and random walks keep their correlation at every tau.
  const size_t later = std::min(points.size() - 1, static_cast<size_t>(kFilterDecayTaus));
  if (later == 0 || !(points[later].lag1 < kFilterDecay * points.front().lag1)) return 0;
  size_t count = 0;
  while (count < points.size() && positive(points[count])) ++count;
  summary->filter_detected = true;
  return static_cast<int>(count);
}

// A read-out along a segment of slope `target` (-1/2 or +1/2): the longest run of consecutive
// points from `first` whose local slopes are within kReadoutSlopeRun of it; its figure is the
// edf-weighted mean of `figure` over the run. Failing a run, the single segment whose slope is
// nearest within kReadoutSlopeTolerance. Sets value, sigma and the tau range; false when none.
struct SegmentReadout {
  double value = std::nan("");
  double sigma = std::nan("");
  double tau_min_s = std::nan("");
  double tau_max_s = std::nan("");
  double bound = std::nan("");  // when the only segment is a disturbance's flank: an upper bound
  double bound_tau_s = std::nan("");
};
template <typename Figure>
SegmentReadout ReadAlong(const std::vector<Point>& points, size_t first, double target, double model_error,
                         Figure figure) {
  SegmentReadout readout;
  if (points.size() < first + 2) return readout;
  std::vector<double> slopes;
  for (size_t i = first; i + 1 < points.size(); ++i) {
    slopes.push_back(0.5 * std::log(points[i + 1].variance / points[i].variance) /
                     std::log(points[i + 1].tau_s / points[i].tau_s));
  }
  // The run with the most degrees of freedom for the -1/2 line (the white noise lives at the short
  // end), the longest for the +1/2 line (the random walk at the long end). A -1/2 run is on the
  // flank of a disturbance (a tone's bump falls through -1/2) when a shorter unfiltered tau lies
  // clearly below its line: white noise cannot put the curve below its own line; such runs are
  // passed over.
  struct Run {
    size_t begin, end;  // segments [begin, end): points begin .. end (from `first`)
    double weight;
  };
  std::vector<Run> runs;
  for (size_t begin = 0; begin < slopes.size();) {
    size_t end = begin;
    while (end < slopes.size() && std::fabs(slopes[end] - target) < kReadoutSlopeRun) ++end;
    if (end > begin) {
      double weight = static_cast<double>(end - begin);
      if (target < 0.0) {
        weight = 0.0;
        for (size_t i = begin; i <= end; ++i) weight += points[first + i].edf;
      }
      runs.push_back({begin, end, weight});
    }
    begin = end == begin ? begin + 1 : end;
  }
  std::stable_sort(runs.begin(), runs.end(), [](const Run& x, const Run& y) { return x.weight > y.weight; });
  // No run: the single segment nearest the target within kReadoutSlopeTolerance.
  double distance = kReadoutSlopeTolerance;
  size_t nearest = slopes.size();
  for (size_t i = 0; i < slopes.size(); ++i) {
    if (std::fabs(slopes[i] - target) < distance) distance = std::fabs(slopes[i] - target), nearest = i;
  }
  if (runs.empty() && nearest < slopes.size()) runs.push_back({nearest, nearest + 1, 0.0});
  const auto value_of = [&](const Run& run) {
    double weighted = 0.0, weights = 0.0;
    for (size_t i = first + run.begin; i <= first + run.end; ++i) {
      weighted += points[i].edf * figure(points[i]);
      weights += points[i].edf;
    }
    return weighted / weights;
  };
  const auto on_a_flank = [&](const Run& run) {
    if (target > 0.0) return false;
    const double value = value_of(run);
    for (size_t i = first; i < first + run.begin; ++i) {
      const double margin = 3.0 * std::sqrt(0.5 / points[i].edf) + model_error;
      if (figure(points[i]) < value * (1.0 - margin)) return true;
    }
    return false;
  };
  const auto chosen =
      std::find_if(runs.begin(), runs.end(), [&](const Run& run) { return !on_a_flank(run); });
  if (chosen == runs.end()) return readout;
  const size_t best_begin = chosen->begin, best_end = chosen->end;
  double weighted = 0.0, weights = 0.0, most_edf = 0.0;
  for (size_t i = first + best_begin; i <= first + best_end; ++i) {
    weighted += points[i].edf * figure(points[i]);
    weights += points[i].edf;
    most_edf = std::max(most_edf, points[i].edf);
  }
  readout.value = weighted / weights;
  // Neighbouring taus are strongly correlated: no gain from averaging is claimed, the figure is
  // as uncertain as the best point's deviation (sqrt(1 / (2 edf)) relative), and no less than
  // the model-error floor allows (half of it, on a deviation).
  readout.sigma = readout.value * std::sqrt(0.5 / most_edf + 0.25 * model_error * model_error);
  readout.tau_min_s = points[first + best_begin].tau_s;
  readout.tau_max_s = points[first + best_end].tau_s;
  return readout;
}

// The classic read-outs of the measured curve (see noise_model.h); `filtered` short taus are not
// on the -1/2 line.
void ReadOut(const std::vector<Point>& points, size_t filtered, double model_error,
             NoiseFitSummary* summary) {
  if (points.empty()) return;
  const size_t lowest = static_cast<size_t>(
      std::min_element(points.begin(), points.end(),
                       [](const Point& a, const Point& b) { return a.variance < b.variance; }) -
      points.begin());
  const double floor_dev = std::sqrt(points[lowest].variance);
  summary->readout_bias_instability = floor_dev / kFlickerFloor;
  summary->readout_bias_tau_s = points[lowest].tau_s;
  double lo = 0.0, hi = 0.0;
  ChiSquaredInterval(floor_dev, points[lowest].edf, kTwoSigmaConfidence, &lo, &hi);
  summary->readout_bias_lower = lo / kFlickerFloor;
  summary->readout_bias_upper = hi / kFlickerFloor;
  // Resolved: a point on each side lies above the minimum beyond both 1-sigma intervals.
  double floor_hi = 0.0;
  ChiSquaredInterval(floor_dev, points[lowest].edf, kOneSigmaConfidence, &lo, &floor_hi);
  const auto above = [&](const Point& p) {
    double p_lo = 0.0, p_hi = 0.0;
    ChiSquaredInterval(std::sqrt(p.variance), p.edf, kOneSigmaConfidence, &p_lo, &p_hi);
    return p_lo > floor_hi;
  };
  summary->readout_bias_resolved = std::any_of(points.begin(), points.begin() + lowest, above) &&
                                   std::any_of(points.begin() + lowest + 1, points.end(), above);
  const SegmentReadout arw = ReadAlong(points, filtered, -0.5, model_error,
                                       [](const Point& p) { return std::sqrt(p.variance * p.tau_s); });
  summary->readout_random_walk = arw.value;
  summary->readout_random_walk_sigma = arw.sigma;
  summary->readout_random_walk_tau_min_s = arw.tau_min_s;
  summary->readout_random_walk_tau_max_s = arw.tau_max_s;
  summary->readout_random_walk_bound = arw.bound;
  summary->readout_random_walk_bound_tau_s = arw.bound_tau_s;
  const SegmentReadout rrw = ReadAlong(points, filtered, 0.5, model_error,
                                       [](const Point& p) { return std::sqrt(p.variance * 3.0 / p.tau_s); });
  summary->readout_rate_random_walk = rrw.value;
  summary->readout_rate_random_walk_sigma = rrw.sigma;
  summary->readout_rate_random_walk_tau_min_s = rrw.tau_min_s;
  summary->readout_rate_random_walk_tau_max_s = rrw.tau_max_s;
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

// `signed_short`: the 1/tau^2 coefficient may be negative (an output filter's deficit).
SubsetFit BestSubset(const std::vector<Point>& points, const NoiseFitOptions& options, bool signed_short) {
  unsigned enabled_mask = 0;
  for (int k = 0; k < kNoiseTerms; ++k) {
    if (options.enabled[k]) enabled_mask |= 1u << k;
  }
  SubsetFit best;
  std::vector<double> model(points.size());
  for (size_t i = 0; i < points.size(); ++i) model[i] = points[i].variance;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    best.problem = Whiten(points, model, options.model_error);
    best.cost = std::numeric_limits<double>::infinity();
    best.mask = 0;
    for (unsigned mask = 1; mask < (1u << kNoiseTerms); ++mask) {
      if ((mask & enabled_mask) != mask) continue;
      Eigen::Matrix<double, 5, 1> c;
      Eigen::Matrix<double, 5, 5> covariance;
      double cost = 0.0;
      if (!SolveSubset(best.problem, mask, &c, &covariance, &cost)) continue;
      if ((c.tail<kNoiseTerms - 1>().array() < 0.0).any() || (!signed_short && c(0) < 0.0)) continue;
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
      model[i] = std::max(v, 1e-3 * points[i].variance);
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
  summary->describes_curve = !(summary->reduced_chi_square > kMisfitReducedChiSquare);
  for (int k = 0; k < kNoiseTerms; ++k) {
    summary->free[k] = (best.mask >> k) & 1u;
    summary->variance[k] = best.c(k);
    if (k == kQuantization && best.c(k) < 0.0) {  // the filter's deficit, not a quantization
      summary->filter_variance = best.c(k);
      summary->variance[k] = 0.0;
    }
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

// Per term, the used taus where it carries at least kTermShare of the model's variance.
void SetTermRanges(const std::vector<Point>& points, NoiseFitSummary* summary) {
  summary->fit_tau_min_s = points.front().tau_s;
  summary->fit_tau_max_s = points.back().tau_s;
  for (const Point& p : points) {
    const double model = summary->ModelDeviation(p.tau_s);
    for (int k = 0; k < kNoiseTerms; ++k) {
      const double share = summary->variance[k] * NoiseTermBasis(k, p.tau_s) / (model * model);
      if (!(share >= kTermShare)) continue;
      if (!(summary->term_tau_min_s[k] <= p.tau_s)) summary->term_tau_min_s[k] = p.tau_s;
      summary->term_tau_max_s[k] = p.tau_s;
    }
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
  double sum = filter_variance * NoiseTermBasis(kQuantization, tau_s);
  for (int k = 0; k < kNoiseTerms; ++k) sum += variance[k] * NoiseTermBasis(k, tau_s);
  return std::sqrt(std::max(sum, 0.0));
}

double NoiseFitSummary::TermDeviation(int term, double tau_s) const {
  return std::sqrt(variance[term] * NoiseTermBasis(term, tau_s));
}

namespace {

// The shortest record (seconds) whose overlapping Allan deviation at tau_s, for noise exponent
// alpha, has edf >= 2 / precision^2 and min_clusters intervals of tau_s.
double RecordFor(double tau_s, int alpha, double tau0_s, double precision, double min_clusters) {
  const int64_t m = std::max<int64_t>(1, std::llround(tau_s / tau0_s));
  const double needed_edf = 2.0 / (precision * precision);
  const auto enough = [&](int64_t n) {
    const std::optional<double> edf = GreenhallEdf(alpha, 2, m, false, true, n + 1);
    return edf && *edf >= needed_edf && static_cast<double>(n) >= min_clusters * static_cast<double>(m);
  };
  int64_t hi = std::max<int64_t>(4 * m, static_cast<int64_t>(min_clusters * static_cast<double>(m)));
  while (!enough(hi)) {
    if (hi > (int64_t{1} << 52)) return std::nan("");
    hi *= 2;
  }
  int64_t lo = hi / 2;
  while (hi - lo > std::max<int64_t>(1, hi / 1000)) {  // to 0.1 %
    const int64_t mid = lo + (hi - lo) / 2;
    (enough(mid) ? hi : lo) = mid;
  }
  return static_cast<double>(hi) * tau0_s;
}

// The shortest tau (from tau0, 1/16 octave steps, up to 1e8 s) where term carries `share` of the
// model's variance; nan when none.
double TauWhereDominant(const NoiseFitSummary& model, int term, double share, double tau0_s) {
  for (double tau = tau0_s; tau < 1e8; tau *= std::pow(2.0, 1.0 / 16.0)) {
    const double total = model.ModelDeviation(tau);
    if (model.variance[term] * NoiseTermBasis(term, tau) >= share * total * total) return tau;
  }
  return std::nan("");
}

}  // namespace

RecordLength RecordLengthFor(double n, double b, double k, double tau0_s, double precision,
                             double min_clusters) {
  constexpr double kDominantShare = 0.75;
  constexpr double kFlickerPastCrossover = 10.0;  // the floor is read where white adds a tenth
  constexpr double kRiseBeyondMinimum = 2.0;      // a point this far past the minimum shows the rise
  NoiseFitSummary model;
  model.variance[kRandomWalk] = n * n;
  model.variance[kBiasInstability] = b * b;
  model.variance[kRateRandomWalk] = k * k;
  RecordLength record;
  if (n > 0.0) {
    const double tau = TauWhereDominant(model, kRandomWalk, kDominantShare, tau0_s);
    if (std::isfinite(tau)) record.random_walk_s = RecordFor(tau, 0, tau0_s, precision, min_clusters);
  }
  if (b > 0.0) {
    double tau = kFlickerPastCrossover * n * n / (kFlickerFloor * kFlickerFloor * b * b);
    if (k > 0.0) {  // the minimum of N^2/tau + 0.44 B^2 + K^2 tau/3
      tau = std::sqrt(3.0) * n / k;
      const double grid = std::pow(2.0, 1.0 / 16.0);
      for (double t = tau0_s; t < 1e8; t *= grid) {
        if (model.ModelDeviation(t) < model.ModelDeviation(tau)) tau = t;
      }
    }
    tau = std::max(tau, tau0_s);
    record.bias_instability_tau_s = tau;
    record.bias_instability_s = std::max(RecordFor(tau, -1, tau0_s, precision, min_clusters),
                                         min_clusters * kRiseBeyondMinimum * tau);
  }
  if (k > 0.0) {
    const double tau = TauWhereDominant(model, kRateRandomWalk, kDominantShare, tau0_s);
    record.rate_random_walk_tau_s = tau;
    if (std::isfinite(tau)) record.rate_random_walk_s = RecordFor(tau, -2, tau0_s, precision, min_clusters);
  }
  return record;
}

NoiseFitSummary FitNoiseModel(const std::vector<AllanPoint>& all_points, int64_t n_samples,
                              const NoiseFitOptions& options) {
  NoiseFitSummary summary;
  const std::vector<Point> usable = UsablePoints(all_points, n_samples, options, &summary);
  const int filtered = FilteredPoints(usable, &summary);
  summary.filtered_points = filtered;
  if (filtered > 0 && static_cast<size_t>(filtered) < usable.size()) {
    summary.filtered_below_tau_s = usable[filtered].tau_s;
  }
  ReadOut(usable, static_cast<size_t>(filtered), options.model_error, &summary);
  // The fit's taus: the user's range, else the usable taus past the filtered ones.
  const bool user_range = options.fit_tau_min_s > 0.0 || std::isfinite(options.fit_tau_max_s);
  std::vector<Point> points;
  for (size_t i = user_range ? 0 : static_cast<size_t>(filtered); i < usable.size(); ++i) {
    if (usable[i].tau_s < options.fit_tau_min_s * (1.0 - 1e-9) ||
        usable[i].tau_s > options.fit_tau_max_s * (1.0 + 1e-9))
      continue;
    points.push_back(usable[i]);
  }
  summary.points_used = static_cast<int>(points.size());
  summary.message = WhyNoFit(all_points, points.size(), options);
  if (!summary.message.empty()) return summary;
  const SubsetFit best = BestSubset(points, options, summary.filter_detected);
  if (best.mask == 0) {
    summary.message = "the noise model could not be fitted (no feasible combination of terms)";
    return summary;
  }
  SetTerms(best, points.size(), options, &summary);
  SetTermRanges(points, &summary);
  return summary;
}

}  // namespace imufit
