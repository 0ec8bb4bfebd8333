#include "imufit/noise/column_analysis.h"

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
