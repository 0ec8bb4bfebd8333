// Fuzzes the PX4 ULog reader (io/ulog_samples.h) and the dispatch that tells it from a CSV
// (io/log_samples.h). Oracles: an accepted log gives samples that are finite, at increasing times,
// and the same when read again with its instance chosen explicitly; every refusal is an InputError.
#include <cmath>
#include <vector>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/log_samples.h"
#include "imufit/io/sha256.h"
#include "imufit/io/ulog_samples.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  const std::string path = fuzz::WriteInput(data, size, ".ulg");
  UlogSamples log;
  try {
    Sha256 digest;
    const LogSamples read = ReadLogSamples(path, {}, &digest);
    IMUFIT_FUZZ_CHECK(digest.HexDigest() == Sha256OfFile(path), "the digest is the file's");
    if (read.format != LogFormat::kUlog) return 0;  // a CSV: fuzz_samples's
    log = ReadUlogSamples(path);
    IMUFIT_FUZZ_CHECK(log.samples.size() == read.samples.size(), "the dispatch reads the same samples");
  } catch (const InputError&) {
    return 0;  // refused, with a message: fine
  }
  IMUFIT_FUZZ_CHECK(!log.samples.empty(), "an accepted log has samples");
  for (size_t i = 0; i < log.samples.size(); ++i) {
    const Sample& s = log.samples[i];
    IMUFIT_FUZZ_CHECK(
        std::isfinite(s.time_s) && std::isfinite(s.temp_c) && s.gyro.allFinite() && s.accel.allFinite(),
        "a sample read is finite");
    IMUFIT_FUZZ_CHECK(i == 0 || s.time_s > log.samples[i - 1].time_s, "time increases");
  }
  UlogOptions chosen;
  chosen.instance = log.instance;
  const UlogSamples again = ReadUlogSamples(path, chosen);
  IMUFIT_FUZZ_CHECK(again.samples.size() == log.samples.size(), "the instance chosen reads the same samples");
  for (size_t i = 0; i < log.samples.size(); ++i) {
    IMUFIT_FUZZ_CHECK(again.samples[i].time_s == log.samples[i].time_s &&
                          again.samples[i].gyro == log.samples[i].gyro &&
                          again.samples[i].accel == log.samples[i].accel,
                      "the same samples");
  }
  return 0;
}
