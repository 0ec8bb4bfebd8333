// imufit — a session's samples from whichever log the user has: imufit's samples CSV (samples.h)
// or a ROS 1 bag (rosbag_samples.h), told apart by the file's first bytes, not its name.
//
// The whole log is read into memory (the field fit needs every sample at once) and its bytes are
// hashed as they are on disk, as for a CSV, for the calibration's samples_sha256.
#ifndef IMUFIT_IO_LOG_SAMPLES_H_
#define IMUFIT_IO_LOG_SAMPLES_H_

#include <string>
#include <vector>

#include "imufit/io/csv_reader.h"
#include "imufit/io/rosbag_samples.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/model/sample.h"

namespace imufit {

// The formats a log may be in.
enum class LogFormat { kSamplesCsv, kRosbag };

// How a log is read: the CSV's format (its temp_c also serves a bag without a temperature topic)
// and the bag's topics.
struct LogSamplesOptions {
  SamplesFormat csv;
  std::string topic;       // --topic (a bag's sensor_msgs/Imu topic)
  std::string temp_topic;  // --temp-topic (a bag's sensor_msgs/Temperature topic)
};

struct LogSamples {
  LogFormat format = LogFormat::kSamplesCsv;
  std::vector<Sample> samples;
  // A CSV's header: its comment lines and the serial it states (empty for a bag).
  std::vector<CsvReader::Comment> header_comments;
  SamplesSerial serial;
  // A bag's topics read (RosbagSamples).
  std::string topic;
  std::string temp_topic;
};

// The format of the file at `path` by its first bytes. Throws InputError when it cannot be read.
LogFormat LogFormatOf(const std::string& path);

// Reads every sample of the log at `path` (no segment column required); `digest`, when not null,
// hashes the file's bytes. Throws InputError (located as its reader locates it); a bag given
// options that only a CSV has (--time-unit, --column, --delimiter, --decimal-comma) is refused, and
// so is a CSV given --topic or --temp-topic.
LogSamples ReadLogSamples(const std::string& path, const LogSamplesOptions& options, Sha256* digest);

}  // namespace imufit

#endif  // IMUFIT_IO_LOG_SAMPLES_H_
