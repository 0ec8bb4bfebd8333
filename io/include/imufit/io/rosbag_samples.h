// imufit — a session recorded as a ROS 1 bag (format 2.0): the sensor_msgs/Imu messages of one
// topic read as samples (docs/field.md, "Sessions in a ROS bag"; docs/spec.md section 2).
//
// Read with Debian's librosbag-storage-dev (rosbag::Bag, rosbag::View) and libsensor-msgs-dev.
// The library stays behind this header: only imufit::io_logs links it.
//
// Per message: time_s from header.stamp (seconds from the first message's stamp, computed in whole
// nanoseconds), gyro = angular_velocity (rad/s), accel = linear_acceleration (m/s^2). SI inputs are
// taken as such: the calibration's raw units are then rad/s and m/s^2. The temperature comes from a
// sensor_msgs/Temperature topic (degC), linearly interpolated at each IMU stamp between the two
// readings around it and held at the nearest reading before the first and after the last (at most
// kMaxTemperatureGapS away); without such a topic from a fixed temperature (--temp-c).
//
// Everything the library throws and everything implausible (a time that does not increase, a
// non-finite value, covariance element 0 = -1 meaning "no such data" on angular_velocity or
// linear_acceleration, an empty topic, another message type) is an InputError naming the file,
// the topic, the message (1-based, in the bag's order) and the field.
#ifndef IMUFIT_IO_ROSBAG_SAMPLES_H_
#define IMUFIT_IO_ROSBAG_SAMPLES_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "imufit/model/sample.h"

namespace imufit {

// The first bytes of a ROS 1 bag ("#ROSBAG V2.0\n" for the format rosbag writes since ROS C Turtle).
inline constexpr std::string_view kRosbagMagic = "#ROSBAG V";
inline constexpr const char* kRosImuType = "sensor_msgs/Imu";
inline constexpr const char* kRosTemperatureType = "sensor_msgs/Temperature";
// An IMU stamp farther than this from every temperature reading is refused: the temperature would
// be a guess (a thermometer topic that stopped, or started late).
inline constexpr double kMaxTemperatureGapS = 10.0;

// How a bag is read: what the command's options say about it.
struct RosbagOptions {
  // The sensor_msgs/Imu topic (--topic); "" = the bag's only one (several are refused, listed).
  std::string topic;
  // The sensor_msgs/Temperature topic (--temp-topic); "" = the bag's only one, if it has exactly
  // one (several are refused, listed), else none.
  std::string temp_topic;
  // The temperature of every sample when no temperature topic is read (--temp-c); given with a
  // temperature topic it is refused, so that no reading is silently replaced.
  std::optional<double> temp_c;
};

struct RosbagSamples {
  std::vector<Sample> samples;
  std::string topic;       // the IMU topic read
  std::string temp_topic;  // the temperature topic read, "" when every sample is at temp_c
  int temp_readings = 0;   // the temperature messages read
};

// Whether `head` (a file's first bytes) starts like a ROS bag.
bool LooksLikeRosbag(std::string_view head);

// Reads the IMU topic of the bag at `path`. Throws InputError (see the top of this file).
RosbagSamples ReadRosbagSamples(const std::string& path, const RosbagOptions& options);

}  // namespace imufit

#endif  // IMUFIT_IO_ROSBAG_SAMPLES_H_
