// imufit::io_logs — sessions in other tools' logs. The ROS bags here are written by rosbag's own
// writer (rosbag::Bag, librosbag-storage-dev), plain and compressed, and read back through
// ReadRosbagSamples / ReadLogSamples: good bags, a temperature topic, two IMU topics, bad ones.
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Temperature.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "imufit/io/error.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/rosbag_samples.h"
#include "imufit/io/sha256.h"
#include "test_util.h"

namespace imufit {
namespace {

constexpr uint32_t kStartSec = 1700000000;  // a stamp of 2023, as a recording's
constexpr double kRateHz = 200.0;

ros::Time StampAt(double t_s) {
  const int64_t ns = static_cast<int64_t>(std::llround(t_s * 1e9));
  return ros::Time(kStartSec + static_cast<uint32_t>(ns / 1000000000),
                   static_cast<uint32_t>(ns % 1000000000));
}

// The i-th IMU message of a test bag: distinct, exactly representable values.
sensor_msgs::Imu ImuMessage(int i) {
  sensor_msgs::Imu imu;
  imu.header.stamp = StampAt(i / kRateHz);
  imu.header.frame_id = "imu_link";
  imu.orientation_covariance[0] = -1.0;  // no orientation: fine, imufit does not read it
  imu.angular_velocity.x = 0.125 * i;
  imu.angular_velocity.y = -0.5;
  imu.angular_velocity.z = 1.0 / 1024.0 * i;
  imu.linear_acceleration.x = 0.25;
  imu.linear_acceleration.y = -9.5 + 0.0625 * i;
  imu.linear_acceleration.z = 9.80665;
  return imu;
}

sensor_msgs::Temperature TemperatureMessage(double t_s, double temp_c) {
  sensor_msgs::Temperature reading;
  reading.header.stamp = StampAt(t_s);
  reading.temperature = temp_c;
  return reading;
}

class RosbagTest : public testing::TempDirTest {
 protected:
  // A bag of `count` IMU messages on `topic`, each edited by `edit` first.
  template <typename Edit>
  std::string WriteImuBag(
      const std::string& name, int count, Edit edit, const std::string& topic = "/imu/data",
      rosbag::compression::CompressionType compression = rosbag::compression::Uncompressed) {
    const std::string path = Path(name);
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.setCompression(compression);
    for (int i = 0; i < count; ++i) {
      sensor_msgs::Imu imu = ImuMessage(i);
      const ros::Time received = imu.header.stamp;  // the bag's time: the order a recorder receives them
      edit(i, &imu);
      bag.write(topic, received, imu);
    }
    return path;
  }
  std::string WriteImuBag(const std::string& name, int count) {
    return WriteImuBag(name, count, [](int, sensor_msgs::Imu*) {});
  }

  // The message of the InputError reading `path` with `options` throws (fails the test if none).
  static std::string ErrorOf(const std::string& path, const RosbagOptions& options) {
    try {
      ReadRosbagSamples(path, options);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << path << " was read without an error";
    return "";
  }
};

const RosbagOptions kAt25C{"", "", 25.0};

::testing::AssertionResult HasText(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

TEST_F(RosbagTest, ReadsEveryImuMessageAsASampleInSiUnits) {
  for (const auto compression :
       {rosbag::compression::Uncompressed, rosbag::compression::BZ2, rosbag::compression::LZ4}) {
    const std::string path = WriteImuBag(
        "good" + std::to_string(static_cast<int>(compression)) + ".bag", 1000, [](int, sensor_msgs::Imu*) {},
        "/imu/data", compression);
    const RosbagSamples read = ReadRosbagSamples(path, kAt25C);
    EXPECT_EQ(read.topic, "/imu/data");
    EXPECT_EQ(read.temp_topic, "");
    ASSERT_EQ(read.samples.size(), 1000u);
    for (int i = 0; i < 1000; ++i) {
      const Sample& s = read.samples[i];
      const sensor_msgs::Imu imu = ImuMessage(i);
      // Time from the first stamp, in whole nanoseconds: 5 ms steps exactly.
      EXPECT_EQ(s.time_s, static_cast<double>(i * 5000000LL) * 1e-9) << i;
      EXPECT_EQ(s.gyro.x(), imu.angular_velocity.x);
      EXPECT_EQ(s.gyro.y(), imu.angular_velocity.y);
      EXPECT_EQ(s.gyro.z(), imu.angular_velocity.z);
      EXPECT_EQ(s.accel.x(), imu.linear_acceleration.x);
      EXPECT_EQ(s.accel.y(), imu.linear_acceleration.y);
      EXPECT_EQ(s.accel.z(), imu.linear_acceleration.z);
      EXPECT_EQ(s.temp_c, 25.0);
      EXPECT_EQ(s.segment, kTransitionSegment);
    }
  }
}

TEST_F(RosbagTest, InterpolatesATemperatureTopicAtTheImuStamps) {
  const std::string path = Path("warm.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    // Readings at 1 Hz from t = 1 s, warming by 0.5 degC per reading; IMU messages over 0 .. 5 s.
    for (int k = 1; k <= 4; ++k) {
      const sensor_msgs::Temperature reading = TemperatureMessage(k, 20.0 + 0.5 * k);
      bag.write("/imu/temperature", reading.header.stamp, reading);
    }
    for (int i = 0; i < 1000; ++i) {
      const sensor_msgs::Imu imu = ImuMessage(i);
      bag.write("/imu/data", imu.header.stamp, imu);
    }
  }
  const RosbagSamples read = ReadRosbagSamples(path, {});
  EXPECT_EQ(read.temp_topic, "/imu/temperature");
  EXPECT_EQ(read.temp_readings, 4);
  ASSERT_EQ(read.samples.size(), 1000u);
  constexpr double kInterpolationToleranceC = 1e-9;  // absolute, degC: rounding only
  for (const Sample& s : read.samples) {
    const double expected = s.time_s < 1.0 ? 20.5 : s.time_s > 4.0 ? 22.0 : 20.0 + 0.5 * s.time_s;
    EXPECT_NEAR(s.temp_c, expected, kInterpolationToleranceC) << s.time_s;
  }
  // --temp-c with a temperature topic replaces no reading silently.
  EXPECT_TRUE(HasText(ErrorOf(path, kAt25C), "a fixed temperature (--temp-c) is only for a bag"));
}

TEST_F(RosbagTest, RefusesAnImuStampTooFarFromEveryTemperatureReading) {
  const std::string path = Path("late_thermometer.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    const sensor_msgs::Temperature reading = TemperatureMessage(11.0, 30.0);
    bag.write("/temp", reading.header.stamp, reading);
    for (int i = 0; i < 10; ++i) {
      const sensor_msgs::Imu imu = ImuMessage(i);
      bag.write("/imu", imu.header.stamp, imu);
    }
  }
  EXPECT_EQ(ErrorOf(path, {}),
            path +
                ": topic \"/imu\", message 1: header.stamp 1700000000.000000000 s is 11 s from the nearest "
                "reading of \"/temp\" (at most 10 s): its temperature is unknown");
}

TEST_F(RosbagTest, TwoImuTopicsAreListedAndOneIsChosenByName) {
  const std::string path = Path("two.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int i = 0; i < 20; ++i) {
      sensor_msgs::Imu imu = ImuMessage(i);
      bag.write("/camera/imu", imu.header.stamp, imu);
      imu.angular_velocity.y = 2.0;
      bag.write("/px4/imu", imu.header.stamp, imu);
    }
  }
  EXPECT_EQ(ErrorOf(path, kAt25C),
            path + ": 2 sensor_msgs/Imu topics (\"/camera/imu\", \"/px4/imu\"): choose one with --topic");
  RosbagOptions options = kAt25C;
  options.topic = "/px4/imu";
  const RosbagSamples read = ReadRosbagSamples(path, options);
  ASSERT_EQ(read.samples.size(), 20u);
  for (const Sample& s : read.samples) EXPECT_EQ(s.gyro.y(), 2.0);
  options.topic = "/nope";
  EXPECT_EQ(
      ErrorOf(path, options),
      path +
          ": --topic \"/nope\": no such topic in the bag; its topics: \"/camera/imu\" (sensor_msgs/Imu), "
          "\"/px4/imu\" (sensor_msgs/Imu)");
}

TEST_F(RosbagTest, RefusesATopicOfAnotherType) {
  const std::string path = Path("temperature_only.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    const sensor_msgs::Temperature reading = TemperatureMessage(1.0, 30.0);
    bag.write("/imu", reading.header.stamp, reading);
  }
  EXPECT_EQ(ErrorOf(path, kAt25C),
            path + ": no sensor_msgs/Imu topic in the bag; its topics: \"/imu\" (sensor_msgs/Temperature)");
  EXPECT_EQ(ErrorOf(path, {"/imu", "", 25.0}),
            path + ": --topic \"/imu\": the topic holds sensor_msgs/Temperature, not sensor_msgs/Imu");
}

TEST_F(RosbagTest, RefusesABagWithoutTemperatureUnlessOneIsGiven) {
  const std::string path = WriteImuBag("cold.bag", 10);
  EXPECT_EQ(ErrorOf(path, {}), path +
                                   ": no sensor_msgs/Temperature topic in the bag; for a session without a "
                                   "thermometer give its temperature (--temp-c)");
}

TEST_F(RosbagTest, RefusesATimeThatDoesNotIncreaseAtItsMessage) {
  const std::string path = WriteImuBag("back.bag", 10, [](int i, sensor_msgs::Imu* imu) {
    imu->header.stamp = StampAt(i == 7 ? 0.02 : i / kRateHz);
  });
  EXPECT_EQ(ErrorOf(path, kAt25C),
            path +
                ": topic \"/imu/data\", message 8: header.stamp 1700000000.020000000 s is "
                "not after the previous message's 1700000000.030000000 s (the samples' "
                "time must increase)");
  const std::string unstamped =
      WriteImuBag("unstamped.bag", 3, [](int, sensor_msgs::Imu* imu) { imu->header.stamp = ros::Time(); });
  EXPECT_TRUE(HasText(ErrorOf(unstamped, kAt25C), "message 2: header.stamp 0.000000000 s is not after"));
}

TEST_F(RosbagTest, RefusesNonFiniteValuesNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::string path = WriteImuBag(
      "nan.bag", 10, [&](int i, sensor_msgs::Imu* imu) { imu->linear_acceleration.z = i == 4 ? nan : 9.8; });
  EXPECT_EQ(ErrorOf(path, kAt25C),
            path + ": topic \"/imu/data\", message 5: linear_acceleration.z: nan is not a finite number");
  const std::string inf = WriteImuBag("inf.bag", 10, [](int i, sensor_msgs::Imu* imu) {
    if (i == 9) imu->angular_velocity.y = -std::numeric_limits<double>::infinity();
  });
  EXPECT_TRUE(HasText(ErrorOf(inf, kAt25C), "message 10: angular_velocity.y: -inf is not a finite"));
  const std::string path2 = Path("nan_temp.bag");
  {
    rosbag::Bag bag(path2, rosbag::bagmode::Write);
    const sensor_msgs::Temperature reading = TemperatureMessage(0.0, nan);
    bag.write("/t", reading.header.stamp, reading);
    const sensor_msgs::Imu imu = ImuMessage(1);
    bag.write("/imu", imu.header.stamp, imu);
  }
  EXPECT_EQ(ErrorOf(path2, {}), path2 + ": topic \"/t\", message 1: temperature: nan is not a finite number");
}

TEST_F(RosbagTest, RefusesAKelvinTemperatureTopic) {
  const std::string path = Path("kelvin.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    const sensor_msgs::Temperature reading = TemperatureMessage(0.0, 300.0);
    bag.write("/t", reading.header.stamp, reading);
    const sensor_msgs::Imu imu = ImuMessage(1);
    bag.write("/imu", imu.header.stamp, imu);
  }
  EXPECT_TRUE(HasText(ErrorOf(path, {}), ": topic \"/t\", message 1: temperature: 300 degC is outside"));
}

TEST_F(RosbagTest, RefusesAChannelTheDriverSaysItDoesNotHave) {
  // REP 145: covariance element 0 = -1 is "no such data"; for the orientation that is fine (above).
  const std::string no_gyro = WriteImuBag(
      "no_gyro.bag", 5, [](int, sensor_msgs::Imu* imu) { imu->angular_velocity_covariance[0] = -1.0; });
  EXPECT_EQ(
      ErrorOf(no_gyro, kAt25C),
      no_gyro +
          ": topic \"/imu/data\", message 1: angular_velocity_covariance[0] is -1: the driver publishes "
          "no angular_velocity (sensor_msgs/Imu), so it cannot be calibrated");
  const std::string no_accel = WriteImuBag("no_accel.bag", 5, [](int i, sensor_msgs::Imu* imu) {
    if (i == 3) imu->linear_acceleration_covariance[0] = -1.0;
  });
  EXPECT_TRUE(HasText(ErrorOf(no_accel, kAt25C),
                      "message 4: linear_acceleration_covariance[0] is -1: the driver publishes no"));
}

TEST_F(RosbagTest, RefusesWhatIsNotAWholeBag) {
  const std::string good = WriteImuBag("whole.bag", 500);
  const std::string bytes = testing::ReadBytes(good);
  const auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(Path(name), std::ios::binary) << content;
    return Path(name);
  };
  // Cut short (a recording killed: no index), only the magic, the magic and garbage, empty.
  for (const std::string& path :
       {write("cut.bag", bytes.substr(0, bytes.size() / 2)), write("magic.bag", "#ROSBAG V2.0\n"),
        write("garbage.bag", "#ROSBAG V2.0\n" + std::string(300, '\x7f')), write("v9.bag", "#ROSBAG V9.9\n"),
        write("empty.bag", "")}) {
    const std::string error = ErrorOf(path, kAt25C);
    EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
  EXPECT_TRUE(HasText(ErrorOf(Path("cut.bag"), kAt25C), "rosbag reindex"));
  // A record's bytes changed in the middle of a chunk: refused or read, never a crash.
  std::string flipped = bytes;
  for (size_t i = 4096; i < flipped.size(); i += 4099) flipped[i] = static_cast<char>(flipped[i] ^ 0x5a);
  const std::string path = write("flipped.bag", flipped);
  try {
    for (const Sample& s : ReadRosbagSamples(path, kAt25C).samples) {
      EXPECT_TRUE(std::isfinite(s.time_s) && s.gyro.allFinite() && s.accel.allFinite() &&
                  std::isfinite(s.temp_c));
    }
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
}

// Each message's bytes are decoded in a buffer reused from message to message: a message cut short
// after a longer one is refused as rosbag refuses it, never completed with the longer one's bytes.
TEST_F(RosbagTest, RefusesAMessageShorterThanItsTypeAfterALongerOne) {
  const std::string path = Path("short.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    sensor_msgs::Imu imu = ImuMessage(0);
    imu.header.frame_id = std::string(300, 'f');
    bag.write("/imu/data", imu.header.stamp, imu);
    // Without a connection header rosbag files it under the topic's connection: a sensor_msgs/Imu
    // of 2 doubles after the header.
    const sensor_msgs::Temperature reading = TemperatureMessage(1.0, 25.0);
    bag.write("/imu/data", reading.header.stamp, reading);
  }
  EXPECT_EQ(ErrorOf(path, kAt25C), path + ": not a readable ROS bag (rosbag: Buffer Overrun)");
}

TEST_F(RosbagTest, RefusesAMessageOfAnotherTypeOnTheImuTopicAtItsMessage) {
  const std::string path = Path("mixed.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int i = 0; i < 3; ++i) {
      const sensor_msgs::Imu imu = ImuMessage(i);
      bag.write("/imu/data", imu.header.stamp, imu);
    }
    // A second connection of the topic (another publisher) with another type, as a recorder writes it.
    const sensor_msgs::Temperature reading = TemperatureMessage(1.0, 25.0);
    const auto header = boost::make_shared<ros::M_string>();
    (*header)["callerid"] = "/thermometer";
    (*header)["type"] = ros::message_traits::datatype(reading);
    (*header)["md5sum"] = ros::message_traits::md5sum(reading);
    (*header)["message_definition"] = ros::message_traits::definition(reading);
    bag.write("/imu/data", reading.header.stamp, reading, header);
  }
  EXPECT_EQ(ErrorOf(path, kAt25C),
            path + ": topic \"/imu/data\", message 4: a sensor_msgs/Temperature (definition md5 " +
                ros::message_traits::MD5Sum<sensor_msgs::Temperature>::value() +
                ") where sensor_msgs/Imu (md5 " + ros::message_traits::MD5Sum<sensor_msgs::Imu>::value() +
                ") was expected");
}

// fuzz/regressions/fuzz_rosbag/: a connection record's header length corrupted to 2.3 GB, which
// rosbag allocated before reading (a libFuzzer out-of-memory); the structure check refuses it first.
TEST_F(RosbagTest, RefusesALengthPastTheEndBeforeRosbagAllocatesIt) {
  const std::string path = std::string(IMUFIT_FUZZ_REGRESSIONS_DIR) + "/fuzz_rosbag/header-length-2gb.bag";
  const std::string error = ErrorOf(path, kAt25C);
  EXPECT_TRUE(HasText(error, ": not a readable ROS bag: at byte ")) << error;
  EXPECT_TRUE(HasText(error, "past the end of the file")) << error;
}

TEST_F(RosbagTest, LogSamplesTellABagFromACsvByItsFirstBytes) {
  const std::string bag = WriteImuBag("session.dat", 50);  // the name says nothing
  const std::string csv = Path("session.bag");             // nor here
  std::ofstream(csv)
      << "time_s,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n0,1,2,3,4,5,6\n0.01,1,2,3,4,5,6\n";
  EXPECT_EQ(LogFormatOf(bag), LogFormat::kRosbag);
  EXPECT_EQ(LogFormatOf(csv), LogFormat::kSamplesCsv);
  LogSamplesOptions options;
  options.csv.temp_c = 25.0;
  Sha256 digest;
  const LogSamples from_bag = ReadLogSamples(bag, options, &digest);
  EXPECT_EQ(from_bag.format, LogFormat::kRosbag);
  EXPECT_EQ(from_bag.samples.size(), 50u);
  EXPECT_EQ(from_bag.topic, "/imu/data");
  // The bag is hashed as it is on disk, as a CSV is.
  EXPECT_EQ(digest.HexDigest(), Sha256OfFile(bag));
  const LogSamples from_csv = ReadLogSamples(csv, options, nullptr);
  EXPECT_EQ(from_csv.format, LogFormat::kSamplesCsv);
  EXPECT_EQ(from_csv.samples.size(), 2u);
  // Options of the other format are refused, not ignored.
  options.csv.seconds_per_time_unit = 1e-3;
  try {
    ReadLogSamples(bag, options, nullptr);
    ADD_FAILURE() << "--time-unit was taken for a bag";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              bag +
                  ": is a ROS bag: --time-unit is for CSV samples (a bag's stamps are in "
                  "seconds and its fields named)");
  }
  options.csv.seconds_per_time_unit = 1.0;
  options.topic = "/imu";
  EXPECT_THROW(ReadLogSamples(csv, options, nullptr), InputError);
}

}  // namespace
}  // namespace imufit
