// Fuzzes the samples reader (CsvReader under SamplesReader, plain and gzip; the fuzz build reads
// in 64-byte blocks so lines straddle refills). Oracle: an accepted file written back by
// SamplesWriter reads back as exactly the same samples (the shortest round-trip decimal form).
#include <cmath>
#include <cstring>
#include <vector>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/samples.h"

namespace {

bool Same(const imufit::Sample& a, const imufit::Sample& b) {
  return std::memcmp(&a.time_s, &b.time_s, sizeof(double)) == 0 &&
         std::memcmp(&a.temp_c, &b.temp_c, sizeof(double)) == 0 && a.segment == b.segment &&
         a.gyro == b.gyro && a.accel == b.accel;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  const std::string path = fuzz::WriteInput(data, size, fuzz::CsvSuffix(data, size));
  std::vector<Sample> samples;
  bool has_segment = false;
  try {
    SamplesReader reader(path, /*require_segment=*/false);
    has_segment = reader.has_segment();
    Sample sample;
    while (reader.Next(&sample)) {
      IMUFIT_FUZZ_CHECK(std::isfinite(sample.time_s) && std::isfinite(sample.temp_c) &&
                            sample.gyro.allFinite() && sample.accel.allFinite(),
                        "a sample read is finite");
      IMUFIT_FUZZ_CHECK(samples.empty() || sample.time_s > samples.back().time_s, "time increases");
      samples.push_back(sample);
    }
  } catch (const InputError&) {
    return 0;  // refused, with a message: fine
  }
  const std::string copy = fuzz::Folder() + "/copy.csv";
  {
    SamplesWriter writer(copy, has_segment);
    for (const Sample& sample : samples) writer.Write(sample);
    writer.Commit();
  }
  SamplesReader again(copy, false);
  Sample sample;
  for (const Sample& expected : samples) {
    IMUFIT_FUZZ_CHECK(again.Next(&sample), "the copy has every sample");
    IMUFIT_FUZZ_CHECK(Same(sample, expected), "write -> read is bit-exact");
  }
  IMUFIT_FUZZ_CHECK(!again.Next(&sample), "the copy has no extra sample");
  return 0;
}
