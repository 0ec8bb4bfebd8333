// imufit — Allan deviation and its relatives, with confidence intervals (NIST SP 1065).
//
// Input: n rate samples y_0 .. y_{n-1} (a gyro in rad/s, an accelerometer in m/s^2: the
// "fractional frequency" of SP 1065) at a uniform interval tau0. Internally the mean is removed
// and the samples are integrated into the phase (angle, velocity) in units of tau0:
//
//   X_0 = 0,  X_k = sum_{i<k} (y_i - mean(y)),  k = 0 .. n        (N = n + 1 phase points)
//
// so that SP 1065's phase is x_k = tau0 X_k. Removing the mean changes X by a straight line, which
// every estimator below cancels exactly; it keeps X small, so double X loses no digits of the
// differences even for 1e8 samples (X is accumulated in long double, stored as double). With
// m = tau / tau0 the averaging factor and T the number of terms:
//
//   adev   AVAR  = sum_{j}   (X_{(j+2)m} - 2 X_{(j+1)m} + X_{jm})^2 / (2 m^2 T),  j = 0..T-1,
//                  T = floor(n/m) - 1                                 (non-overlapping, eq. 6)
//   oadev  AVAR  = sum_{i}   (X_{i+2m} - 2 X_{i+m} + X_i)^2 / (2 m^2 T),  T = N - 2m   (eq. 11)
//   mdev   MVAR  = sum_{j}   (sum_{i=j}^{j+m-1} (X_{i+2m} - 2 X_{i+m} + X_i))^2 / (2 m^4 T),
//                  T = N - 3m + 1                                                   (eq. 14)
//   tdev   TDEV  = tau / sqrt(3) * MDEV                       (units of y times seconds, eq. 15)
//   hdev   HVAR  = sum_{j}   (X_{(j+3)m} - 3 X_{(j+2)m} + 3 X_{(j+1)m} - X_{jm})^2 / (6 m^2 T),
//                  T = floor(n/m) - 2                                               (eq. 17)
//   ohdev  HVAR  = same with stride 1, T = N - 3m                                   (eq. 18)
//   totdev TOTVAR = sum_{i=1}^{N-2} (X*_{i-m} - 2 X*_i + X*_{i+m})^2 / (2 m^2 (N - 2)), where X*
//                  extends X by reflection about both ends: X*_{-j} = 2 X_0 - X_j,
//                  X*_{N-1+j} = 2 X_{N-1} - X_{N-1-j}                                (eq. 25)
//
// Each averaging factor costs one O(N) pass. The overlapping estimators evaluate many averaging
// factors in one sweep over X in cache-sized blocks, so that octave factors, whose offsets m and
// 2m coincide, share their memory traffic; the sweep is split across threads. Sums of squares are
// accumulated per block in double and across blocks in long double.
//
// Confidence intervals: chi-squared with Greenhall's equivalent degrees of freedom (statistics.h),
// for a noise type identified per averaging factor by the lag-1 autocorrelation of the rate
// averages, or assumed (EdfNoise). Identification needs 30 averages; with fewer than 100 it only
// lowers alpha (the conservative side: fewer degrees of freedom); where it is impossible the type
// of the previous factor is carried (white FM before any).
#ifndef IMUFIT_NOISE_ALLAN_H_
#define IMUFIT_NOISE_ALLAN_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "imufit/base/option_table.h"

namespace imufit {

enum class AllanEstimator { kAdev, kOadev, kMdev, kTdev, kHdev, kOhdev, kTotdev };

// "adev", "oadev", ...
const char* ToString(AllanEstimator estimator);
// Parses a name; false (and `estimator` untouched) for anything else.
bool ParseAllanEstimator(std::string_view text, AllanEstimator* estimator);
// "adev, oadev, mdev, tdev, hdev, ohdev, totdev", for messages and help.
std::string AllanEstimatorNames();

// The noise type assumed for the degrees of freedom of the confidence intervals.
enum class EdfNoise {
  kIdentify,      // "auto": lag-1 autocorrelation per averaging factor (statistics.h)
  kWhitePm,       // "wpm",  alpha = +2 (quantisation)
  kFlickerPm,     // "fpm",  alpha = +1
  kWhiteFm,       // "wfm",  alpha =  0 (angle / velocity random walk)
  kFlickerFm,     // "ffm",  alpha = -1 (bias instability)
  kRandomWalkFm,  // "rwfm", alpha = -2 (rate random walk)
};
const char* ToString(EdfNoise noise);
bool ParseEdfNoise(std::string_view text, EdfNoise* noise);
std::string EdfNoiseNames();

// Which averaging factors to evaluate.
//   octave          m = 1, 2, 4, 8, ...
//   decade          m = 1, 2, 4, 10, 20, 40, 100, ... (Stable32's decade set)
//   all             every m = 1, 2, 3, ... (O(N^2): for short records)
//   per-decade:K    K log-spaced factors per decade, m = round(10^(i/K)), duplicates dropped
//   a list          taus in seconds, "1,10,100"; each must be a whole multiple of tau0 within
//                   kTauMultipleTolerance of an interval, and fit in the data
// The generated sets stop where the estimator would have too few terms: m <= n / 4 for the
// Allan, modified and Hadamard families (at least about three independent clusters, as Stable32),
// m <= n / 2 for totdev (SP 1065: tau up to half the record).
struct TauSpec {
  enum class Kind { kOctave, kDecade, kAll, kPerDecade, kList };
  Kind kind = Kind::kOctave;
  int per_decade = 0;          // kPerDecade
  std::vector<double> taus_s;  // kList
};
inline constexpr double kTauMultipleTolerance = 0.01;
// Parses the --taus text; returns "" or a message naming the allowed forms.
std::string ParseTauSpec(std::string_view text, TauSpec* spec);

// The largest averaging factor with at least one term, and the largest a generated set uses.
int64_t MaxAveragingFactor(AllanEstimator estimator, int64_t n_samples);
int64_t MaxGeneratedAveragingFactor(AllanEstimator estimator, int64_t n_samples);
// Number of terms T of the estimator (see above); <= 0 when m does not fit.
int64_t EstimatorTerms(AllanEstimator estimator, int64_t m, int64_t n_samples);

// The averaging factors of `spec` for n samples at tau0, ascending, unique. Returns "" or a
// message (a tau that is not a multiple of tau0, or that does not fit, or an empty set).
std::string AveragingFactors(const TauSpec& spec, AllanEstimator estimator, int64_t n_samples, double tau0_s,
                             std::vector<int64_t>* factors);

// The options of the computation. AllanOptionTable() describes each (the command line of `imufit
// allan`, the Python keywords, the validation messages); the defaults are these.
struct AllanOptions {
  AllanEstimator estimator = AllanEstimator::kOadev;
  // Two-sided confidence of [dev_lo, dev_hi], 0 < confidence < 1; the default is one sigma (the
  // probability of a normal variable within one standard deviation of its mean, 68.3 %).
  double confidence = 0.683;
  // Noise type behind the degrees of freedom; kIdentify identifies it per averaging factor.
  EdfNoise edf_noise = EdfNoise::kIdentify;
  // Worker threads; 0 = all hardware threads.
  int threads = 0;
  // Noise identification uses at most this many rate averages per factor (the first ones): the
  // lag-1 autocorrelation is settled long before, and the cost stays bounded at m = 1.
  int64_t max_noise_id_points = int64_t{1} << 18;

  // "" when valid, else a readable reason naming the option and its value.
  std::string Validate() const;
};
// Every option of AllanOptions but max_noise_id_points (a bound on work, not a user's choice).
const OptionTable<AllanOptions>& AllanOptionTable();

struct AllanPoint {
  int64_t m = 0;        // averaging factor
  double tau_s = 0.0;   // m * tau0
  int64_t terms = 0;    // T
  double dev = 0.0;     // the deviation (y units; tdev: y units * s)
  double dev_lo = 0.0;  // confidence interval; nan when no edf could be computed
  double dev_hi = 0.0;
  double edf = 0.0;               // equivalent degrees of freedom (nan when unknown)
  int alpha = 0;                  // noise exponent used for the edf
  bool alpha_identified = false;  // identified at this m (else assumed or carried from below)
  // Lag-1 autocorrelation of the non-overlapping rate averages over tau (mean removed; nan with
  // fewer than kMinLag1Averages averages). White noise gives 0 +- 1/sqrt(n/m), quantization
  // (white PM) -1/2, an output filter a positive value that decays as 1/m once m exceeds the
  // filter's memory; flicker and random walks a value that does not decay (noise_model.h).
  double lag1 = std::nan("");
};
// The fewest averages a lag-1 autocorrelation is computed from.
inline constexpr int64_t kMinLag1Averages = 30;

struct AllanResult {
  AllanEstimator estimator = AllanEstimator::kOadev;
  double tau0_s = 0.0;
  int64_t n_samples = 0;
  double mean = 0.0;  // the mean that was removed, y units
  std::vector<AllanPoint> points;
};

// Integrates rates in place into the phase X of the header comment (n + 1 values; the vector
// grows by one: reserve n + 1 to spare a reallocation) and returns the removed mean. Uses
// `threads` threads (0 = all).
double RatesToPhase(std::vector<double>* samples, int threads = 0);

// Deviations only (no confidence intervals): deviation[i] for factors[i], from the phase X.
// The fast path the benchmark measures.
std::vector<double> Deviations(const std::vector<double>& phase, double tau0_s,
                               const std::vector<int64_t>& factors, AllanEstimator estimator,
                               int threads = 0);

// The full computation: deviations, terms, noise identification, edf and intervals.
// `phase` from RatesToPhase. Factors must satisfy EstimatorTerms(...) >= 1 (checked: abort).
AllanResult ComputeAllan(const std::vector<double>& phase, double tau0_s, const std::vector<int64_t>& factors,
                         const AllanOptions& options);

// Convenience for tests and small data: copies the rates, integrates, computes.
AllanResult ComputeAllanFromRates(std::vector<double> rates, double tau0_s,
                                  const std::vector<int64_t>& factors, const AllanOptions& options);

}  // namespace imufit

#endif  // IMUFIT_NOISE_ALLAN_H_
