#include "imufit/factory/gyro_noise.h"

#include <cstdio>
#include <utility>

#include "imufit/io/error.h"
#include "imufit/io/samples.h"
#include "imufit/io/units.h"

namespace imufit {
namespace {

// The section's figures of one axis from its noise fit, in deg/sqrt(h) and deg/h.
NoiseAxis AxisFigures(const char* axis, const NoiseFitSummary& fit) {
  NoiseAxis a;
  a.axis = axis;
  a.fitted = fit.fitted;
  a.why_not = fit.message;
  if (!fit.fitted) return a;
  a.points = fit.points_used;
  a.arw_deg_per_sqrt_hr = DegPerSqrtHrFromRadPerSqrtS(fit.value[kRandomWalk]);
  a.arw_sigma = DegPerSqrtHrFromRadPerSqrtS(fit.sigma[kRandomWalk]);
  a.arw_resolved = IsResolved(fit, kRandomWalk);
  a.bias_instability_dph = DphFromRadps(fit.value[kBiasInstability]);
  a.bias_instability_sigma = DphFromRadps(fit.sigma[kBiasInstability]);
  a.bias_instability_resolved = IsResolved(fit, kBiasInstability);
  return a;
}

}  // namespace

NoiseSection GyroNoise(const Calibration& calibration, StaticStretch stretch) {
  const size_t n = static_cast<size_t>(stretch.size());
  NoiseSection section;
  section.duration_s = stretch.duration_s();
  if (section.duration_s < kMinAllanStretchS) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the longest static stretch is %.1f s, and the Allan deviation needs at least "
                  "%.0f s (imufit allan measures the noise on a long static log)",
                  section.duration_s, kMinAllanStretchS);
    section.why_not = text;
    return section;
  }
  section.computed = true;
  section.segment = stretch.segment;
  section.temp_c = stretch.temp_sum_c / n;
  const double tau0_s = section.duration_s / (n - 1);
  std::vector<int64_t> factors;
  AveragingFactors(TauSpec(), AllanEstimator::kOadev, static_cast<int64_t>(n), tau0_s, &factors);
  AllanOptions options;
  options.threads = 1;
  const double x = calibration.model.basis.Argument(section.temp_c);
  const char* axes[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const double scale = EvaluateTemperaturePolynomial(
        calibration.model.gyro.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
    std::vector<double> rates = std::move(stretch.gyro[axis]);  // in place: raw to rad/s
    for (double& rate : rates) rate /= scale;
    ColumnAnalysis analysis = AnalyseColumn(std::string("gyro_") + axes[axis], ColumnKind::kGyro,
                                            std::move(rates), tau0_s, factors, options);
    section.axes.push_back(AxisFigures(axes[axis], analysis.fit));
    section.columns.push_back(std::move(analysis));
  }
  return section;
}

NoiseSection MeasureGyroNoise(const Calibration& calibration, const Plan& plan,
                              const std::string& samples_path, const SamplesInput& input,
                              const std::optional<Segmentation>& segmentation) {
  try {
    return GyroNoise(calibration, ReadStaticStretch(plan, samples_path, input, segmentation));
  } catch (const InputError& e) {  // the data, not the program: said in the section
    NoiseSection section;
    section.why_not = e.what();
    return section;
  } catch (const PlanMismatchError& e) {
    NoiseSection section;
    section.why_not = e.what();
    return section;
  }
}

}  // namespace imufit
