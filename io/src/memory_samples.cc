#include "imufit/io/memory_samples.h"

#include <cmath>

#include "imufit/io/error.h"
#include "imufit/io/sha256.h"

namespace imufit {

std::string SamplesInMemory::Sha256() const {
  imufit::Sha256 digest;
  for (const Sample& s : samples) {
    const double values[] = {s.time_s,   s.temp_c,   static_cast<double>(s.segment),
                             s.gyro(0),  s.gyro(1),  s.gyro(2),
                             s.accel(0), s.accel(1), s.accel(2)};
    digest.Update(std::string_view(reinterpret_cast<const char*>(values), sizeof values));
  }
  return digest.HexDigest();
}

bool MemorySamplesReader::Next(Sample* sample) {
  const std::vector<Sample>& samples = run_.samples;
  if (next_ == samples.size()) {
    if (next_ > 1 && next_ <= static_cast<size_t>(kIntervalProbeRows)) {
      const double interval_s = (TimeS(next_ - 1) - TimeS(0)) / static_cast<double>(next_ - 1);
      if (const std::string problem =
              IntervalProblem(interval_s, static_cast<long long>(next_ - 1), seconds_per_time_unit_);
          !problem.empty()) {
        Fail("time_s", problem);
      }
    }
    return false;
  }
  *sample = samples[next_++];
  sample->time_s = TimeS(next_ - 1);
  if (!run_.has_segment) sample->segment = kTransitionSegment;
  const auto finite = [this](const char* column, double value) {
    if (!std::isfinite(value)) Fail(column, FormatDouble(value) + " is not a finite number");
  };
  finite("time_s", sample->time_s);
  if (run_.has_temp) finite("temp_c", sample->temp_c);
  for (int axis = 0; axis < 3; ++axis) {
    finite("gyro", sample->gyro(axis));
    finite("accel", sample->accel(axis));
  }
  if (next_ > 1 && !(sample->time_s > TimeS(next_ - 2))) {
    Fail("time_s", FormatDouble(sample->time_s) + " s does not increase (the sample before has " +
                       FormatDouble(TimeS(next_ - 2)) + " s)");
  }
  if (next_ == static_cast<size_t>(kIntervalProbeRows) + 1) {
    const double interval_s = (sample->time_s - TimeS(0)) / kIntervalProbeRows;
    if (const std::string problem = IntervalProblem(interval_s, kIntervalProbeRows, seconds_per_time_unit_);
        !problem.empty()) {
      Fail("time_s", problem);
    }
  }
  if (const std::string problem = TemperatureProblem(sample->temp_c, next_ == 1);
      run_.has_temp && !problem.empty()) {
    Fail("temp_c", problem);
  }
  if (sample->segment < kTransitionSegment) {
    Fail("segment",
         std::to_string(sample->segment) + " is not a segment id (an id >= 0, or -1 while the table moves)");
  }
  return true;
}

void MemorySamplesReader::Fail(const std::string& column, const std::string& message) const {
  throw InputError(run_.name, static_cast<long>(next_), 0, column + ": " + message);
}

}  // namespace imufit
