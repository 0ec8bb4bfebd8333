// imufit — a run's samples held in memory (Python's arrays), read as a samples file is read: the
// same checks (times that increase, a plausible sample interval and temperature, segment ids), so
// that a fit from arrays and a fit from the file of the same samples see the same run. Errors are
// InputErrors located at the run's name and the sample's row (1-based), e.g.
//   imufit.fit samples:12: temp_c: 300 degC is outside -100..200 degC, ...
#ifndef IMUFIT_IO_MEMORY_SAMPLES_H_
#define IMUFIT_IO_MEMORY_SAMPLES_H_

#include <string>
#include <vector>

#include "imufit/io/samples.h"
#include "imufit/model/sample.h"

namespace imufit {

// The samples of a run, in time order, with what a file's header would say about them.
struct SamplesInMemory {
  std::string name;  // stands for the file's path in messages and records
  std::vector<Sample> samples;
  bool has_segment = false;  // false: the segments are found in the data
  bool has_temp = true;      // false: no temperature is known (temp_c NaN, imufit segment's)
  SamplesSerial serial;      // the unit's serial, if known (line and column 0)

  // SHA-256 of the samples' values (time, temperature, segment, gyro, accel of each, as
  // little-endian doubles): what names these samples in a calibration's record.
  std::string Sha256() const;
};

class MemorySamplesReader {
 public:
  // Reads `run` (which must outlive the reader) from its first sample, its times in units of
  // `seconds_per_time_unit` (SamplesFormat).
  explicit MemorySamplesReader(const SamplesInMemory& run, double seconds_per_time_unit = 1.0)
      : run_(run), seconds_per_time_unit_(seconds_per_time_unit) {}

  // The next sample, checked as SamplesReader::Next() checks a row; false at the end.
  bool Next(Sample* sample);
  // Reads again from the first sample.
  void Rewind() { next_ = 0; }
  [[noreturn]] void Fail(const std::string& column, const std::string& message) const;

  bool has_segment() const { return run_.has_segment; }
  const std::string& path() const { return run_.name; }
  const SamplesSerial& located_serial() const { return run_.serial; }
  // The samples and the time from the first to the last, s.
  long long rows() const { return static_cast<long long>(run_.samples.size()); }
  double time_span_s() const {
    return run_.samples.empty() ? 0.0 : TimeS(run_.samples.size() - 1) - TimeS(0);
  }

 private:
  double TimeS(size_t i) const { return run_.samples[i].time_s * seconds_per_time_unit_; }

  const SamplesInMemory& run_;
  double seconds_per_time_unit_;
  size_t next_ = 0;
};

}  // namespace imufit

#endif  // IMUFIT_IO_MEMORY_SAMPLES_H_
