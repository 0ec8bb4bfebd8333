// The field fit's step 1 (field_fit.h): the poses of a session by hand, the turns between them and
// the log's noise floor. No Ceres.
#include <algorithm>
#include <cmath>
#include <limits>

#include "imufit/fit/field_fit.h"
#include "imufit/model/check.h"
#include "imufit/run/channel_check.h"

namespace imufit {
namespace {

// The index of the first sample at or after `time_s` (samples in time order).
long long FirstAtOrAfter(const std::vector<Sample>& samples, double time_s) {
  const auto it = std::lower_bound(samples.begin(), samples.end(), time_s,
                                   [](const Sample& s, double t) { return s.time_s < t; });
  return static_cast<long long>(it - samples.begin());
}

// A pose over samples [first, last]: its means.
FieldPose PoseOver(const std::vector<Sample>& samples, long long first, long long last) {
  FieldPose pose;
  pose.first = first;
  pose.last = last;
  pose.start_s = samples[first].time_s;
  pose.end_s = samples[last].time_s;
  for (long long i = first; i <= last; ++i) {
    pose.gyro_mean += samples[i].gyro;
    pose.accel_mean += samples[i].accel;
    pose.temp_c += samples[i].temp_c;
  }
  const double n = static_cast<double>(last - first + 1);
  pose.gyro_mean /= n;
  pose.accel_mean /= n;
  pose.temp_c /= n;
  return pose;
}

// Each gyro axis's rails: its largest and smallest reading over the log when that reading is a
// converter's limit (run/channel_check.h) reached more than once (a clipped converter); NaN, which
// no reading equals, when not.
struct GyroRails {
  Eigen::Vector3d high = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};
GyroRails GyroRailsOf(const std::vector<Sample>& samples) {
  GyroRails rails;
  for (int axis = 0; axis < 3; ++axis) {
    double high = -std::numeric_limits<double>::infinity();
    double low = std::numeric_limits<double>::infinity();
    int at_high = 0;
    int at_low = 0;
    for (const Sample& s : samples) {
      const double v = s.gyro(axis);
      if (v > high) high = v, at_high = 0;
      if (v == high) ++at_high;
      if (v < low) low = v, at_low = 0;
      if (v == low) ++at_low;
    }
    if (ConverterLimit(high) && at_high > 1) rails.high(axis) = high;
    if (ConverterLimit(low) && at_low > 1) rails.low(axis) = low;
  }
  return rails;
}

}  // namespace

void FindFieldPoses(const std::vector<Sample>& samples, const FieldFitOptions& options,
                    std::vector<FieldPose>* poses, std::vector<FieldTurn>* turns,
                    Eigen::Vector3d* gyro_noise_raw, Eigen::Vector3d* accel_noise_raw) {
  poses->clear();
  turns->clear();
  *gyro_noise_raw = Eigen::Vector3d::Zero();
  *accel_noise_raw = Eigen::Vector3d::Zero();
  if (samples.size() < 2) return;
  SegmentationOptions detection = options.detection;
  detection.rests_held_by_hand = true;  // the threshold between the rests' tremor and the turns
  MotionDetector detector(detection);
  for (const Sample& sample : samples) detector.Add(sample);
  const DetectedRun run = detector.Finish();
  for (const MotionPiece& piece : run.pieces) {
    if (piece.kind != PieceKind::kSteady || piece.end_s - piece.start_s < options.min_pose_s) continue;
    const long long first = FirstAtOrAfter(samples, piece.start_s);
    const long long last = FirstAtOrAfter(samples, piece.end_s);
    if (last <= first || last >= static_cast<long long>(samples.size())) continue;
    poses->push_back(PoseOver(samples, first, last));
  }
  // The noise of one sample, per axis, pooled over the poses (each about its own mean).
  Eigen::Vector3d gyro_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero();
  long long degrees_of_freedom = 0;
  for (const FieldPose& pose : *poses) {
    for (long long i = pose.first; i <= pose.last; ++i) {
      gyro_sum += (samples[i].gyro - pose.gyro_mean).cwiseAbs2();
      accel_sum += (samples[i].accel - pose.accel_mean).cwiseAbs2();
    }
    degrees_of_freedom += pose.last - pose.first;
  }
  if (degrees_of_freedom > 0) {
    *gyro_noise_raw = (gyro_sum / static_cast<double>(degrees_of_freedom)).cwiseSqrt();
    *accel_noise_raw = (accel_sum / static_cast<double>(degrees_of_freedom)).cwiseSqrt();
  }
  // A noiseless log (a simulation without noise, a stuck converter) still weighs its residuals:
  // its floor is a relative rounding of its largest reading.
  double gyro_largest = 0.0;
  double accel_largest = 0.0;
  for (const Sample& s : samples) {
    gyro_largest = std::max(gyro_largest, s.gyro.cwiseAbs().maxCoeff());
    accel_largest = std::max(accel_largest, s.accel.cwiseAbs().maxCoeff());
  }
  constexpr double kNoiseFloorRelative = 1e-9;
  *gyro_noise_raw = gyro_noise_raw->cwiseMax(kNoiseFloorRelative * std::max(gyro_largest, 1e-300));
  *accel_noise_raw = accel_noise_raw->cwiseMax(kNoiseFloorRelative * std::max(accel_largest, 1e-300));
  const GyroRails rails = GyroRailsOf(samples);
  for (size_t p = 1; p < poses->size(); ++p) {
    FieldTurn turn;
    turn.from = static_cast<int>(p - 1);
    turn.to = static_cast<int>(p);
    turn.first = (*poses)[p - 1].last;
    turn.last = (*poses)[p].first;
    IMUFIT_CHECK(turn.last > turn.first, "successive poses overlap");
    for (long long i = turn.first; i <= turn.last && !turn.saturated; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        turn.saturated = turn.saturated || samples[i].gyro(axis) == rails.high(axis) ||
                         samples[i].gyro(axis) == rails.low(axis);
      }
    }
    turns->push_back(turn);
  }
}

}  // namespace imufit
