// Fuzzes the ROS 1 bag reader (io_logs: ReadRosbagSamples over Debian's rosbag_storage, which is
// not instrumented: its own code is exercised, not measured). Whatever the library throws must come
// out as an InputError; oracles on an accepted bag: every sample finite, time strictly increasing
// from 0, the temperature a plausible one, and the same samples read through ReadLogSamples (the
// dispatch by the file's first bytes) with the same SHA-256 as the file's.
#include <cmath>
#include <cstring>
#include <vector>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/rosbag_samples.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"

namespace {

void CheckSamples(const std::vector<imufit::Sample>& samples) {
  IMUFIT_FUZZ_CHECK(!samples.empty(), "an accepted bag has samples");
  IMUFIT_FUZZ_CHECK(samples.front().time_s == 0.0, "time counts from the first stamp");
  for (size_t i = 0; i < samples.size(); ++i) {
    const imufit::Sample& s = samples[i];
    IMUFIT_FUZZ_CHECK(
        std::isfinite(s.time_s) && std::isfinite(s.temp_c) && s.gyro.allFinite() && s.accel.allFinite(),
        "a sample read is finite");
    IMUFIT_FUZZ_CHECK(s.temp_c >= imufit::kMinPlausibleTempC && s.temp_c <= imufit::kMaxPlausibleTempC,
                      "a plausible temperature");
    IMUFIT_FUZZ_CHECK(i == 0 || s.time_s > samples[i - 1].time_s, "time increases");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  const std::string path = fuzz::WriteInput(data, size, ".bag");
  // The bag's own temperature topic, else every sample at 25 degC.
  for (const RosbagOptions& options : {RosbagOptions{}, RosbagOptions{"", "", 25.0}}) {
    std::vector<Sample> samples;
    try {
      samples = ReadRosbagSamples(path, options).samples;
    } catch (const InputError& e) {
      IMUFIT_FUZZ_CHECK(std::strchr(e.what(), '\n') == nullptr, "one line");
      continue;  // refused, with a message: fine
    }
    CheckSamples(samples);
    LogSamplesOptions log;
    log.csv.temp_c = options.temp_c;
    Sha256 digest;
    const LogSamples again = ReadLogSamples(path, log, &digest);
    IMUFIT_FUZZ_CHECK(again.format == LogFormat::kRosbag, "told by its magic");
    IMUFIT_FUZZ_CHECK(again.samples.size() == samples.size(), "read alike twice");
    for (size_t i = 0; i < samples.size(); ++i) {
      IMUFIT_FUZZ_CHECK(std::memcmp(&again.samples[i].time_s, &samples[i].time_s, sizeof(double)) == 0 &&
                            again.samples[i].gyro == samples[i].gyro &&
                            again.samples[i].accel == samples[i].accel,
                        "read alike twice");
    }
    IMUFIT_FUZZ_CHECK(digest.HexDigest() == Sha256OfFile(path), "the file's hash");
  }
  return 0;
}
