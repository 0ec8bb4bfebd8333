// io_test: the PX4 ULog reader (io/ulog_samples.h) on byte sequences built here from the format
// specification's message definitions (docs.px4.io, dev_log/ulog_file_format): nested formats,
// arrays, padding, appended data, dropouts, instances, interpolation, and the refusals, each at
// its byte offset. (python/tests/test_ulog.py reads logs written by an independent Python writer.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "imufit/io/error.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/sha256.h"
#include "imufit/io/ulog_samples.h"

namespace imufit {
namespace {

// Little-endian bytes, message by message, as the specification lays them out.
class UlogBytes {
 public:
  explicit UlogBytes(uint64_t start_us = 0) {
    Raw("ULog\x01\x12\x35", 7);
    bytes_.push_back(1);
    Put(start_us);
  }
  template <typename T>
  UlogBytes& Put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes_.append(raw, sizeof(T));
    return *this;
  }
  UlogBytes& Raw(const char* data, size_t size) {
    bytes_.append(data, size);
    return *this;
  }
  // A message of `type` with `payload`; returns its offset.
  size_t Message(char type, const std::string& payload) {
    const size_t offset = bytes_.size();
    Put(static_cast<uint16_t>(payload.size()));
    bytes_.push_back(type);
    bytes_ += payload;
    return offset;
  }
  size_t FlagBits(uint8_t incompat0 = 0, std::vector<uint64_t> appended = {}) {
    std::string payload(16, '\0');
    payload[8] = static_cast<char>(incompat0);
    appended.resize(3, 0);
    for (uint64_t offset : appended) payload.append(reinterpret_cast<const char*>(&offset), 8);
    return Message('B', payload);
  }
  size_t Format(const std::string& text) { return Message('F', text); }
  size_t Subscribe(uint8_t multi_id, uint16_t msg_id, const std::string& name) {
    std::string payload(1, static_cast<char>(multi_id));
    payload.append(reinterpret_cast<const char*>(&msg_id), 2);
    return Message('A', payload + name);
  }
  size_t Data(uint16_t msg_id, const std::string& data) {
    return Message('D', std::string(reinterpret_cast<const char*>(&msg_id), 2) + data);
  }
  size_t size() const { return bytes_.size(); }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

template <typename... T>
std::string Pack(T... values) {
  std::string out;
  ((out.append(reinterpret_cast<const char*>(&values), sizeof(T))), ...);
  return out;
}

// PX4's sensor_accel / sensor_gyro layout (44 bytes logged, 4 of trailing padding left out).
const char* const kSensorFields =
    "uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;float "
    "temperature;uint32_t error_count;uint8_t[3] clip_counter;uint8_t samples;uint8_t[4] _padding0;";

std::string Sensor(uint64_t t_us, uint32_t device, float x, float y, float z, float temp) {
  return Pack(t_us + 100, t_us, device, x, y, z, temp, uint32_t{0}, uint8_t{0}, uint8_t{0}, uint8_t{0},
              uint8_t{1});
}

// A log with sensor_gyro (msg_id 0) and sensor_accel (msg_id 1) of instance 0 subscribed.
UlogBytes SensorLog(uint8_t incompat0 = 0, std::vector<uint64_t> appended = {}) {
  UlogBytes log(1000);
  log.FlagBits(incompat0, std::move(appended));
  log.Format(std::string("sensor_accel:") + kSensorFields);
  log.Format(std::string("sensor_gyro:") + kSensorFields);
  log.Subscribe(0, 0, "sensor_gyro");
  log.Subscribe(0, 1, "sensor_accel");
  return log;
}

std::string Write(const std::string& bytes, const std::string& name) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("imufit_ulog_test_" + name + ".ulg")).string();
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The message of the InputError reading `bytes` throws ("" when none).
std::string Refusal(const std::string& bytes, const std::string& name, const UlogOptions& options = {}) {
  try {
    ReadUlogSamples(Write(bytes, name), options);
  } catch (const InputError& e) {
    return e.message();
  }
  return "";
}

// Accelerometer and gyro at one instance, the gyro at 200 Hz, the accelerometer at 100 Hz.
void AddRamp(UlogBytes* log, int gyro_messages, uint64_t t0_us = 10000) {
  for (int i = 0; i < gyro_messages; ++i) {
    const uint64_t t = t0_us + 5000u * i;
    log->Data(0, Sensor(t, 0x2100, 0.01f * i, -0.02f, 0.5f, 30.0f + 0.01f * i));
    if (i % 2 == 0) log->Data(1, Sensor(t, 0x1100, 0.1f * i, 9.5f, -1.0f, 29.0f));
  }
}

constexpr double kFloatTolerance = 1e-5;  // absolute, on values stored as float32

TEST(UlogTest, InterpolatesTheAccelerometerAtTheGyroTimes) {
  UlogBytes log = SensorLog();
  AddRamp(&log, 21);
  Sha256 digest;
  const std::string path = Write(log.bytes(), "ramp");
  const UlogSamples read = ReadUlogSamples(path, {}, &digest);
  EXPECT_EQ(digest.HexDigest(), Sha256OfFile(path));
  ASSERT_EQ(read.samples.size(), 21u);  // the gyro's last time is the accelerometer's last
  EXPECT_EQ(read.version, 1);
  EXPECT_DOUBLE_EQ(read.start_time_s, 1e-3);
  EXPECT_EQ(read.gyro_device_id, 0x2100u);
  EXPECT_EQ(read.accel_device_id, 0x1100u);
  EXPECT_EQ(read.gyro_messages, 21);
  EXPECT_EQ(read.accel_messages, 11);
  EXPECT_TRUE(read.gyro_temperature);
  for (int i = 0; i < 21; ++i) {
    const Sample& s = read.samples[i];
    EXPECT_DOUBLE_EQ(s.time_s, (10000 + 5000.0 * i) * 1e-6);
    EXPECT_NEAR(s.gyro.x(), 0.01 * i, kFloatTolerance);
    // The accelerometer's x ramps by 0.1 per gyro step: interpolation gives it at odd steps too.
    EXPECT_NEAR(s.accel.x(), 0.1 * i, kFloatTolerance) << i;
    EXPECT_NEAR(s.accel.y(), 9.5, kFloatTolerance);
    EXPECT_NEAR(s.temp_c, 30.0 + 0.01 * i, kFloatTolerance);  // the gyro's own
  }
}

TEST(UlogTest, TakesTheAccelerometerTemperatureWhenTheGyroHasNone) {
  UlogBytes log = SensorLog();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 5; ++i) {
    log.Data(0, Sensor(10000 + 5000u * i, 1, 0, 0, 0, nan));
    log.Data(1, Sensor(10000 + 5000u * i, 2, 0, 0, 9.8f, 20.0f + i));
  }
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "accel_temp"));
  ASSERT_EQ(read.samples.size(), 5u);
  EXPECT_FALSE(read.gyro_temperature);
  EXPECT_NEAR(read.samples[3].temp_c, 23.0, kFloatTolerance);
}

TEST(UlogTest, ReadsNestedFormatsArraysAndPaddingAnywhereInTheMessage) {
  UlogBytes log(0);
  log.FlagBits();
  // sensor_gyro with a nested array before its numbers (a type used before its definition), doubles
  // and a 16-bit timestamp-less inner type; the trailing padding is left out of the data.
  log.Format(
      "sensor_gyro:uint64_t timestamp;inner[2] pre;uint64_t timestamp_sample;double x;double y;double "
      "z;float "
      "temperature;uint32_t device_id;uint8_t[3] _padding0;");
  log.Format("inner:uint16_t a;uint8_t[3] b;");
  log.Format(std::string("sensor_accel:") + kSensorFields);
  log.Subscribe(0, 0, "sensor_gyro");
  log.Subscribe(0, 1, "sensor_accel");
  const std::string inner = Pack(uint16_t{7}, uint8_t{1}, uint8_t{2}, uint8_t{3});
  for (int i = 0; i < 3; ++i) {
    const uint64_t t = 1000 + 1000u * i;
    log.Data(0, Pack(t) + inner + inner + Pack(t, 0.25 * i, -1.5, 2.0 + i, 31.5f, uint32_t{0xABCD}));
    log.Data(1, Sensor(t, 9, 0, 0, 9.8f, 31.0f));
  }
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "nested"));
  ASSERT_EQ(read.samples.size(), 3u);
  EXPECT_EQ(read.samples[2].gyro, Eigen::Vector3d(0.5, -1.5, 4.0));
  EXPECT_EQ(read.samples[2].temp_c, 31.5);
  EXPECT_EQ(read.gyro_device_id, 0xABCDu);
  // A circular nesting is refused at its format.
  UlogBytes circular(0);
  circular.FlagBits();
  const size_t a = circular.Format("A_t:B_t[2] b;");
  circular.Format("B_t:A_t x;");
  circular.Format(std::string("sensor_gyro:") + kSensorFields);
  circular.Subscribe(0, 0, "sensor_gyro");
  const std::string refused = Refusal(circular.bytes(), "circular");
  EXPECT_NE(refused.find("'F' A_t: the format contains itself"), std::string::npos) << refused;
  EXPECT_NE(refused.find("byte " + std::to_string(a) + ":"), std::string::npos) << refused;
}

TEST(UlogTest, SkipsTheOtherMessagesAndUnknownTypes) {
  UlogBytes log = SensorLog();
  log.Message('I', std::string(1, 16) + "char[3] sys_name" + "PX4");
  log.Message('M', std::string(1, 0) + std::string(1, 12) + "char[2] note" + "ab");
  log.Message('P', std::string(1, 18) + "int32_t SDLOG_MODE" + Pack(int32_t{1}));
  log.Message('Q', std::string(1, 1) + std::string(1, 18) + "int32_t SDLOG_MODE" + Pack(int32_t{0}));
  log.Message('L', Pack(uint8_t{'6'}, uint64_t{5}) + "hello");
  log.Message('C', Pack(uint8_t{'6'}, uint16_t{2}, uint64_t{5}) + "tagged");
  log.Message('S', "\x2F\x73\x13\x20\x25\x0C\xBB\x12");
  log.Message('x', "unknown");
  AddRamp(&log, 5);
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "others"));
  EXPECT_EQ(read.samples.size(), 5u);
  EXPECT_EQ(read.unknown_messages, 1);
  EXPECT_EQ(read.sys_name, "PX4");
}

TEST(UlogTest, ReadsAppendedDataAfterAMessageCutShort) {
  // The main data stops in the middle of a message; appended data follows at the offset the flag
  // bits message gives (its position filled in once known).
  UlogBytes log = SensorLog(/*incompat0=*/1, {1});
  AddRamp(&log, 4);
  const std::string cut = log.bytes().substr(0, log.size()) + Sensor(0, 0, 0, 0, 0, 0).substr(0, 10);
  log.bytes() = cut;
  const uint64_t appended = log.size();
  AddRamp(&log, 4, 40000);
  std::memcpy(&log.bytes()[16 + 3 + 16], &appended, 8);
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "appended"));
  EXPECT_EQ(read.samples.size(), 7u);  // 0..15 ms, 40..55 ms (the accelerometer's last is at 50 ms)
  EXPECT_EQ(read.discarded_bytes, 10);
  EXPECT_DOUBLE_EQ(read.samples[4].time_s, 0.04);
  // An offset beyond the end is refused at the flag bits.
  UlogBytes beyond = SensorLog(1, {1u << 30});
  EXPECT_NE(Refusal(beyond.bytes(), "beyond").find("byte 16: 'B': appended_offsets[0]"), std::string::npos);
}

TEST(UlogTest, DiscardsAMessageCutShortAtTheEnd) {
  UlogBytes log = SensorLog();
  AddRamp(&log, 5);
  const std::string bytes = log.bytes() + std::string("\x30\x00\x44", 3) + "partial";
  const UlogSamples read = ReadUlogSamples(Write(bytes, "cut_end"));
  EXPECT_EQ(read.samples.size(), 5u);
  EXPECT_EQ(read.discarded_bytes, 10);
  EXPECT_EQ(UlogNotes("x.ulg", read).size(), 1u);
}

TEST(UlogTest, NotesDropoutsAndMakesNoSampleAcrossAnAccelerometerGap) {
  UlogBytes log = SensorLog();
  AddRamp(&log, 10);
  log.Message('O', Pack(uint16_t{300}));
  AddRamp(&log, 10, 400000);
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "dropout"));
  ASSERT_EQ(read.dropouts.size(), 1u);
  EXPECT_DOUBLE_EQ(read.dropouts[0].duration_s, 0.3);
  EXPECT_DOUBLE_EQ(read.dropouts[0].time_s, 0.055);
  // The gyro's 55 ms message lies between the accelerometer's 50 and 400 ms: no sample; nor do the
  // last one (after the accelerometer's last).
  EXPECT_EQ(read.gyro_without_sample, 2);
  EXPECT_EQ(read.samples.size(), 18u);
  EXPECT_EQ(UlogNotes("x.ulg", read).size(), 2u);
}

TEST(UlogTest, ChoosesAnInstanceOrNamesThem) {
  UlogBytes log(0);
  log.FlagBits();
  log.Format(std::string("sensor_accel:") + kSensorFields);
  log.Format(std::string("sensor_gyro:") + kSensorFields);
  for (uint8_t id = 0; id < 2; ++id) {
    log.Subscribe(id, 2 * id, "sensor_gyro");
    log.Subscribe(id, 2 * id + 1, "sensor_accel");
  }
  for (int i = 0; i < 4; ++i) {
    for (uint16_t id = 0; id < 2; ++id) {
      log.Data(2 * id, Sensor(1000 + 1000u * i, 0x200 + id, 0.1f * (id + 1), 0, 0, 25));
      log.Data(2 * id + 1, Sensor(1000 + 1000u * i, 0x100 + id, 0, 0, 9.8f, 25));
    }
  }
  const std::string several = Refusal(log.bytes(), "instances");
  EXPECT_NE(several.find("several IMU instances"), std::string::npos) << several;
  EXPECT_NE(several.find("1 (device id 0x201"), std::string::npos) << several;
  UlogOptions second;
  second.instance = 1;
  const UlogSamples read = ReadUlogSamples(Write(log.bytes(), "instances"), second);
  EXPECT_EQ(read.instance, 1);
  EXPECT_EQ(read.gyro_device_id, 0x201u);
  EXPECT_NEAR(read.samples[0].gyro.x(), 0.2, kFloatTolerance);
  second.instance = 2;
  EXPECT_NE(Refusal(log.bytes(), "instances", second).find("--instance 2: sensor_accel has the instances 0"),
            std::string::npos);
}

TEST(UlogTest, RefusesBadLogsAtTheirByteOffset) {
  const auto expect = [](const std::string& bytes, const std::string& name, const std::string& wanted) {
    const std::string message = Refusal(bytes, name);
    EXPECT_NE(message.find(wanted), std::string::npos) << name << ": " << message;
  };
  expect("ULog\x01\x12\x34" + std::string(9, '\0'), "magic", "byte 0: not a ULog file");
  expect(std::string("ULog\x01\x12\x35\x01", 8), "short_header", "the ULog header is cut short");
  {
    UlogBytes log = SensorLog();
    const size_t at = log.Data(0, Sensor(1, 0, 0, 0, 0, 0).substr(0, 30));
    expect(log.bytes(), "short_data",
           "byte " + std::to_string(at) +
               ": 'D' sensor_gyro[0]: 30 data bytes, its "
               "format has 48 (message cut short)");
  }
  {
    UlogBytes log = SensorLog();
    const size_t at = log.Message('A', Pack(uint8_t{0}, uint8_t{1}));
    expect(log.bytes(), "short_a", "byte " + std::to_string(at) + ": 'A': 2 bytes, at least 4 expected");
  }
  {
    UlogBytes log(0);
    log.FlagBits();
    const size_t at = log.Format("sensor_gyro:uint64_t timestamp;vector3 v;");
    log.Subscribe(0, 0, "sensor_gyro");
    expect(log.bytes(), "unknown_type",
           "byte " + std::to_string(at) + ": 'F' sensor_gyro: field v has the type \"vector3\"");
  }
  {
    UlogBytes log = SensorLog();
    const size_t at = log.Data(7, "12345678");
    expect(log.bytes(), "unknown_id",
           "byte " + std::to_string(at) + ": 'D': msg_id 7, which no subscription");
  }
  {
    UlogBytes log = SensorLog();
    log.Data(1, Sensor(5000, 0, 0, 0, 0, 20));
    const size_t at = log.Data(1, Sensor(5000, 0, 0, 0, 0, 20));
    expect(log.bytes(), "repeat",
           "byte " + std::to_string(at) +
               ": 'D' sensor_accel[0]: timestamp_sample 5000 us "
               "repeats");
  }
  {
    UlogBytes log = SensorLog();
    const size_t at = log.Data(0, Sensor(5000, 0, std::numeric_limits<float>::infinity(), 0, 0, 20));
    expect(log.bytes(), "inf", "byte " + std::to_string(at) + ": 'D' sensor_gyro[0]: x is inf");
  }
  {
    UlogBytes log = SensorLog();
    const size_t at = log.Data(0, Sensor(5000, 0, 0, 0, 0, 400));
    expect(log.bytes(), "hot", "byte " + std::to_string(at) + ": 'D' sensor_gyro[0]: temperature: ");
  }
  {
    UlogBytes log(0);
    log.FlagBits();
    log.Format(std::string("sensor_gyro:") + kSensorFields);
    log.Subscribe(0, 0, "sensor_gyro");
    expect(log.bytes(), "no_accel", "no sensor_accel topic (the log has: sensor_gyro)");
  }
  {
    UlogBytes log(0);
    log.FlagBits(0x04);
    expect(log.bytes(), "incompat", "byte 16: 'B': incompat_flags[0] has the unknown bits 0x04");
  }
  {
    UlogBytes log(0);
    log.Format("x:uint64_t timestamp;");
    const size_t at = log.FlagBits();
    expect(log.bytes(), "late_b",
           "byte " + std::to_string(at) + ": 'B': the flag bits message must be the first");
  }
}

TEST(UlogTest, LogSamplesTellsAUlogFromACsvByItsBytes) {
  UlogBytes log = SensorLog();
  AddRamp(&log, 5);
  const std::string path = Write(log.bytes(), "dispatch");
  const std::string csv = std::filesystem::path(path).replace_extension(".csv").string();
  std::filesystem::copy_file(path, csv, std::filesystem::copy_options::overwrite_existing);
  Sha256 digest;
  const LogSamples read = ReadLogSamples(csv, {}, &digest);  // named .csv, read as what it is
  EXPECT_EQ(read.format, LogFormat::kUlog);
  EXPECT_EQ(read.samples.size(), 5u);
  EXPECT_EQ(digest.HexDigest(), Sha256OfFile(csv));
  LogSamplesOptions csv_only;
  csv_only.csv.seconds_per_time_unit = 1e-3;
  try {
    ReadLogSamples(path, csv_only, nullptr);
    ADD_FAILURE() << "--time-unit with a ULog";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--time-unit reads a CSV"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace imufit
