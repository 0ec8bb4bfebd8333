// imufit — the statistics behind Allan-deviation confidence intervals (NIST SP 1065 section 5).
//
// A variance estimate s^2 of a true variance sigma^2 with `edf` equivalent degrees of freedom is
// modelled as chi-squared: edf * s^2 / sigma^2 ~ chi2(edf). The two-sided interval of confidence
// p for sigma is therefore
//
//   sigma_lo = s * sqrt(edf / chi2_q((1 + p) / 2, edf)),
//   sigma_hi = s * sqrt(edf / chi2_q((1 - p) / 2, edf)),                      (SP 1065 eq. 45)
//
// where chi2_q(P, k) is the chi-squared quantile: the x with P(chi2(k) <= x) = P. The quantile is
// computed from the regularized incomplete gamma function, chi2_q(P, k) = 2 * P^-1(k / 2, P), with
// a safeguarded Newton iteration; no tables, valid for 0.05 <= k <= 1e9.
//
// Equivalent degrees of freedom follow C. A. Greenhall and W. J. Riley, "Uncertainty of stability
// variances based on finite differences", 35th PTTI (2003) — the algorithm Stable32 uses — for the
// Allan, modified Allan and Hadamard families, and SP 1065 table 7 for the total deviation.
// Noise types are the power-law exponents alpha of S_y(f) ~ f^alpha:
//   +2 white PM, +1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM,
//   -3 flicker walk FM, -4 random run FM.
// For an IMU rate signal ("frequency" y = rate, "phase" x = angle): white FM is angle random walk,
// flicker FM is bias instability, random-walk FM is rate random walk, white PM is quantisation.
#ifndef IMUFIT_NOISE_STATISTICS_H_
#define IMUFIT_NOISE_STATISTICS_H_

#include <cstdint>
#include <optional>

namespace imufit {

// Regularized lower incomplete gamma P(a, x) = gamma(a, x) / Gamma(a), a > 0, x >= 0, and its
// complement Q = 1 - P, each to about 1e-14 relative (Q is computed directly, not as 1 - P).
void RegularizedGamma(double a, double x, double* p, double* q);

// The chi-squared quantile: x with P(chi2(dof) <= x) = probability, 0 < probability < 1.
double ChiSquaredQuantile(double probability, double dof);

// Standard normal quantile (inverse of Phi), used for starting values; about 1e-15 absolute.
double NormalQuantile(double probability);

// The interval [dev_lo, dev_hi] of confidence `confidence` (e.g. one sigma) for a deviation `dev`
// estimated with `edf` equivalent degrees of freedom (SP 1065 eq. 45).
void ChiSquaredInterval(double dev, double edf, double confidence, double* dev_lo, double* dev_hi);

// Greenhall's edf for a variance built from d-th differences of N phase samples.
//   alpha: noise exponent, alpha + 2 d > 1 (alpha in [-4, 2]).
//   d: 1 (first difference), 2 (Allan), 3 (Hadamard).
//   m: averaging factor tau / tau0.
//   modified: true for the modified variances (filter factor F = 1), false for F = m.
//   overlapping: true for stride 1 (S = m), false for stride m (S = 1).
//   n_phase: number of phase samples N (rate samples + 1).
// Returns nullopt when the estimator does not fit in N samples or alpha is outside the domain.
std::optional<double> GreenhallEdf(int alpha, int d, int64_t m, bool modified, bool overlapping,
                                   int64_t n_phase);

// The edf of the total deviation, SP 1065 table 7: edf = b (T / tau) - c with T / tau = N / m,
// b, c = (1.50, 0), (1.17, 0.22), (0.93, 0.36) for alpha = 0, -1, -2. For alpha > 0 the total and
// overlapping Allan deviations coincide in distribution closely; the overlapping Allan edf is used.
std::optional<double> TotdevEdf(int alpha, int64_t m, int64_t n_phase);

// Lag-1 autocorrelation noise identification (W. J. Riley and C. A. Greenhall, "Power law noise
// identification using the lag 1 autocorrelation", 18th EFTF, 2004), on frequency (rate) data.
//
// `means` are the non-overlapping averages of the rate over the averaging time (at least
// kMinNoiseIdPoints of them). A linear drift is removed, then with r1 the lag-1 autocorrelation,
// rho = r1 / (1 + r1); while rho >= 0.25 and fewer than d_max differences were taken, the series is
// differenced once more (d += 1). The noise exponent is alpha = -2 (rho + d), rounded:
// alpha = -round(2 rho) - 2 d. d_max is 2 for the Allan family and 3 for the Hadamard family.
struct NoiseIdentification {
  int alpha = 0;              // the rounded noise exponent
  double alpha_estimate = 0;  // the unrounded one, -2 (rho + d)
  int differences = 0;        // d
};
inline constexpr int64_t kMinNoiseIdPoints = 30;
// Below this many averages an identification is used only when it is the more conservative one.
inline constexpr int64_t kReliableNoiseIdPoints = 100;
std::optional<NoiseIdentification> IdentifyNoiseLag1(const double* means, int64_t count, int d_max);

}  // namespace imufit

#endif  // IMUFIT_NOISE_STATISTICS_H_
