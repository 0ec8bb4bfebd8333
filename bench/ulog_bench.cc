// imufit — benchmark of the PX4 ULog reader (io/ulog_samples.h) beside the samples CSV reader on
// the same samples (issue 32: reading a 1 GB ULog at least as fast as the same samples as CSV).
//
// The samples (a gyro and an accelerometer message each, PX4's 44-byte sensor_gyro/sensor_accel
// layout, 98 bytes a sample in the ULog) are written once to a ULog and, by SamplesWriter, to a
// CSV in build-release's temp folder, then each file is read whole (ReadLogSamples, as
// `imufit fit --field` reads it, SHA-256 included) best of 3. Prints both times, MB/s and the
// ratio CSV time / ULog time (target >= 1). Measured, never asserted: this is not a test.
//
// Usage: ulog_bench [SAMPLES]   (default 2,000,000: a 196 MB ULog; 1 GB is 10.2 million)
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "bench_timing.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"

namespace {

// Appends `value`'s little-endian bytes.
template <typename T>
void Append(std::string* out, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out->append(raw, sizeof(T));
}

void AppendMessage(std::string* out, char type, const std::string& payload) {
  Append(out, static_cast<uint16_t>(payload.size()));
  out->push_back(type);
  *out += payload;
}

// sensor_gyro (msg_id 0) or sensor_accel (msg_id 1) data of one sample, padding left out.
void AppendSensor(std::string* out, uint16_t msg_id, uint64_t t_us, const Eigen::Vector3d& v, double temp_c) {
  std::string payload;
  Append(&payload, msg_id);
  Append(&payload, t_us);
  Append(&payload, t_us);
  Append(&payload, uint32_t{0x2a0000u + msg_id});
  for (int i = 0; i < 3; ++i) Append(&payload, static_cast<float>(v[i]));
  Append(&payload, static_cast<float>(temp_c));
  Append(&payload, uint32_t{0});
  Append(&payload, uint32_t{0x01000000u});  // clip_counter[3], samples
  AppendMessage(out, 'D', payload);
}

}  // namespace

using imufit::bench::BestSeconds;

int main(int argc, char** argv) {
  using namespace imufit;
  const long long count = argc > 1 ? std::atoll(argv[1]) : 2000000;
  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) {
    std::printf("load average (1 min): %.2f%s\n", load[0],
                load[0] > 1.0 ? "  (shared machine: ratios hold better than seconds)" : "");
  }
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "imufit_ulog_bench";
  std::filesystem::create_directories(folder);
  const std::string ulog = (folder / "session.ulg").string();
  const std::string csv = (folder / "session.csv").string();
  {
    // The samples as a ULog file would hold them: float32 values, microsecond times at 1 kHz.
    std::mt19937_64 random(32);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::ofstream out(ulog, std::ios::binary);
    std::string bytes("ULog\x01\x12\x35\x01", 8);
    Append(&bytes, uint64_t{0});
    AppendMessage(&bytes, 'B', std::string(40, '\0'));
    const char* fields =
        "uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;float "
        "temperature;uint32_t error_count;uint8_t[3] clip_counter;uint8_t samples;uint8_t[4] _padding0;";
    AppendMessage(&bytes, 'F', std::string("sensor_gyro:") + fields);
    AppendMessage(&bytes, 'F', std::string("sensor_accel:") + fields);
    AppendMessage(&bytes, 'A', std::string("\0\0\0sensor_gyro", 14));
    AppendMessage(&bytes, 'A', std::string("\0\1\0sensor_accel", 15));
    SamplesWriter writer(csv, SampleColumns{false, true});
    for (long long i = 0; i < count; ++i) {
      Sample sample;
      const uint64_t t_us = 1000000 + 1000 * static_cast<uint64_t>(i);
      sample.time_s = static_cast<double>(t_us) * 1e-6;
      sample.temp_c = static_cast<float>(25.0 + 1e-6 * static_cast<double>(i));
      for (int k = 0; k < 3; ++k) {
        sample.gyro[k] =
            static_cast<float>(0.3 * std::sin(1e-3 * static_cast<double>(i) + k) + noise(random));
        sample.accel[k] =
            static_cast<float>(9.8 * std::cos(1e-4 * static_cast<double>(i) + k) + noise(random));
      }
      AppendSensor(&bytes, 0, t_us, sample.gyro, sample.temp_c);
      AppendSensor(&bytes, 1, t_us, sample.accel, sample.temp_c);
      writer.Write(sample);
      if (bytes.size() > (1u << 24)) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        bytes.clear();
      }
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    writer.Commit();
  }
  const double ulog_mb = static_cast<double>(std::filesystem::file_size(ulog)) / 1e6;
  const double csv_mb = static_cast<double>(std::filesystem::file_size(csv)) / 1e6;
  size_t read_ulog = 0, read_csv = 0;
  const auto read = [](const std::string& path, size_t* samples) {
    Sha256 digest;
    *samples = ReadLogSamples(path, {}, &digest).samples.size();
    digest.HexDigest();
  };
  const double csv_s = BestSeconds(3, [&] { read(csv, &read_csv); });
  const double ulog_s = BestSeconds(3, [&] { read(ulog, &read_ulog); });
  std::printf("%lld samples at 1 kHz (gyro and accelerometer), read whole with SHA-256, best of 3:\n", count);
  std::printf("  CSV   %8.1f MB  %7.3f s  %7.1f MB/s  %zu samples\n", csv_mb, csv_s, csv_mb / csv_s,
              read_csv);
  std::printf("  ULog  %8.1f MB  %7.3f s  %7.1f MB/s  %zu samples\n", ulog_mb, ulog_s, ulog_mb / ulog_s,
              read_ulog);
  std::printf("  ratio CSV time / ULog time: %.2f (target >= 1); a 1 GB ULog at this speed: %.1f s\n",
              csv_s / ulog_s, 1000.0 / (ulog_mb / ulog_s));
  std::filesystem::remove_all(folder);
  return read_ulog == read_csv ? 0 : 1;
}
