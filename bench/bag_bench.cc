// imufit — benchmark of reading a session from a ROS 1 bag against reading the same samples as CSV
// (issue 32: "reading a 1 GB bag runs at least as fast as reading the same samples as CSV").
//
// The same samples (a hand-held unit's readings at 1 kHz, random but fixed: seed 32) are written
// once as a bag by rosbag's own writer (sensor_msgs/Imu in SI, sensor_msgs/Temperature at 10 Hz, the
// layout of a ROS driver) and once as imufit's samples CSV, then each is read as `imufit fit
// --field` reads it (ReadLogSamples: every sample into memory, the file hashed with SHA-256).
// Figures (best of 3): wall-clock and CPU seconds, MB/s of the file and samples per CPU second, and
// the ratio CSV / bag time (at least 1: the bag reads at least as fast). Also the bag without its
// hash (rosbag's share). Both files are in the page cache (just written): no disk is measured.
// Measured, never asserted: this is not a test. It prints the 1-minute load average first.
//
// Usage: bag_bench [SAMPLES]   (default 1,000,000: a bag of about 350 MB)
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Temperature.h>

#include <time.h>
#include <Eigen/Geometry>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "imufit/io/log_samples.h"
#include "imufit/io/rosbag_samples.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"

namespace {

// Best of `runs` times of `f`, s: wall clock and this process's CPU time (user + system; on a
// loaded shared machine the wall clock measures the other processes as much as this one).
struct Times {
  double wall_s = 1e300;
  double cpu_s = 1e300;
};

double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

Times Best(int runs, const std::function<void()>& f) {
  Times best;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = CpuSeconds();
    f();
    best.cpu_s = std::min(best.cpu_s, CpuSeconds() - cpu_start);
    best.wall_s = std::min(best.wall_s,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

ros::Time StampOf(int64_t ns) {
  return ros::Time(static_cast<uint32_t>(ns / 1000000000), static_cast<uint32_t>(ns % 1000000000));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace imufit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const long long count = argc > 1 ? std::atoll(argv[1]) : 1000000;
  if (count < 10) {
    std::fprintf(stderr, "usage: bag_bench [SAMPLES >= 10]\n");
    return 2;
  }
  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) {
    std::printf("load average (1 min): %.2f%s\n", load[0],
                load[0] > 1.0 ? "  (shared machine: ratios hold better than seconds)" : "");
  }
  const std::filesystem::path folder = std::filesystem::temp_directory_path();
  const std::string bag_path = (folder / "imufit_bag_bench.bag").string();
  const std::string csv_path = (folder / "imufit_bag_bench.csv").string();
  // A unit in the hand at 1 kHz: slowly wandering rates and gravity, white noise, warming up.
  std::mt19937_64 random(32);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int64_t start_ns = 1700000000LL * 1000000000LL;
  std::vector<Sample> samples;
  samples.reserve(count);
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    SamplesWriter csv(csv_path, /*with_segment=*/false);
    Eigen::Vector3d rate = Eigen::Vector3d::Zero();
    Eigen::Vector3d gravity(0.0, 0.0, 9.80665);
    for (long long i = 0; i < count; ++i) {
      const int64_t ns = start_ns + i * 1000000;
      for (int k = 0; k < 3; ++k) rate(k) = 0.999 * rate(k) + 0.01 * noise(random);
      gravity = (gravity + 1e-3 * rate.cross(gravity)).normalized() * 9.80665;
      Sample s;
      s.time_s = static_cast<double>(i) * 1e-3;
      s.temp_c = 25.0 + 10.0 * static_cast<double>(i) / static_cast<double>(count);  // warming linearly
      for (int k = 0; k < 3; ++k) {
        s.gyro(k) = rate(k) + 3e-3 * noise(random);
        s.accel(k) = gravity(k) + 2e-2 * noise(random);
      }
      sensor_msgs::Imu imu;
      imu.header.stamp = StampOf(ns);
      imu.header.frame_id = "imu_link";
      imu.orientation_covariance[0] = -1.0;
      imu.angular_velocity.x = s.gyro.x();
      imu.angular_velocity.y = s.gyro.y();
      imu.angular_velocity.z = s.gyro.z();
      imu.linear_acceleration.x = s.accel.x();
      imu.linear_acceleration.y = s.accel.y();
      imu.linear_acceleration.z = s.accel.z();
      bag.write("/imu/data", imu.header.stamp, imu);
      // A thermometer at 10 Hz; linear in time, so the bag's reader interpolates the CSV's temperature.
      if (i % 100 == 0) {
        sensor_msgs::Temperature reading;
        reading.header.stamp = imu.header.stamp;
        reading.temperature = s.temp_c;
        bag.write("/imu/temperature", reading.header.stamp, reading);
      }
      samples.push_back(s);
    }
    // Past the last thermometer message the reader holds its reading.
    const long long last_reading = (count - 1) / 100 * 100;
    for (long long i = last_reading + 1; i < count; ++i) samples[i].temp_c = samples[last_reading].temp_c;
    for (const Sample& s : samples) csv.Write(s);
    csv.Commit();
  }
  const double bag_mb = static_cast<double>(std::filesystem::file_size(bag_path)) / 1e6;
  const double csv_mb = static_cast<double>(std::filesystem::file_size(csv_path)) / 1e6;
  std::printf(
      "session: %lld samples at 1 kHz; bag %.0f MB (sensor_msgs/Imu + Temperature at 10 Hz), CSV %.0f MB\n",
      count, bag_mb, csv_mb);

  LogSamplesOptions options;
  const auto read = [&](const std::string& path, bool hash) {
    Sha256 digest;
    const LogSamples log = ReadLogSamples(path, options, hash ? &digest : nullptr);
    const auto fail = [&](const char* what) {
      std::fprintf(stderr, "bag_bench: %s: %s\n", path.c_str(), what);
      std::abort();
    };
    if (static_cast<long long>(log.samples.size()) != count) fail("not every sample read");
    // The two files hold the same samples (the interpolated temperature to rounding).
    for (long long i = 0; i < count; i += count / 7) {
      if (log.samples[i].gyro != samples[i].gyro || log.samples[i].accel != samples[i].accel ||
          std::abs(log.samples[i].temp_c - samples[i].temp_c) > 1e-9)
        fail("another sample than written");
    }
    if (hash) digest.HexDigest();
  };
  const Times bag = Best(3, [&] { read(bag_path, true); });
  const Times bag_unhashed = Best(3, [&] { read(bag_path, false); });
  const Times csv = Best(3, [&] { read(csv_path, true); });
  const auto line = [&](const char* what, const Times& t, double mb) {
    std::printf("%-32s wall %7.3f s  cpu %7.3f s  %6.0f MB/s  %5.2f M samples/s (cpu)\n", what, t.wall_s,
                t.cpu_s, mb / t.cpu_s, static_cast<double>(count) / t.cpu_s / 1e6);
  };
  line("bag (ReadLogSamples, hashed)", bag, bag_mb);
  line("bag without its SHA-256", bag_unhashed, bag_mb);
  line("CSV (ReadLogSamples, hashed)", csv, csv_mb);
  std::printf(
      "ratio CSV / bag time: cpu %.2f, wall %.2f (target >= 1: the bag reads at least as fast as the same "
      "samples as CSV)\n",
      csv.cpu_s / bag.cpu_s, csv.wall_s / bag.wall_s);
  std::filesystem::remove(bag_path);
  std::filesystem::remove(csv_path);
  return 0;
}
