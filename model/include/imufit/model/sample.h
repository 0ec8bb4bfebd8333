// imufit — one sample of a run, as every part of imufit passes it around.
//
// Raw samples hold the unit's own numbers (gyro B, accel A); corrected samples hold SI values
// (gyro rad/s, accel m/s^2), body frame. `segment` is the plan segment the table was in, or
// kTransitionSegment while the table moved between segments.
#ifndef IMUFIT_MODEL_SAMPLE_H_
#define IMUFIT_MODEL_SAMPLE_H_

#include <Eigen/Core>

namespace imufit {

// The segment id of a sample taken while the table moves between segments.
inline constexpr int kTransitionSegment = -1;

struct Sample {
  double time_s = 0.0;
  double temp_c = 0.0;
  int segment = kTransitionSegment;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

}  // namespace imufit

#endif  // IMUFIT_MODEL_SAMPLE_H_
