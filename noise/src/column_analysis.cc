#include "imufit/noise/column_analysis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace imufit {

ColumnKind ColumnKindOf(const std::string& column, const std::string& kind) {
  if (kind == "gyro" || (kind == "auto" && column.rfind("gyro", 0) == 0)) return ColumnKind::kGyro;
  if (kind == "accel" || (kind == "auto" && column.rfind("accel", 0) == 0)) return ColumnKind::kAccel;
  return ColumnKind::kOther;
}

bool IsResolved(const NoiseFitSummary& fit, int term) {
  return fit.fitted && fit.variance[term] > kResolvedSigmas * fit.variance_sigma[term];
}

namespace {

// `value` to `digits` significant digits, without an exponent from 0.001 up (1234 -> "1234" at 2
// digits, 0.0123 -> "0.012"), with one below (9.1e-07).
std::string Significant(double value, int digits) {
  if (value == 0.0 || !std::isfinite(value)) return value == 0.0 ? "0" : std::to_string(value);
  if (std::abs(value) < 1e-3) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*e", digits - 1, value);
    return text;
  }
  const int decimals = std::max(0, digits - 1 - static_cast<int>(std::floor(std::log10(std::abs(value)))));
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace

NoiseTermFigure TermFigure(const NoiseFitSummary& fit, int term, double scale) {
  NoiseTermFigure figure;
  figure.resolved = IsResolved(fit, term);
  figure.value = fit.value[term] * scale;
  figure.sigma = fit.sigma[term] * scale;
  return figure;
}

std::string TermFigureText(const NoiseTermFigure& figure, const std::string& unit, const char* plus_minus) {
  const std::string space_unit = unit.empty() ? "" : " " + unit;
  if (figure.resolved) {
    return Significant(figure.value, 3) + " " + plus_minus + " " + Significant(figure.sigma, 2) + space_unit;
  }
  const std::string upper = Significant(figure.upper(), 2) + space_unit;
  return "at most " + upper + " (not resolved: estimate " + Significant(figure.value, 3) + space_unit +
         ", interval " + Significant(figure.lower(), 2) + " to " + upper + " at " +
         Significant(kNoiseIntervalSigmas, 1) + " sigma)";
}

QuotedFigure QuoteTerm(const NoiseFitSummary& fit, int term) {
  QuotedFigure quote;
  quote.term = term;
  const auto set = [&](QuoteSource source, double value, double sigma, double lower, double upper,
                       double lo_s, double hi_s) {
    quote.source = source;
    quote.value = value;
    quote.sigma = sigma;
    quote.lower = lower;
    quote.upper = upper;
    quote.tau_min_s = lo_s;
    quote.tau_max_s = hi_s;
  };
  const NoiseTermFigure figure = TermFigure(fit, term);
  const bool described = fit.fitted && fit.describes_curve;
  if (described && figure.resolved) {
    set(QuoteSource::kFit, figure.value, figure.sigma, figure.lower(), figure.upper(),
        fit.term_tau_min_s[term], fit.term_tau_max_s[term]);
    return quote;
  }
  const double two_sigma = kNoiseIntervalSigmas;
  if (term == kRandomWalk && std::isfinite(fit.readout_random_walk)) {
    const double n = fit.readout_random_walk, s = fit.readout_random_walk_sigma;
    set(QuoteSource::kReadout, n, s, std::max(0.0, n - two_sigma * s), n + two_sigma * s,
        fit.readout_random_walk_tau_min_s, fit.readout_random_walk_tau_max_s);
    return quote;
  }
  if (term == kBiasInstability && fit.readout_bias_resolved) {
    set(QuoteSource::kResolvedMinimum, fit.readout_bias_instability, std::nan(""), fit.readout_bias_lower,
        fit.readout_bias_upper, fit.readout_bias_tau_s, fit.readout_bias_tau_s);
    return quote;
  }
  if (term == kRateRandomWalk && std::isfinite(fit.readout_rate_random_walk)) {
    const double k = fit.readout_rate_random_walk, s = fit.readout_rate_random_walk_sigma;
    set(QuoteSource::kReadout, k, s, std::max(0.0, k - two_sigma * s), k + two_sigma * s,
        fit.readout_rate_random_walk_tau_min_s, fit.readout_rate_random_walk_tau_max_s);
    return quote;
  }
  if (described && std::isfinite(figure.upper())) {
    set(QuoteSource::kFitBound, figure.upper(), std::nan(""), 0.0, figure.upper(), fit.fit_tau_min_s,
        fit.fit_tau_max_s);
    return quote;
  }
  if (term == kRandomWalk && std::isfinite(fit.readout_random_walk_bound)) {
    set(QuoteSource::kCurveBound, fit.readout_random_walk_bound, std::nan(""), 0.0,
        fit.readout_random_walk_bound, fit.readout_random_walk_bound_tau_s,
        fit.readout_random_walk_bound_tau_s);
  } else if (term == kBiasInstability && std::isfinite(fit.readout_bias_upper)) {
    set(QuoteSource::kCurveBound, fit.readout_bias_upper, std::nan(""), 0.0, fit.readout_bias_upper,
        fit.readout_bias_tau_s, fit.readout_bias_tau_s);
  } else if (term == kRateRandomWalk && std::isfinite(fit.readout_rate_random_walk_bound)) {
    set(QuoteSource::kCurveBound, fit.readout_rate_random_walk_bound, std::nan(""), 0.0,
        fit.readout_rate_random_walk_bound, fit.readout_rate_random_walk_bound_tau_s,
        fit.readout_rate_random_walk_bound_tau_s);
  } else if (fit.fitted && std::isfinite(figure.upper()) && term != kRandomWalk) {
    // A misfit, and the curve gives nothing better: the fit's bound, said as such.
    set(QuoteSource::kFitBound, figure.upper(), std::nan(""), 0.0, figure.upper(), fit.fit_tau_min_s,
        fit.fit_tau_max_s);
  } else if (fit.fitted && term == kRandomWalk && figure.resolved) {
    set(QuoteSource::kMisfit, figure.value, figure.sigma, figure.lower(), figure.upper(),
        fit.term_tau_min_s[term], fit.term_tau_max_s[term]);
  }
  return quote;
}

std::string QuoteSourceText(const QuotedFigure& quote) {
  const auto taus = [&](const std::string& prefix) {
    if (!std::isfinite(quote.tau_min_s)) return std::string();
    if (quote.tau_min_s == quote.tau_max_s) return prefix + Significant(quote.tau_min_s, 3) + " s";
    return prefix + Significant(quote.tau_min_s, 3) + " to " + Significant(quote.tau_max_s, 3) + " s";
  };
  switch (quote.source) {
    case QuoteSource::kNone:
      return "nothing to quote";
    case QuoteSource::kFit:
      return "IEEE 952 fit" + (std::isfinite(quote.tau_min_s) ? " (dominant at " + taus("") + ")" : "");
    case QuoteSource::kReadout:
      return std::string("read-out along the ") + (quote.term == kRateRandomWalk ? "+1/2" : "-1/2") +
             " line" + taus(", ");
    case QuoteSource::kResolvedMinimum:
      return "resolved Allan minimum / 0.664" + taus(" at ");
    case QuoteSource::kFitBound:
      return "upper bound of the IEEE 952 fit (not resolved)";
    case QuoteSource::kMisfit:
      return "IEEE 952 fit of a curve it does not describe (no -1/2 segment to read): check the plot";
    case QuoteSource::kCurveBound:
      return "upper bound from the curve (not resolved)" + taus(" at ");
  }
  return "";
}

QuotedFigure Scaled(QuotedFigure quote, double scale) {
  quote.value *= scale;
  quote.sigma *= scale;
  quote.lower *= scale;
  quote.upper *= scale;
  return quote;
}

ColumnAnalysis AnalyseColumn(std::string name, ColumnKind kind, std::vector<double> rates, double tau0_s,
                             const std::vector<int64_t>& factors, const AllanOptions& options,
                             const NoiseFitOptions& fit_options) {
  ColumnAnalysis result;
  result.name = std::move(name);
  result.kind = kind;
  const int64_t n = static_cast<int64_t>(rates.size());
  std::vector<double> phase = std::move(rates);
  const double mean = RatesToPhase(&phase, options.threads);
  result.curve = ComputeAllan(phase, tau0_s, factors, options);
  result.curve.mean = mean;
  // The IEEE 952 model is the Allan variance's: fit it to the overlapping Allan deviation.
  if (options.estimator == AllanEstimator::kOadev) {
    result.allan = result.curve;
  } else {
    AllanOptions allan_options = options;
    allan_options.estimator = AllanEstimator::kOadev;
    result.allan = ComputeAllan(phase, tau0_s, factors, allan_options);
    result.allan.mean = mean;
  }
  result.fit = FitNoiseModel(result.allan.points, n, fit_options);
  return result;
}

}  // namespace imufit
