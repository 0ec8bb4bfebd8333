// Fuzzes the uniform-series reader of imufit allan (plain and gzip). Oracle: an accepted series
// has columns of one length, at least two samples, finite values and a positive, finite sample
// interval within its time span.
#include <cmath>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/pipeline/series_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  UniformSeriesOptions options;
  options.bridge_gaps = size > 0 && (data[size - 1] & 1);
  UniformSeries series;
  try {
    series = ReadUniformSeries(fuzz::WriteInput(data, size, fuzz::CsvSuffix(data, size)), {}, options);
  } catch (const InputError&) {
    return 0;
  }
  IMUFIT_FUZZ_CHECK(!series.columns.empty() && series.columns.size() == series.names.size(), "columns named");
  for (const std::vector<double>& column : series.columns) {
    IMUFIT_FUZZ_CHECK(column.size() == series.columns[0].size(), "columns of one length");
    IMUFIT_FUZZ_CHECK(column.size() >= 2, "at least two samples");
    for (const double value : column) IMUFIT_FUZZ_CHECK(std::isfinite(value), "finite values");
  }
  IMUFIT_FUZZ_CHECK(series.sample_interval_s > 0.0 && std::isfinite(series.sample_interval_s), "an interval");
  IMUFIT_FUZZ_CHECK(series.end_time_s > series.start_time_s, "time advances");
  return 0;
}
