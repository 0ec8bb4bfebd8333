#include "imufit/run/channel_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <Eigen/Geometry>
#include <Eigen/QR>

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
// with one sign: their raw means, averaged (what the message quotes).
struct Group {
  double sum = 0.0;
  int count = 0;
  std::set<int> segments;
  double Mean() const { return sum / count; }
};

std::string Ids(const std::set<int>& ids) {
  std::string text;
  for (int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text;
}

// A window's planned truth for one sensor (rad/s or m/s^2, body frame) beside the window.
struct Planned {
  Eigen::Vector3d truth;
  const Window* window;
};

// The windows whose planned truth the sensor's channels can be judged against: every window of a
// plan segment for the gyro; for the accelerometer those whose specific force the plan knows.
std::vector<Planned> PlannedWindows(bool gyro, const std::vector<Window>& windows, const TableSite& site,
                                    const std::vector<TableSegment>& segments) {
  std::map<int, const TableSegment*> by_id;
  for (const TableSegment& segment : segments) by_id[segment.id] = &segment;
  std::vector<Planned> planned;
  for (const Window& w : windows) {
    const auto found = by_id.find(w.segment);
    if (found == by_id.end()) continue;
    const TableSegment& segment = *found->second;
    if (!gyro && (segment.IsTurn() || !segment.SpecificForceIsKnown())) continue;
    if (segment.IsTurn() && w.DurationS() <= 0.0) continue;
    const SegmentTruth truth =
        segment.IsTurn() ? TurnTruth(site, segment, w.DurationS()) : TruthOf(site, segment);
    planned.push_back({gyro ? truth.omega_radps : truth.a_mps2, &w});
  }
  return planned;
}

// The straight line raw = offset + slope * truth through the windows' means of one channel against
// their planned truth along one axis (a line, whatever the truth's sizes: faces at 1 g and corners at
// 0.58 g lie on it), and whether the slope stands out of its standard error by kResponseSigmas: the
// channel responds. The error counts the means' scatter about the line and their noise.
bool Responds(const std::vector<Planned>& planned, bool gyro, int channel_axis, int truth_axis) {
  double n = 0.0, st = 0.0, sm = 0.0, stt = 0.0, stm = 0.0, noise = 0.0;
  for (const Planned& p : planned) {
    const double t = p.truth(truth_axis);
    const double m = (gyro ? p.window->gyro_mean : p.window->accel_mean)(channel_axis);
    n += 1.0;
    st += t;
    sm += m;
    stt += t * t;
    stm += t * m;
    noise += std::pow(p.window->NoiseOfMean(gyro)(channel_axis), 2);
  }
  const double sxx = stt - st * st / n;
  if (n < 3.0 || sxx <= 0.0) return true;  // nothing to judge it by
  const double slope = (stm - st * sm / n) / sxx;
  const double offset = (sm - slope * st) / n;
  double rss = 0.0;
  for (const Planned& p : planned) {
    const double m = (gyro ? p.window->gyro_mean : p.window->accel_mean)(channel_axis);
    rss += std::pow(m - offset - slope * p.truth(truth_axis), 2);
  }
  const double variance = rss / (n - 2.0) + noise / n;
  return std::abs(slope) > kResponseSigmas * std::sqrt(variance / sxx);
}

// "" when the channel responds, or cannot be judged (the plan does not drive its axis both ways).
std::string Unresponsive(int channel, const std::vector<Window>& windows, const TableSite& site,
                         const std::vector<TableSegment>& segments) {
  const bool gyro = channel < 3;
  const int axis = channel % 3;
  const std::vector<Planned> planned = PlannedWindows(gyro, windows, site, segments);
  std::vector<std::pair<double, const Window*>> driven;
  double largest = 0.0;
  for (const Planned& p : planned) {
    driven.emplace_back(p.truth(axis), p.window);
    largest = std::max(largest, std::abs(p.truth(axis)));
  }
  Group plus;
  Group minus;
  for (const auto& [along, w] : driven) {
    if (std::abs(along) < kResponseShare * largest || largest == 0.0) continue;
    Group& group = along > 0.0 ? plus : minus;
    const double raw = (gyro ? w->gyro_mean : w->accel_mean)(axis);
    group.sum += raw;
    ++group.count;
    group.segments.insert(w->segment);
  }
  // The Earth rate alone (a static-only plan) drives no gyro measurably.
  if (plus.count == 0 || minus.count == 0 || (gyro && largest < kMinDrivingRateRadps)) return "";
  if (Responds(planned, gyro, axis, axis)) return "";
  const double response = std::abs(plus.Mean() - minus.Mean());
  std::set<int> ids = plus.segments;
  ids.insert(minus.segments.begin(), minus.segments.end());
  const std::string size = gyro ? NumberText("%.4g", largest * kRadToDeg) + " deg/s about "
                                : NumberText("%.3g", largest / kStandardGravityMps2) + " g along ";
  return std::string(ChannelName(channel)) + " does not respond: raw spread " + NumberText("%.3g", response) +
         " between the +-" + size + "xyz"[axis] + " (segments " + Ids(ids) + "), raw mean " +
         NumberText("%.6g", plus.Mean()) + ": dead or disconnected?";
}

// A raw channel follows one planned axis when that axis carries at least this share of its
// response's norm (the rest: misalignment, a few per cent at most).
constexpr double kAxisShare = 0.9;
constexpr int kMinMapWindows = 8;

// The signed axis map of one sensor: P(i, j) = +-1 when raw channel i follows the plan's axis j
// with that sign (raw = offset + K truth, each row of K fitted through every window with a known
// truth), the identity for a log that is as planned. nullopt when the run cannot tell (too few
// windows, truths that do not span the three axes), or when a channel follows no single axis,
// responds to nothing, or two channels follow one axis: the dead-channel check speaks then.
std::optional<Eigen::Matrix3d> SignedAxisMap(const std::vector<Planned>& planned, bool gyro) {
  const int n = static_cast<int>(planned.size());
  if (n < kMinMapWindows) return std::nullopt;
  Eigen::MatrixXd design(n, 4), means(n, 3);
  Eigen::Vector3d noise = Eigen::Vector3d::Zero();
  for (int w = 0; w < n; ++w) {
    design.row(w) << 1.0, planned[w].truth.transpose();
    means.row(w) = (gyro ? planned[w].window->gyro_mean : planned[w].window->accel_mean).transpose();
    noise += planned[w].window->NoiseOfMean(gyro).cwiseAbs2() / n;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design);
  if (qr.rank() < 4) return std::nullopt;
  const Eigen::MatrixXd coefficients = qr.solve(means);  // row 0: offsets; rows 1..3: K transposed
  const Eigen::MatrixXd residuals = means - design * coefficients;
  const Eigen::Matrix4d covariance = (design.transpose() * design).inverse();
  Eigen::Matrix3d map = Eigen::Matrix3d::Zero();
  std::array<bool, 3> followed{};
  for (int channel = 0; channel < 3; ++channel) {
    const Eigen::Vector3d response = coefficients.block<3, 1>(1, channel);
    int axis = 0;
    const double largest = response.cwiseAbs().maxCoeff(&axis);
    const double variance = residuals.col(channel).squaredNorm() / std::max(n - 4, 1) + noise(channel);
    if (largest < kAxisShare * response.norm() ||
        largest <= kResponseSigmas * std::sqrt(variance * covariance(axis + 1, axis + 1)) || followed[axis]) {
      return std::nullopt;
    }
    followed[axis] = true;
    map(channel, axis) = response(axis) > 0.0 ? 1.0 : -1.0;
  }
  return map;
}

std::string SignedAxis(const Eigen::Matrix3d& map, int channel) {
  for (int axis = 0; axis < 3; ++axis) {
    if (map(channel, axis) != 0.0) return std::string(map(channel, axis) > 0.0 ? "+" : "-") + "xyz"[axis];
  }
  return "?";
}

// What a signed axis map says in a person's terms: "gyro x and y look exchanged", "accel_y reads
// with its sign inverted", else which plan axis each misplaced channel follows.
std::string MapInWords(const char* sensor, const Eigen::Matrix3d& map) {
  const std::string name(sensor);
  std::vector<int> moved, inverted;
  for (int channel = 0; channel < 3; ++channel) {
    if (map(channel, channel) == 0.0) moved.push_back(channel);
    if (map(channel, channel) < 0.0) inverted.push_back(channel);
  }
  std::string words;
  if (moved.size() == 2 && map(moved[0], moved[1]) > 0.0 && map(moved[1], moved[0]) > 0.0) {
    words = name + " " + "xyz"[moved[0]] + " and " + "xyz"[moved[1]] + " look exchanged";
  } else if (!moved.empty()) {
    for (const int channel : moved) {
      words += (words.empty() ? "" : ", ") + name + "_" + "xyz"[channel] + " follows the plan's " +
               SignedAxis(map, channel) + " axis";
    }
  }
  for (const int channel : inverted) {
    words += (words.empty() ? "" : ", ") + name + "_" + "xyz"[channel] +
             " reads with its sign inverted against the plan (the logger's channel sign, or the plan's " +
             (name == "gyro" ? "rates and turns" : "up vectors") + " about " + "xyz"[channel] +
             " of the wrong sign: the right-hand rule)";
  }
  return words;
}

// The rotation that turns the plan's body axes into the unit's, in words ("90 deg about +z").
std::string RotationInWords(const Eigen::Matrix3d& map) {
  // raw = map * truth: the unit's axes are the plan's turned by R = map^T.
  const Eigen::AngleAxisd turn(Eigen::Matrix3d(map.transpose()));
  const Eigen::Vector3d& axis = turn.axis();
  std::string about;
  for (int k = 0; k < 3; ++k) {
    const double c = std::round(axis(k) * 1000.0) / 1000.0;
    if (c == 0.0) continue;
    about += (about.empty() ? "" : ", ") + NumberText("%+.3g", c) + "xyz"[k];
  }
  return NumberText("%.0f", turn.angle() * kRadToDeg) + " deg about (" + about + ")";
}

// The column map that reads the file's channels back into the plan's axes (--column), when every
// channel keeps its sign; "" when a sign is inverted (no column map undoes that).
std::string ColumnRemedy(const char* sensor, const Eigen::Matrix3d& map) {
  if ((map.array() < 0.0).any()) return "";
  std::string remedy;
  for (int axis = 0; axis < 3; ++axis) {
    for (int channel = 0; channel < 3; ++channel) {
      // Raw channel `channel` measures the plan's `axis`: that axis's column is `channel`'s.
      if (map(channel, axis) > 0.0 && channel != axis) {
        remedy += std::string(remedy.empty() ? "" : " ") + "--column " + sensor + "_" + "xyz"[axis] + "=" +
                  sensor + "_" + "xyz"[channel];
      }
    }
  }
  return remedy;
}

// "" when both sensors follow the plan's axes (or the run cannot tell); else what the channels do
// in a person's terms, and the remedy: a mounting rotation when both sensors are turned alike, a
// channel map (or sign) in the logger when one sensor is.
std::string AxisMapFinding(const std::vector<Window>& windows, const TableSite& site,
                           const std::vector<TableSegment>& segments) {
  const std::optional<Eigen::Matrix3d> gyro =
      SignedAxisMap(PlannedWindows(true, windows, site, segments), true);
  const std::optional<Eigen::Matrix3d> accel =
      SignedAxisMap(PlannedWindows(false, windows, site, segments), false);
  const bool gyro_off = gyro && !gyro->isIdentity(), accel_off = accel && !accel->isIdentity();
  if (!gyro_off && !accel_off) return "";
  if (gyro_off && accel_off && gyro->isApprox(*accel) && gyro->determinant() > 0.0) {
    return "both sensors read the plan's axes turned (" + MapInWords("gyro", *gyro) + "; " +
           MapInWords("accel", *accel) + "): the unit looks mounted rotated " + RotationInWords(*gyro) +
           " from the plan's axes; mount it as planned, or turn the plan's up, axis and north vectors into "
           "the unit's axes";
  }
  const auto in_words = [](const char* sensor, const Eigen::Matrix3d& map) {
    const std::string remedy = ColumnRemedy(sensor, map);
    return MapInWords(sensor, map) +
           (map.determinant() < 0.0 && remedy.empty() ? " (a left-handed frame?)" : "") +
           (remedy.empty() ? "; fix the logger's channel map and signs, or the plan's"
                           : "; the logger's channel map? read them back with " + remedy);
  };
  std::string finding;
  if (gyro_off) finding = in_words("gyro", *gyro);
  if (accel_off) finding += (finding.empty() ? "" : "; ") + in_words("accel", *accel);
  // One sensor as planned, the other not: the logger, not the mounting.
  if (gyro_off != accel_off && (gyro_off ? accel : gyro)) {
    finding += std::string(" (the ") + (gyro_off ? "accelerometer" : "gyro") +
               " follows the plan: not the mounting)";
  }
  return finding;
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
  // Channels that respond, but to another axis than their own, are not dead: say what they do.
  if (std::string mapped = AxisMapFinding(windows, site, segments); !mapped.empty()) return mapped;
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
