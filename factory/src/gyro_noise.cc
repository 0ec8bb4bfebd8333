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
  a.arw_deg_per_sqrt_hr = TermFigure(fit, kRandomWalk, DegPerSqrtHrFromRadPerSqrtS(1.0));
  a.bias_instability_dph = TermFigure(fit, kBiasInstability, DphFromRadps(1.0));
  return a;
}

}  // namespace

NoiseSection GyroNoise(const Calibration& calibration, StaticStretch stretch) {
  const size_t n = static_cast<size_t>(stretch.size());
  NoiseSection section;
  section.duration_s = stretch.duration_s();
  section.segment = stretch.segment;
  section.chosen = stretch.chosen;
  if (n > 0) section.temp_c = stretch.mean_temp_c();
  if (section.duration_s < kMinAllanStretchS) {
    const std::string which = stretch.named ? "the static stretch of segment " +
                                                  std::to_string(stretch.segment) + " (--noise-segment)"
                                            : std::string("the longest static stretch");
    char text[240];
    std::snprintf(text, sizeof text,
                  "%s is %.1f s, and the Allan deviation needs at least %.0f s (imufit allan measures the "
                  "noise on a long static log)",
                  which.c_str(), section.duration_s, kMinAllanStretchS);
    section.why_not = text;
    return section;
  }
  section.computed = true;
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
                              const std::optional<Segmentation>& segmentation,
                              const NoiseStretchOptions& options) {
  try {
    return GyroNoise(calibration, ReadStaticStretch(plan, samples_path, input, segmentation, options));
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
