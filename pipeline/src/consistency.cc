#include "imufit/pipeline/consistency.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "imufit/base/text.h"
#include "imufit/model/constants.h"

namespace imufit {
namespace {

// A sensor held whole (SensorFit::kNone) was not fitted: its chi-square measures the held values.
std::string Chi2Finding(const char* sensor, bool judged, double reduced_chi2, int dof) {
  if (!judged || dof <= 0 || !(reduced_chi2 > ReducedChi2Limit(dof))) return "";
  return std::string(sensor) + " reduced chi-square " + NumberText("%.3g", reduced_chi2) + " (at most " +
         NumberText("%.3g", ReducedChi2Limit(dof)) + " for the noise and model error of " +
         std::to_string(dof) + " degrees of freedom)";
}

// The temperature cluster (index into distinct_temps_c) nearest to `temp_c`.
size_t Cluster(const std::vector<double>& centres, double temp_c) {
  size_t best = 0;
  for (size_t c = 1; c < centres.size(); ++c) {
    if (std::abs(centres[c] - temp_c) < std::abs(centres[best] - temp_c)) best = c;
  }
  return best;
}

// Segments down-weighted (more than half of their windows) at every temperature they were seen at.
std::string DownweightedSegments(const FitSummary& fit, const std::vector<Window>& windows, bool gyro_judged,
                                 bool accel_judged) {
  struct Count {
    int windows = 0;
    int downweighted = 0;
  };
  std::map<int, std::map<size_t, Count>> counts;  // segment -> temperature cluster -> counts
  std::map<int, double> gyro_sum;                 // squared residuals, for the finding
  std::map<int, double> accel_sum;
  std::map<int, double> normalised_sum;  // squared residuals over the noise of the window means
  // |residual / sigma|^2 per axis, over the axes that carry a weight.
  const auto normalised = [](const Eigen::Vector3d& residual, const Eigen::Vector3d& sigma) {
    double sum = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      if (sigma(axis) > 0.0) sum += (residual(axis) / sigma(axis)) * (residual(axis) / sigma(axis));
    }
    return sum;
  };
  for (const WindowResidual& r : fit.residuals) {
    const Window& w = windows[static_cast<size_t>(r.window)];
    Count& count =
        counts[w.segment][fit.distinct_temps_c.empty() ? 0 : Cluster(fit.distinct_temps_c, w.temp_c)];
    ++count.windows;
    count.downweighted += r.downweighted ? 1 : 0;
    gyro_sum[w.segment] += r.gyro_radps.squaredNorm() / 3.0;
    accel_sum[w.segment] += r.accel_mps2.squaredNorm() / 3.0;
    normalised_sum[w.segment] += ((gyro_judged ? normalised(r.gyro_radps, r.gyro_sigma_radps) : 0.0) +
                                  (accel_judged ? normalised(r.accel_mps2, r.accel_sigma_mps2) : 0.0)) /
                                 (3.0 * (gyro_judged + accel_judged));
  }
  std::string text;
  for (const auto& [segment, by_temp] : counts) {
    std::string temps;
    int windows_seen = 0;
    bool everywhere = true;
    for (const auto& [cluster, count] : by_temp) {
      everywhere = everywhere && 2 * count.downweighted > count.windows;
      windows_seen += count.windows;
      if (!fit.distinct_temps_c.empty())
        temps += (temps.empty() ? "" : ", ") + NumberText("%.0f", fit.distinct_temps_c[cluster]);
    }
    if (!everywhere ||
        normalised_sum[segment] / windows_seen <= kModelErrorAllowance * kModelErrorAllowance) {
      continue;
    }
    text += (text.empty() ? "" : "; ") + std::string("segment ") + std::to_string(segment) +
            " down-weighted at every temperature (" + temps + " degC), residual RMS gyro " +
            NumberText("%.3g", std::sqrt(gyro_sum[segment] / windows_seen) * kRadToDeg) + " deg/s, accel " +
            NumberText("%.3g", std::sqrt(accel_sum[segment] / windows_seen) / (1e-3 * kStandardGravityMps2)) +
            " mg";
  }
  return text;
}

}  // namespace

double ReducedChi2Limit(int dof) {
  return kModelErrorAllowance * kModelErrorAllowance *
         (1.0 + kChi2Sigmas * std::sqrt(2.0 / std::max(dof, 1)));
}

bool JudgedByTheGate(const FitOptions& options, bool gyro) {
  const int default_order = FitOptions().gyro_temp_order;
  if (gyro) {
    return options.gyro_fit == SensorFit::kAll && options.fit_g_sensitivity &&
           options.gyro_temp_order >= default_order;
  }
  return options.accel_fit == SensorFit::kAll && options.accel_temp_order >= default_order;
}

std::string Inconsistency(const FitSummary& fit, const std::vector<Window>& windows,
                          const FitOptions& options) {
  const bool gyro = JudgedByTheGate(options, true), accel = JudgedByTheGate(options, false);
  if (!gyro && !accel) return "";
  std::string text;
  for (const std::string& finding : {Chi2Finding("gyro", gyro, fit.gyro_reduced_chi2, fit.gyro_dof),
                                     Chi2Finding("accel", accel, fit.accel_reduced_chi2, fit.accel_dof),
                                     DownweightedSegments(fit, windows, gyro, accel)}) {
    if (!finding.empty()) text += (text.empty() ? "" : "; ") + finding;
  }
  if (text.empty()) return text;
  return text + ": the plan does not describe the run (a segment's up, rate, angle or axis, or its labels)";
}

}  // namespace imufit
