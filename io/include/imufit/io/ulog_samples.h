// imufit — a session's samples from a PX4 ULog file (docs/field.md, "Sessions in a PX4 ULog").
//
// The reader follows PX4's "ULog File Format" specification (docs.px4.io, dev_log/ulog_file_format):
// the 16-byte header (magic "ULog" 01 12 35, version, start time in us), then messages of
// {uint16 msg_size, uint8 msg_type, msg_size bytes}, little endian:
//   'B' flag bits (first message; unknown incompat bits refuse the file; appended data offsets),
//   'F' formats "name:type field;..." (basic types, fixed arrays, nested formats, `_padding` fields),
//   'I'/'M' information, 'P'/'Q' parameters (checked for size, otherwise skipped),
//   'A' subscriptions (msg_id -> format name and multi_id), 'R' unsubscriptions, 'D' logged data,
//   'L'/'C' logged strings, 'S' sync, 'O' dropouts (noted); any other type is skipped, as the spec
//   says a parser must. A message cut short at the end of the file (a log whose power was cut) is
//   discarded, as the spec requires, and counted; so is one cut short at an appended data offset,
//   where reading continues.
//
// It reads the raw IMU topics `sensor_accel` (m/s^2) and `sensor_gyro` (rad/s) of one instance
// (multi_id): their `timestamp_sample` (us; `timestamp` where a format has none), `x`, `y`, `z`,
// `temperature` (degC) and `device_id`. The values are SI and taken as such: the calibration's raw
// units are then m/s^2 and rad/s.
//
// Accelerometer and gyro come at their own times and rates. The samples are made at the gyro's
// sample times, the accelerometer (and its temperature) interpolated linearly in time between its
// two messages around each: the field fit integrates the turns from the gyro at its own rate, so
// the gyro is kept as measured, and the rests use means, which linear interpolation leaves as they
// are. A gyro time outside the accelerometer's span, or between two accelerometer messages further
// apart than kMaxAccelGapIntervals of its median interval (a dropout), gives no sample. The
// temperature is the gyro's own where its messages carry one, else the accelerometer's.
//
// Errors are InputErrors whose message starts with the byte offset of the message at fault and
// names its type, topic and field: `log.ulg: byte 1234: 'D' sensor_gyro[0]: x is nan`.
#ifndef IMUFIT_IO_ULOG_SAMPLES_H_
#define IMUFIT_IO_ULOG_SAMPLES_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "imufit/model/sample.h"

namespace imufit {

class Sha256;

// The 7 bytes a ULog file starts with.
inline constexpr unsigned char kUlogMagic[7] = {'U', 'L', 'o', 'g', 0x01, 0x12, 0x35};
// A file starting with "ULog" is read as a ULog (so that one with the rest of the magic wrong is
// refused as such, not read as a CSV).
inline constexpr size_t kUlogNameBytes = 4;
// A gyro sample between two accelerometer messages further apart than this many median
// accelerometer intervals is not made (the accelerometer is not interpolated across a dropout).
inline constexpr double kMaxAccelGapIntervals = 4.0;

struct UlogOptions {
  // The instance (multi_id) of sensor_accel and sensor_gyro to read; none: the only one there is
  // (several are refused, naming each with its device ids).
  std::optional<int> instance;
  // The temperature of every sample, degC, for a log whose sensors carry none (both report NaN or
  // have no temperature field); a log with temperatures is then refused (--temp-c).
  std::optional<double> temp_c;
};

// A logging dropout ('O'): messages lost for `duration_s`, after the data logged at `time_s`.
struct UlogDropout {
  long long offset = 0;  // byte offset of the 'O' message
  double time_s = 0.0;   // the last sensor time read before it (0 before any)
  double duration_s = 0.0;
};

struct UlogSamples {
  std::vector<Sample> samples;  // at the gyro's times, increasing; segment kTransitionSegment
  int version = 0;              // the header's format version
  double start_time_s = 0.0;    // the header's timestamp: logging start, s since boot
  int instance = 0;             // the multi_id read
  uint32_t accel_device_id = 0;
  uint32_t gyro_device_id = 0;
  long long accel_messages = 0;
  long long gyro_messages = 0;
  bool gyro_temperature = false;      // the temperature is the gyro's (else the accelerometer's)
  long long gyro_without_sample = 0;  // gyro messages outside the accelerometer's span or in its gaps
  std::vector<UlogDropout> dropouts;
  long long discarded_bytes = 0;   // of messages cut short at the end or at an appended offset
  long long unknown_messages = 0;  // messages of a type the spec does not define, skipped
  std::string sys_name;            // the 'I' sys_name and ver_hw, when the log states them
  std::string ver_hw;
};

// True when the file starts with "ULog" (kUlogNameBytes of kUlogMagic). Throws
// InputError when the file cannot be read.
bool IsUlogFile(const std::string& path);

// Reads `path` (the whole file goes through `digest` when not null). Throws InputError.
UlogSamples ReadUlogSamples(const std::string& path, const UlogOptions& options = {},
                            Sha256* digest = nullptr);

// The notes a user should see about a log read (dropouts, discarded bytes, skipped gyro samples),
// one line each, without the "imufit:" prefix.
std::vector<std::string> UlogNotes(const std::string& path, const UlogSamples& log);

}  // namespace imufit

#endif  // IMUFIT_IO_ULOG_SAMPLES_H_
