#include "imufit/io/path.h"
#include "imufit/io/series_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "imufit/io/csv_reader.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

// Rows read before the vectors are reserved from the file size.
constexpr int64_t kRowsBeforeReserve = 4096;

bool StartsWith(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char text[400];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

}  // namespace

UniformSeries ReadUniformSeries(const std::string& path, const std::vector<std::string>& columns,
                                const UniformSeriesOptions& options) {
  if (!(options.time_tolerance > 0.0 && options.time_tolerance < 0.5)) {
    throw InputError(path, "the time tolerance must lie between 0 and 0.5 sample intervals");
  }
  CsvReader csv(path);
  const long header_line = csv.line_number();
  UniformSeries series;
  series.names = columns;
  if (series.names.empty()) {
    for (const std::string& name : csv.header()) {
      if (StartsWith(name, "gyro_") || StartsWith(name, "accel_")) series.names.push_back(name);
    }
    if (series.names.empty()) {
      throw InputError(path, header_line, 0, "no columns named: give --columns (no gyro_* or accel_* column in the header)");
    }
  }
  const int time_column = csv.RequireColumn("time_s");
  std::vector<int> indices;
  for (const std::string& name : series.names) indices.push_back(csv.RequireColumn(name));
  series.columns.resize(series.names.size());

  int64_t rows = 0;
  double previous_time = 0.0;
  double nominal = 0.0;
  long double accepted_sum = 0.0L;
  int64_t accepted = 0;
  while (csv.NextRow()) {
    const double time = csv.Number(time_column);
    if (rows == 0) {
      series.start_time_s = time;
    } else {
      const double dt = time - previous_time;
      if (!(dt > 0.0)) {
        csv.Fail(time_column, FormatDouble(time) + " s does not increase (the previous sample is at " +
                                  FormatDouble(previous_time) + " s)");
      }
      if (rows == 1) nominal = dt;
      const double deviation = (dt - nominal) / nominal;
      if (std::fabs(deviation) <= options.time_tolerance) {
        accepted_sum += dt;
        ++accepted;
        series.max_jitter = std::max(series.max_jitter, std::fabs(deviation));
      } else if (deviation > 0.0 && options.bridge_gaps) {
        ++series.gaps_bridged;
        series.bridged_time_s += dt - nominal;
      } else if (deviation > 0.0) {
        csv.Fail(time_column,
                 "a gap in time: " + FormatDouble(time) + " s follows " + FormatDouble(previous_time) +
                     Format(" s, %.4g sample intervals of %.9g s (tolerance %g intervals; --gaps bridge joins "
                            "the data across gaps)",
                            dt / nominal, nominal, options.time_tolerance));
      } else {
        csv.Fail(time_column,
                 "time jitter: " + FormatDouble(time) + " s follows " + FormatDouble(previous_time) +
                     Format(" s after %.4g of the sample interval %.9g s (the tolerance is +-%g intervals, "
                            "--time-tolerance)",
                            dt / nominal, nominal, options.time_tolerance));
      }
    }
    previous_time = time;
    for (size_t c = 0; c < indices.size(); ++c) series.columns[c].push_back(csv.Number(indices[c]));
    ++rows;
    if (rows == kRowsBeforeReserve && !IsGzipPath(path)) {
      struct stat status;
      if (::stat(path.c_str(), &status) == 0 && csv.bytes_read() > 0) {
        const double bytes_per_row = static_cast<double>(csv.bytes_read()) / static_cast<double>(rows);
        const auto expected = static_cast<size_t>(1.02 * static_cast<double>(status.st_size) / bytes_per_row) + 1024;
        for (std::vector<double>& column : series.columns) column.reserve(expected);
      }
    }
  }
  if (rows < 2) {
    throw InputError(path, "too short: " + std::to_string(rows) +
                               " sample(s); at least two are needed for the sample interval");
  }
  series.end_time_s = previous_time;
  // Timestamps written in decimal carry rounding of about 1e-13 relative in each difference, so
  // the mean interval is rounded to 12 significant digits: 0.01, not 0.009999999999999998.
  const double mean_interval = accepted > 0 ? static_cast<double>(accepted_sum / accepted) : nominal;
  char digits[32];
  std::snprintf(digits, sizeof digits, "%.12g", mean_interval);
  series.sample_interval_s = std::strtod(digits, nullptr);
  return series;
}

}  // namespace imufit
