// imufit — the IEEE Std 952 noise model fitted to an Allan variance (Annex C of IEEE 952-1997).
//
//   sigma^2(tau) = 3 Q^2 / tau^2  +  N^2 / tau  +  (2 ln 2 / pi) B^2  +  K^2 tau / 3  +  R^2 tau^2 / 2
//
// in SI units of the rate y (gyro rad/s, accelerometer m/s^2), tau in seconds:
//   Q  quantisation noise             y * s        (gyro: rad)
//   N  angle / velocity random walk   y * sqrt(s)  (gyro: rad/sqrt(s) = rad/s/sqrt(Hz))
//   B  bias instability (flicker)     y            (the flat floor is 0.664 B)
//   K  rate / acceleration random walk y / sqrt(s) (gyro: rad/s/sqrt(s) = rad/s^2/sqrt(Hz))
//   R  rate ramp                      y / s
//
// The model is linear in c = (Q^2, N^2, B^2, K^2, R^2) >= 0, so the fit is a non-negative
// generalized least-squares problem, solved exactly by trying every subset of free terms (2^5 = 32
// small problems, columns scaled to unit norm) and keeping the best feasible one. The covariance
// of the measured variances has standard deviations sigma^2 sqrt(2 / edf) (a chi-squared estimate
// with edf degrees of freedom), with sigma^2 from the model of the previous iteration (from the
// data at the first) so that low points do not pull the fit down, and correlations between taus
// from a model calibrated by simulation (noise_model.cc): overlapping Allan variances at
// neighbouring taus are strongly correlated (0.5 at an octave for white FM, 0.9 for random-walk
// FM), and ignoring that makes the uncertainties 1.6 to 2.6 times too small. Points with fewer
// than `min_clusters` independent averaging intervals (n / m) are left out.
//
// Uncertainty: the covariance of the free terms, scaled up by the reduced chi-square when that
// exceeds 1; a term at zero gets the uncertainty it would have if freed. Monte-Carlo checked
// (white FM plus random-walk FM, octave and 5-per-decade taus): the rms of (fit - truth) /
// uncertainty is 1.0 to 1.2 for N^2 and K^2. The uncertainty of Q = sqrt(Q^2) is
// (sqrt(v + s) - sqrt(max(v - s, 0))) / 2 for v = Q^2 +- s, which is s / (2 Q) when the term is
// well determined and stays finite when it is not; whether a term is resolved is judged on v / s.
//
// Model-error floor: the IEEE 952 model is an idealisation (a flicker floor is only approximately
// flat, a real sensor adds tones and drifts), so every point's variance gets a relative
// uncertainty of at least `model_error` besides its chi-squared one: no point carries more than
// 2 / model_error^2 equivalent degrees of freedom (5000 at the default 0.02), where a 100 Hz
// record of hours gives the shortest taus 10^6 and lets them alone decide the fit.
//
// Filtered outputs: most MEMS units low-pass filter their output, which correlates consecutive
// samples and bends the curve below the -1/2 line at short tau. For a filter with finite memory
// the Allan variance of its white noise is exactly N^2/tau - D/tau^2 (D > 0) once tau exceeds
// the memory (a 1/tau^2 deficit, the shape of quantization with the opposite sign), and
// exponentially close to it soon after. A filter is detected by the lag-1 autocorrelation of the
// rate averages (AllanPoint::lag1): positive beyond kFilterLag1 (and kFilterLag1Sigmas of its
// scatter, 1/sqrt(n/m)) at the shortest tau, and decaying with tau (it halves within three
// octaves; flicker and random walks keep theirs). The run of short taus where it stays positive is
// left out of the fit ("filtered taus"), and the fit's 1/tau^2 coefficient may then be negative:
// it models the filter's deficit over the rest (FilterVariance()); quantization is then reported
// as not resolved. `fit_tau_min_s` / `fit_tau_max_s` (`--fit-taus`) overrule the detection.
//
// A misfit said out loud: a reduced chi-square above kMisfitReducedChiSquare means the model does
// not describe the curve (describes_curve false); the fitted terms are then not figures of the
// sensor and the read-outs are what to quote (column_analysis.h, QuotedFigure).
//
// The classic read-outs of IEEE 952 are reported too, from the measured curve alone: N along the
// -1/2 segment (the longest run of unfiltered taus whose local slope is within kReadoutSlopeRun of
// -1/2; the edf-weighted mean of sigma(tau) sqrt(tau) over it, with its tau range), K likewise along
// the +1/2 segment (sigma(tau) sqrt(3 / tau)), B = minimum / 0.664 with the minimum's 95 % interval.
// The minimum is "resolved" when the curve rises significantly on both sides of it (a point before
// and a point after whose 68 % intervals lie above the minimum's): then it is the bias instability
// to quote. A tau the fit and the read-outs leave out (fewer than min_clusters intervals) is named.
#ifndef IMUFIT_NOISE_NOISE_MODEL_H_
#define IMUFIT_NOISE_NOISE_MODEL_H_

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "imufit/base/noise_terms.h"
#include "imufit/base/option_table.h"
#include "imufit/noise/allan.h"

namespace imufit {

// The terms (NoiseTerm, kNoiseTerms, NoiseTermName, ParseNoiseTerm, NoiseTermNames) are
// model/noise_terms.h.

// The basis function of term k at tau: the variance it contributes per unit coefficient.
double NoiseTermBasis(int term, double tau_s);

struct NoiseFitOptions {
  // Points whose record holds fewer than this many averaging intervals (n / m) are left out.
  double min_clusters = 8.0;
  // Reweighting iterations (weights from the previous model).
  int iterations = 4;
  // Terms the fit may use; a disabled term stays zero.
  std::array<bool, kNoiseTerms> enabled = {true, true, true, true, true};
  // Relative model-error floor on each point's variance (see above); 0 turns it off.
  double model_error = 0.02;
  // The taus the fit may use (`--fit-taus LO:HI`, seconds); 0 / inf: all, less the filtered taus.
  // When either is set, the filter detection is reported but leaves no tau out.
  double fit_tau_min_s = 0.0;
  double fit_tau_max_s = std::numeric_limits<double>::infinity();

  std::string Validate() const;  // from NoiseFitOptionTable()
};
// A reduced chi-square above this says the model does not describe the curve (docs/allan.md).
inline constexpr double kMisfitReducedChiSquare = 5.0;
// A filter is detected when the shortest tau's lag-1 autocorrelation exceeds this and
// kFilterLag1Sigmas / sqrt(averages), and has at least halved kFilterDecayFactor taus later.
inline constexpr double kFilterLag1 = 0.05;
inline constexpr double kFilterLag1Sigmas = 4.0;
// A term's tau range: the used taus where it carries at least this share of the model's variance.
inline constexpr double kTermShare = 0.25;
// A read-out segment: consecutive unfiltered taus with local slopes within this of -1/2 or +1/2.
inline constexpr double kReadoutSlopeRun = 0.05;

// min_clusters, model_error, fit_taus (on the command line of `imufit allan`) and iterations.
const OptionTable<NoiseFitOptions>& NoiseFitOptionTable();

inline constexpr double kNoTau = std::numeric_limits<double>::quiet_NaN();

struct NoiseFitSummary {
  bool fitted = false;  // false: too few usable points (see message)
  std::string message;  // why not fitted, or ""
  int points_used = 0;
  double reduced_chi_square = std::nan("");
  // Coefficients in SI units of the rate (see above) and their 1-sigma uncertainties.
  std::array<double, kNoiseTerms> value = {0, 0, 0, 0, 0};
  std::array<double, kNoiseTerms> sigma = {0, 0, 0, 0, 0};
  // The fitted variance coefficients c_k = value_k^2 and their uncertainties.
  std::array<double, kNoiseTerms> variance = {0, 0, 0, 0, 0};
  std::array<double, kNoiseTerms> variance_sigma = {0, 0, 0, 0, 0};
  std::array<bool, kNoiseTerms> free = {false, false, false, false, false};  // in the final model

  // The taus the fit used (nan when not fitted), and per term the used taus where it carries at
  // least kTermShare of the model's variance (nan: nowhere).
  double fit_tau_min_s = std::nan("");
  double fit_tau_max_s = std::nan("");
  std::array<double, kNoiseTerms> term_tau_min_s = {kNoTau, kNoTau, kNoTau, kNoTau, kNoTau};
  std::array<double, kNoiseTerms> term_tau_max_s = {kNoTau, kNoTau, kNoTau, kNoTau, kNoTau};
  // False when the reduced chi-square exceeds kMisfitReducedChiSquare: the terms do not describe
  // the curve; quote the read-outs.
  bool describes_curve = true;

  // An output filter (see above): the lag-1 autocorrelation of the samples (the shortest tau's
  // averages), whether a filter was detected, how many short taus it bends (left out of the fit
  // unless --fit-taus says otherwise) and the first tau past them.
  double sample_lag1 = std::nan("");
  bool filter_detected = false;
  int filtered_points = 0;
  double filtered_below_tau_s = std::nan("");
  // The filter's 1/tau^2 deficit: the negative part of the 1/tau^2 coefficient, in Q^2's units
  // (0 when none); ModelDeviation includes it.
  double filter_variance = 0.0;

  // Classic read-outs (nan when the curve has no such region).
  double readout_random_walk = std::nan("");  // N along the -1/2 segment
  double readout_random_walk_sigma = std::nan("");
  double readout_random_walk_tau_min_s = std::nan("");  // the segment
  double readout_random_walk_tau_max_s = std::nan("");
  double readout_bias_instability = std::nan("");  // B = min / 0.664
  double readout_bias_lower = std::nan("");        // its 95 % interval (the minimum's chi-squared one)
  double readout_bias_upper = std::nan("");
  double readout_bias_tau_s = std::nan("");        // where the minimum is
  bool readout_bias_resolved = false;              // a minimum with a significant rise on both sides
  double readout_rate_random_walk = std::nan("");  // K along the +1/2 segment
  double readout_rate_random_walk_sigma = std::nan("");
  double readout_rate_random_walk_tau_min_s = std::nan("");
  double readout_rate_random_walk_tau_max_s = std::nan("");
  // When the only -1/2 segment is a disturbance's flank (a shorter tau lies clearly below its
  // line): no read-out, but its upper 2-sigma figure bounds N from above, and its first tau.
  double readout_random_walk_bound = std::nan("");
  double readout_random_walk_bound_tau_s = std::nan("");
  // The curve's own upper bound on K: min over the usable taus of the upper 95 % bound of sigma
  // times sqrt(3 / tau) (every point lies above K sqrt(tau / 3)), and its tau.
  double readout_rate_random_walk_bound = std::nan("");
  double readout_rate_random_walk_bound_tau_s = std::nan("");
  // The longest tau left out for having fewer than min_clusters intervals (nan: none), and its
  // number of intervals.
  double skipped_tau_s = std::nan("");
  double skipped_clusters = std::nan("");

  // The fitted Allan deviation and one term's share, at tau.
  double ModelDeviation(double tau_s) const;
  double TermDeviation(int term, double tau_s) const;
};

// How long a static record must be to resolve each term (docs/allan.md "How long to record"):
// for a sensor with white noise N, bias instability B and rate random walk K (SI; 0 for a term it
// does not have), sampled every tau0_s, the shortest record in which the overlapping Allan
// deviation at the tau where the term shows gives it to a relative 2-sigma interval `precision`
// (edf >= 2 / precision^2: the deviation's relative 1-sigma is sqrt(1 / (2 edf))), with at least
// `min_clusters` intervals of that tau in the record. Where each term shows: the random walk at the
// shortest tau where it carries 3/4 of the variance; the bias instability at the model's minimum
// (10 times the white/flicker crossover when there is no rate random walk), which to be resolved
// needs the curve to rise beyond it, so the record holds min_clusters intervals of twice that tau;
// the rate random walk where it carries 3/4 of the variance. nan: the term is 0, or no tau shows it.
struct RecordLength {
  double random_walk_s = std::nan("");
  double bias_instability_s = std::nan("");
  double bias_instability_tau_s = std::nan("");
  double rate_random_walk_s = std::nan("");
  double rate_random_walk_tau_s = std::nan("");
};
RecordLength RecordLengthFor(double n, double b, double k, double tau0_s, double precision,
                             double min_clusters = NoiseFitOptions().min_clusters);

// Fits the model to Allan-variance points (adev, oadev or totdev: the model is the Allan
// variance's) of a record of n_samples.
NoiseFitSummary FitNoiseModel(const std::vector<AllanPoint>& points, int64_t n_samples,
                              const NoiseFitOptions& options = NoiseFitOptions());

}  // namespace imufit

#endif  // IMUFIT_NOISE_NOISE_MODEL_H_
