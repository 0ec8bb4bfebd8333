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

#include "imufit/model/noise_terms.h"
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
