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
// The classic read-outs of IEEE 952 are reported too, from the measured curve alone: N from the
// slope -1/2 line through the curve where its slope is -1/2 (within 0.05, the segment with the
// most degrees of freedom; else the nearest slope within 0.25), read at tau = 1 s;
// B = minimum / 0.664; K likewise from the slope +1/2 line, read at tau = 3 s.
#ifndef IMUFIT_NOISE_NOISE_MODEL_H_
#define IMUFIT_NOISE_NOISE_MODEL_H_

#include <array>
#include <cmath>
#include <cstdint>
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

  std::string Validate() const;  // from NoiseFitOptionTable()
};
// min_clusters (on the command line of `imufit allan`) and iterations.
const OptionTable<NoiseFitOptions>& NoiseFitOptionTable();

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

  // Classic read-outs (nan when the curve has no such region).
  double readout_random_walk = std::nan("");       // N, from the -1/2 line at 1 s
  double readout_bias_instability = std::nan("");  // B = min / 0.664
  double readout_bias_tau_s = std::nan("");        // where the minimum is
  double readout_rate_random_walk = std::nan("");  // K, from the +1/2 line at 3 s

  // The fitted Allan deviation and one term's share, at tau.
  double ModelDeviation(double tau_s) const;
  double TermDeviation(int term, double tau_s) const;
};

// Fits the model to Allan-variance points (adev, oadev or totdev: the model is the Allan
// variance's) of a record of n_samples.
NoiseFitSummary FitNoiseModel(const std::vector<AllanPoint>& points, int64_t n_samples,
                              const NoiseFitOptions& options = NoiseFitOptions());

}  // namespace imufit

#endif  // IMUFIT_NOISE_NOISE_MODEL_H_
