#include "imufit/fit/validation.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace imufit {

std::vector<WindowError> PredictWindows(const SensorModel& model, const std::vector<Window>& windows,
                                        const TableSite& site, const std::vector<TableSegment>& segments) {
  std::vector<WindowError> errors;
  for (size_t w = 0; w < windows.size(); ++w) {
    const Window& window = windows[w];
    const auto segment = std::find_if(segments.begin(), segments.end(),
                                      [&](const TableSegment& s) { return s.id == window.segment; });
    if (segment == segments.end()) continue;
    // As the fit takes it: a turn's truth is its mean rate over the whole occurrence.
    const SegmentTruth truth =
        segment->IsTurn() ? TurnTruth(site, *segment, window.DurationS()) : TruthOf(site, *segment);
    WindowError error;
    error.window = static_cast<int>(w);
    error.segment = window.segment;
    error.temp_c = window.temp_c;
    Eigen::Vector3d omega_hat;
    Eigen::Vector3d a_hat;
    model.Correct(window.temp_c, window.gyro_mean, window.accel_mean, &omega_hat, &a_hat);
    error.gyro_radps = omega_hat - truth.omega_radps;
    error.accel_mps2 = a_hat - truth.a_mps2;
    error.omega_true_radps = truth.omega_radps;
    error.a_true_mps2 = truth.a_mps2;
    error.specific_force_known = segment->SpecificForceIsKnown();
    errors.push_back(error);
  }
  return errors;
}

ErrorStats SummariseErrors(const std::vector<WindowError>& errors) {
  ErrorStats stats;
  double gyro_sum = 0.0;
  double accel_sum = 0.0;
  for (const WindowError& e : errors) {
    ++stats.windows;
    gyro_sum += e.gyro_radps.squaredNorm();
    stats.gyro_max_radps = std::max(stats.gyro_max_radps, e.gyro_radps.cwiseAbs().maxCoeff());
    if (!e.specific_force_known) continue;  // its accel error is against a specific force that turned
    ++stats.accel_windows;
    accel_sum += e.accel_mps2.squaredNorm();
    stats.accel_max_mps2 = std::max(stats.accel_max_mps2, e.accel_mps2.cwiseAbs().maxCoeff());
  }
  // RMS per axis component.
  if (stats.windows > 0) stats.gyro_rms_radps = std::sqrt(gyro_sum / (3.0 * stats.windows));
  if (stats.accel_windows > 0) stats.accel_rms_mps2 = std::sqrt(accel_sum / (3.0 * stats.accel_windows));
  return stats;
}

std::vector<ErrorStats> ErrorsBySegment(const std::vector<WindowError>& errors) {
  std::map<int, std::vector<WindowError>> by_segment;
  for (const WindowError& e : errors) by_segment[e.segment].push_back(e);
  std::vector<ErrorStats> stats;
  for (const auto& [segment, segment_errors] : by_segment) {
    stats.push_back(SummariseErrors(segment_errors));
    stats.back().segment = segment;
  }
  return stats;
}

std::vector<HeldOutGroup> LeaveOneTemperatureOut(const std::vector<Window>& windows, const TableSite& site,
                                                 const std::vector<TableSegment>& segments,
                                                 const FitOptions& options, int max_groups) {
  std::vector<double> temps;
  for (const Window& w : windows) temps.push_back(w.temp_c);
  std::vector<double> centres = DistinctTemperatures(temps, options.distinct_temp_c);
  std::vector<HeldOutGroup> groups;
  if (centres.size() < 3) return groups;
  // Group edges: midway between distinct temperatures, or equal bands for a ramp.
  std::vector<double> edges;
  if (static_cast<int>(centres.size()) > max_groups) {
    const double lo = centres.front();
    const double hi = centres.back();
    centres.clear();
    for (int g = 0; g < max_groups; ++g) {
      centres.push_back(lo + (hi - lo) * (g + 0.5) / max_groups);
      if (g > 0) edges.push_back(lo + (hi - lo) * g / max_groups);
    }
  } else {
    for (size_t g = 1; g < centres.size(); ++g) edges.push_back(0.5 * (centres[g - 1] + centres[g]));
  }
  const auto group_of = [&](double temp_c) {
    return static_cast<int>(std::upper_bound(edges.begin(), edges.end(), temp_c) - edges.begin());
  };
  for (int g = 1; g + 1 < static_cast<int>(centres.size()); ++g) {
    std::vector<Window> kept;
    std::vector<Window> held;
    for (const Window& w : windows) (group_of(w.temp_c) == g ? held : kept).push_back(w);
    HeldOutGroup group;
    group.temp_c = centres[g];
    FitOptions fold = options;
    std::vector<double> kept_temps;
    for (const Window& w : kept) kept_temps.push_back(w.temp_c);
    const int highest_order =
        static_cast<int>(DistinctTemperatures(kept_temps, options.distinct_temp_c).size()) - 1;
    fold.gyro_temp_order = std::max(0, std::min(options.gyro_temp_order, highest_order));
    fold.accel_temp_order = std::max(0, std::min(options.accel_temp_order, highest_order));
    group.gyro_temp_order = fold.gyro_temp_order;
    group.accel_temp_order = fold.accel_temp_order;
    group.order_lowered =
        fold.gyro_temp_order < options.gyro_temp_order || fold.accel_temp_order < options.accel_temp_order;
    const FitSummary fit = FitThermalModel(kept, site, segments, fold);
    if (!fit.IsSolutionUsable()) {
      group.why_not = fit.undetermined.empty() ? fit.termination : fit.undetermined.front();
    } else {
      group.fitted = true;
      group.errors = SummariseErrors(PredictWindows(fit.model, held, site, segments));
    }
    groups.push_back(group);
  }
  return groups;
}

}  // namespace imufit
