// imufit — a session's samples from whichever log the user has: imufit's samples CSV (samples.h),
// a ROS 1 bag (rosbag_samples.h) or a PX4 ULog (ulog_samples.h), told apart by the file's first
// bytes, not its name.
//
// The whole log is read into memory (the field fit needs every sample at once) and its bytes are
// hashed as they are on disk, as for a CSV, for the calibration's samples_sha256.
#ifndef IMUFIT_IO_LOG_SAMPLES_H_
#define IMUFIT_IO_LOG_SAMPLES_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/io/csv_reader.h"
#include "imufit/io/rosbag_samples.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/model/sample.h"

namespace imufit {

// The formats a log may be in.
enum class LogFormat { kSamplesCsv, kRosbag, kUlog };

// How a log is read: the CSV's format (its temp_c also serves a bag without a temperature topic
// and a ULog without temperatures; its CSV-only parts are refused for the others), the bag's
// topics and the ULog's sensor instance.
struct LogSamplesOptions {
  SamplesFormat csv;
  std::string topic;                 // --topic (a bag's sensor_msgs/Imu topic)
  std::string temp_topic;            // --temp-topic (a bag's sensor_msgs/Temperature topic)
  std::optional<int> ulog_instance;  // --instance (a ULog's sensor_accel/sensor_gyro multi_id)
};

struct LogSamples {
  LogFormat format = LogFormat::kSamplesCsv;
  std::vector<Sample> samples;  // in time order
  // A CSV's header: its comment lines and the serial it states (empty for a bag or a ULog).
  std::vector<CsvReader::Comment> header_comments;
  SamplesSerial serial;
  // A bag's topics read (RosbagSamples).
  std::string topic;
  std::string temp_topic;
  // What a user should know about the reading (a ULog's dropouts, ...), one line each.
  std::vector<std::string> notes;
};

// The format of the file at `path` by its first bytes. Throws InputError when it cannot be read.
LogFormat LogFormatOf(const std::string& path);

// Reads every sample of the log at `path` (a CSV's segment column is read when present); `digest`,
// when not null, hashes the file's bytes. Throws InputError (located as its reader locates it); a
// bag or a ULog given options that only a CSV has (--time-unit, --column, --delimiter,
// --decimal-comma) is refused, and so is a log given another format's options (--topic,
// --temp-topic for a bag; --instance for a ULog).
LogSamples ReadLogSamples(const std::string& path, const LogSamplesOptions& options, Sha256* digest);

}  // namespace imufit

#endif  // IMUFIT_IO_LOG_SAMPLES_H_
