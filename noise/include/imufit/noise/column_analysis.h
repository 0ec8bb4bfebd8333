// imufit — the noise analysis of one column of rates: its deviation curve (the chosen estimator),
// the overlapping Allan deviation, and the IEEE Std 952 model fitted to it. What `imufit allan`
// runs per column and what a certificate runs on each gyro axis of a static stretch.
//
// The rates are in the column's own unit (SI for a corrected file: rad/s, m/s^2); the kind says
// which engineer units a writer uses (io/noise_file.h).
#ifndef IMUFIT_NOISE_COLUMN_ANALYSIS_H_
#define IMUFIT_NOISE_COLUMN_ANALYSIS_H_

#include <string>
#include <vector>

#include "imufit/base/noise_terms.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/noise_model.h"

namespace imufit {

// ColumnKind, ToString(ColumnKind) and SiUnit() are model/noise_terms.h.

// `kind` is "auto", "gyro", "accel" or "other"; auto: gyro_* columns are gyros, accel_* are
// accelerometers, others are other.
ColumnKind ColumnKindOf(const std::string& column, const std::string& kind);

// A noise term counts as resolved when its variance coefficient (Q^2, N^2, B^2, ...) exceeds this
// many of its standard uncertainties (on the coefficient itself: its square root is not Gaussian
// near 0). An unresolved term is reported as "not resolved", never as "0 +- s".
inline constexpr double kResolvedSigmas = 2.0;
bool IsResolved(const NoiseFitSummary& fit, int term);

// A noise term's figure as a data sheet quotes it. The fit estimates `value` with the standard
// uncertainty `sigma`; its interval is value -+ kNoiseIntervalSigmas sigma, the lower bound clipped
// at 0 (an amplitude is not negative). A resolved term is quoted as its value (+- sigma); one the
// data do not resolve as "at most" the interval's upper bound: its estimate is not a measurement,
// and kResolvedSigmas sigma of the coefficient is not a bound on it.
inline constexpr double kNoiseIntervalSigmas = 2.0;
struct NoiseTermFigure {
  bool resolved = false;
  double value = 0.0;  // the fit's estimate
  double sigma = 0.0;  // its standard uncertainty

  double lower() const {
    return value - kNoiseIntervalSigmas * sigma > 0.0 ? value - kNoiseIntervalSigmas * sigma : 0.0;
  }
  double upper() const { return value + kNoiseIntervalSigmas * sigma; }
  // The figure to quote: the value when resolved, else the upper bound ("at most").
  double quoted() const { return resolved ? value : upper(); }
};
// Term `term` of `fit` in a unit `scale` times the fit's (1 for SI).
NoiseTermFigure TermFigure(const NoiseFitSummary& fit, int term, double scale = 1.0);
// The figure in words, `unit` after each number: "0.344 +- 0.012 deg/sqrt(h)" when resolved, else
// "at most 6.9 deg/h (not resolved: estimate 2.88 deg/h, interval 0 to 6.9 deg/h at 2 sigma)".
// `plus_minus` writes +-: "+-" for a terminal, "\xc2\xb1" for a page.
std::string TermFigureText(const NoiseTermFigure& figure, const std::string& unit,
                           const char* plus_minus = "+-");

// Which figure of a term to quote (docs/allan.md, "Which figure to quote"), for the random walk,
// the bias instability and the rate random walk; the other terms are the fit's figure.
//   - the fit's value when the model describes the curve (NoiseFitSummary::describes_curve) and
//     resolves the term;
//   - else the read-out where the curve shows the term: the random walk along the -1/2 segment,
//     the bias instability at a resolved minimum, the rate random walk along the +1/2 segment;
//   - else an upper bound ("at most"): the fit's when it describes the curve, else the curve's own
//     (every point lies above the flat floor 0.664 B and above K sqrt(tau / 3): the lowest point's
//     upper 95 % bound / 0.664; the longest tau's upper bound times sqrt(3 / tau)).
// Nothing to quote (no fit, no read-out): value nan.
//   - last, for the random walk of a misfit curve without a -1/2 segment: the fit's value, said
//     as a misfit's (kMisfit).
enum class QuoteSource { kNone, kFit, kReadout, kResolvedMinimum, kFitBound, kCurveBound, kMisfit };
struct QuotedFigure {
  QuoteSource source = QuoteSource::kNone;
  int term = kRandomWalk;
  double value = std::nan("");  // the figure to quote (an upper bound when bound())
  double sigma = std::nan("");  // 1-sigma (nan for a bound)
  double lower = std::nan("");  // the 2-sigma (95 %) interval
  double upper = std::nan("");
  double tau_min_s = std::nan("");  // where on the curve the figure comes from
  double tau_max_s = std::nan("");
  bool bound() const { return source == QuoteSource::kFitBound || source == QuoteSource::kCurveBound; }
  bool found() const { return source != QuoteSource::kNone; }
};
QuotedFigure QuoteTerm(const NoiseFitSummary& fit, int term);
// Where a quoted figure comes from, in words: "IEEE 952 fit (dominant at 0.08 to 20 s)",
// "read-out along the -1/2 line, 0.16 to 2.6 s", "resolved Allan minimum at 655 s", ...
std::string QuoteSourceText(const QuotedFigure& quote);
// A figure in a unit `scale` times the fit's.
QuotedFigure Scaled(QuotedFigure quote, double scale);

struct ColumnAnalysis {
  std::string name;
  ColumnKind kind = ColumnKind::kOther;
  AllanResult curve;  // the estimator asked for
  AllanResult allan;  // the overlapping Allan deviation the noise fit used (== curve for oadev)
  NoiseFitSummary fit;
};

// Analyses one column of uniformly sampled rates (moved in: its memory is reused for the phase).
// `factors` come from AveragingFactors() for the record's length.
ColumnAnalysis AnalyseColumn(std::string name, ColumnKind kind, std::vector<double> rates, double tau0_s,
                             const std::vector<int64_t>& factors, const AllanOptions& options,
                             const NoiseFitOptions& fit_options = NoiseFitOptions());

}  // namespace imufit

#endif  // IMUFIT_NOISE_COLUMN_ANALYSIS_H_
