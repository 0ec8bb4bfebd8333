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
