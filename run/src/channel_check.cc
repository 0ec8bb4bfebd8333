#include "imufit/run/channel_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "imufit/base/text.h"
#include "imufit/model/constants.h"

namespace imufit {
namespace {

// A gyro axis is judged only when the plan turns the table about it at least this fast, rad/s.
constexpr double kMinDrivingRateRadps = 0.1;

const char* ChannelName(int channel) {
  static const char* const kNames[6] = {"gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"};
  return kNames[channel];
}

std::string Stuck(int channel, double value, const WindowOptions& options) {
  const double full_scale = channel < 3 ? options.gyro_full_scale_raw : options.accel_full_scale_raw;
  const std::string reads =
      std::string(ChannelName(channel)) + " reads " + NumberText("%.10g", value) + " in every sample";
  if ((full_scale > 0.0 && std::abs(value) >= full_scale) || ConverterLimit(value)) {
    return reads + ": at its rail (saturated, or a fault holds it there)?";
  }
  return reads + ": dead or disconnected?";
}

// The group of windows whose planned truth along the channel's axis is at least half the largest,
// with one sign: their raw means, averaged, and their scatter.
struct Group {
  double sum = 0.0;
  double sum_squares = 0.0;
  double noise_squares = 0.0;
  int count = 0;
  std::set<int> segments;
  double Mean() const { return sum / count; }
  double Scatter() const {
    const double variance = count > 1 ? std::max(sum_squares / count - Mean() * Mean(), 0.0) : 0.0;
    return std::sqrt(variance + noise_squares / count);
  }
};

std::string Ids(const std::set<int>& ids) {
  std::string text;
  for (int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text;
}

// "" when the channel responds, or cannot be judged (the plan does not drive its axis both ways).
std::string Unresponsive(int channel, const std::vector<Window>& windows, const TableSite& site,
                         const std::vector<TableSegment>& segments) {
  const bool gyro = channel < 3;
  const int axis = channel % 3;
  std::map<int, const TableSegment*> by_id;
  for (const TableSegment& segment : segments) by_id[segment.id] = &segment;
  std::vector<std::pair<double, const Window*>> driven;
  double largest = 0.0;
  for (const Window& w : windows) {
    const auto found = by_id.find(w.segment);
    if (found == by_id.end()) continue;
    const TableSegment& segment = *found->second;
    if (!gyro && (segment.IsTurn() || !segment.SpecificForceIsKnown())) continue;
    if (segment.IsTurn() && w.DurationS() <= 0.0) continue;
    const SegmentTruth truth =
        segment.IsTurn() ? TurnTruth(site, segment, w.DurationS()) : TruthOf(site, segment);
    const double along = (gyro ? truth.omega_radps : truth.a_mps2)(axis);
    driven.emplace_back(along, &w);
    largest = std::max(largest, std::abs(along));
  }
  Group plus;
  Group minus;
  for (const auto& [along, w] : driven) {
    if (std::abs(along) < kResponseShare * largest || largest == 0.0) continue;
    Group& group = along > 0.0 ? plus : minus;
    const double raw = (gyro ? w->gyro_mean : w->accel_mean)(axis);
    group.sum += raw;
    group.sum_squares += raw * raw;
    group.noise_squares += std::pow(w->NoiseOfMean(gyro)(axis), 2);
    ++group.count;
    group.segments.insert(w->segment);
  }
  // The Earth rate alone (a static-only plan) drives no gyro measurably.
  if (plus.count == 0 || minus.count == 0 || (gyro && largest < kMinDrivingRateRadps)) return "";
  const double response = std::abs(plus.Mean() - minus.Mean());
  if (response > kResponseSigmas * (plus.Scatter() + minus.Scatter())) return "";
  std::set<int> ids = plus.segments;
  ids.insert(minus.segments.begin(), minus.segments.end());
  const std::string size = gyro ? NumberText("%.4g", largest * kRadToDeg) + " deg/s about "
                                : NumberText("%.3g", largest / kStandardGravityMps2) + " g along ";
  return std::string(ChannelName(channel)) + " does not respond: raw spread " + NumberText("%.3g", response) +
         " between the +-" + size + "xyz"[axis] + " (segments " + Ids(ids) + "), raw mean " +
         NumberText("%.6g", plus.Mean()) + ": dead or disconnected?";
}

}  // namespace

bool ConverterLimit(double value) {
  for (int k = 7; k <= 31; ++k) {
    const double limit = std::ldexp(1.0, k);
    if (value == limit - 1.0 || value == -(limit - 1.0) || value == -limit) return true;
  }
  return false;
}

std::string CheckChannels(const std::vector<Window>& windows, const WindowStats& stats, const TableSite& site,
                          const std::vector<TableSegment>& segments, const WindowOptions& options) {
  std::string text;
  for (int channel = 0; channel < 6; ++channel) {
    std::string finding;
    if (stats.samples > 1 && stats.raw_min(channel) == stats.raw_max(channel)) {
      finding = Stuck(channel, stats.raw_min(channel), options);
      // A constant channel the plan drives both ways says so.
      if (finding.find("rail") == std::string::npos) {
        if (std::string why = Unresponsive(channel, windows, site, segments); !why.empty()) finding = why;
      }
    } else {
      finding = Unresponsive(channel, windows, site, segments);
    }
    if (!finding.empty()) text += (text.empty() ? "" : "; ") + finding;
  }
  return text;
}

}  // namespace imufit
