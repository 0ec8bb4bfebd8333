#include "imufit/pipeline/series_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <utility>

#include "imufit/base/enum_names.h"
#include "imufit/io/csv_reader.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/path.h"
#include "imufit/io/samples.h"
#include "imufit/pipeline/correct_file.h"

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

// Builds a UniformSeries row by row, whatever reads the rows: checks each time step against the
// nominal interval (gaps, jitter; see series_reader.h), keeps the values, and reserves the
// vectors from the file size once the bytes per row are known. `fail(message)` throws an
// InputError located at the current row's time field.
class SeriesBuilder {
 public:
  SeriesBuilder(std::string path, std::vector<std::string> names, const UniformSeriesOptions& options)
      : path_(std::move(path)), options_(options) {
    series_.names = std::move(names);
    series_.columns.resize(series_.names.size());
  }

  template <typename Fail>
  void AddTime(double time, const Fail& fail) {
    if (rows_ == 0) {
      series_.start_time_s = time;
    } else {
      const double dt = time - previous_time_;
      if (!(dt > 0.0)) {
        fail(FormatDouble(time) + " s does not increase (the previous sample is at " +
             FormatDouble(previous_time_) + " s)");
      }
      if (rows_ == 1) nominal_ = dt;
      const double deviation = (dt - nominal_) / nominal_;
      if (std::fabs(deviation) <= options_.time_tolerance) {
        accepted_sum_ += dt;
        ++accepted_;
        series_.max_jitter = std::max(series_.max_jitter, std::fabs(deviation));
      } else if (deviation > 0.0 && options_.bridge_gaps) {
        ++series_.gaps_bridged;
        series_.bridged_time_s += dt - nominal_;
      } else if (deviation > 0.0) {
        fail("a gap in time: " + FormatDouble(time) + " s follows " + FormatDouble(previous_time_) +
             Format(" s, %.4g sample intervals of %.9g s (tolerance %g intervals; --gaps bridge joins "
                    "the data across gaps)",
                    dt / nominal_, nominal_, options_.time_tolerance));
      } else {
        fail("time jitter: " + FormatDouble(time) + " s follows " + FormatDouble(previous_time_) +
             Format(" s after %.4g of the sample interval %.9g s (the tolerance is +-%g intervals, "
                    "--time-tolerance)",
                    dt / nominal_, nominal_, options_.time_tolerance));
      }
    }
    previous_time_ = time;
  }

  // After AddTime and the row's values: counts the row; reserves once enough rows were read.
  void EndRow(long long bytes_read) {
    ++rows_;
    if (rows_ == kRowsBeforeReserve && !IsGzipPath(path_)) {
      struct stat status;
      if (::stat(path_.c_str(), &status) == 0 && bytes_read > 0) {
        const double bytes_per_row = static_cast<double>(bytes_read) / static_cast<double>(rows_);
        const auto expected =
            static_cast<size_t>(1.02 * static_cast<double>(status.st_size) / bytes_per_row) + 1024;
        for (std::vector<double>& column : series_.columns) column.reserve(expected);
      }
    }
  }

  std::vector<double>& column(size_t c) { return series_.columns[c]; }

  UniformSeries Finish() {
    if (rows_ < 2) {
      throw InputError(path_, "too short: " + std::to_string(rows_) +
                                  " sample(s); at least two are needed for the sample interval");
    }
    series_.end_time_s = previous_time_;
    // Timestamps written in decimal carry rounding of about 1e-13 relative in each difference, so
    // the mean interval is rounded to 12 significant digits: 0.01, not 0.009999999999999998.
    const double mean_interval = accepted_ > 0 ? static_cast<double>(accepted_sum_ / accepted_) : nominal_;
    char digits[32];
    std::snprintf(digits, sizeof digits, "%.12g", mean_interval);
    series_.sample_interval_s = std::strtod(digits, nullptr);
    return std::move(series_);
  }

 private:
  std::string path_;
  UniformSeriesOptions options_;
  UniformSeries series_;
  int64_t rows_ = 0;
  double previous_time_ = 0.0;
  double nominal_ = 0.0;
  long double accepted_sum_ = 0.0L;
  int64_t accepted_ = 0;
};

void CheckTolerance(const std::string& path, const UniformSeriesOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty()) throw InputError(path, problem);
}

// How a gap in the time column is taken: "error" or "bridge" (bridge_gaps).
constexpr EnumName<bool> kGapNames[] = {{false, "error"}, {true, "bridge"}};

OptionTable<UniformSeriesOptions> MakeUniformSeriesOptionTable() {
  using O = UniformSeriesOptions;
  OptionTable<O> t;
  t.Number("time_tolerance", "--time-tolerance",
           "largest deviation of a time step from the sample interval, in sample intervals", "",
           &O::time_tolerance, Between(0.0, 0.5, /*min_open=*/true, /*max_open=*/true));
  t.Text(
      "gaps", "--gaps", "error: a gap in time_s is an error; bridge: join the data across gaps",
      [](const O& o) { return std::string(NameOf(kGapNames, o.bridge_gaps)); },
      [](const std::string& text, O* o) -> std::string {
        if (ValueOf(kGapNames, text, &o->bridge_gaps)) return "";
        return "\"" + text + "\" is not one of: " + AllNames(kGapNames);
      });
  return t;
}

// The columns of a corrected sample ReadCorrectedSeries offers, and the value of each.
constexpr const char* kCorrectedNames[] = {"gyro_x",  "gyro_y",  "gyro_z", "accel_x",
                                           "accel_y", "accel_z", "temp_c"};
constexpr int kCorrectedRates = 6;  // the first six: what is analysed without --columns
double CorrectedValue(const Sample& corrected, int index) {
  if (index < 3) return corrected.gyro(index);
  if (index < kCorrectedRates) return corrected.accel(index - 3);
  return corrected.temp_c;
}

}  // namespace

const OptionTable<UniformSeriesOptions>& UniformSeriesOptionTable() {
  static const OptionTable<UniformSeriesOptions> table = MakeUniformSeriesOptionTable();
  return table;
}

std::string UniformSeriesOptions::Validate() const {
  return ValidateOptions(UniformSeriesOptionTable(), *this);
}

UniformSeries ReadUniformSeries(const std::string& path, const std::vector<std::string>& columns,
                                const UniformSeriesOptions& options) {
  CheckTolerance(path, options);
  CsvReader csv(path);
  const long header_line = csv.line_number();
  std::vector<std::string> names = columns;
  if (names.empty()) {
    for (const std::string& name : csv.header()) {
      if (StartsWith(name, "gyro_") || StartsWith(name, "accel_")) names.push_back(name);
    }
    if (names.empty()) {
      throw InputError(path, header_line, 0,
                       "no columns named: give --columns (no gyro_* or accel_* column in the header)");
    }
  }
  const int time_column = csv.RequireColumn("time_s");
  std::vector<int> indices;
  for (const std::string& name : names) indices.push_back(csv.RequireColumn(name));
  SeriesBuilder builder(path, std::move(names), options);
  const auto fail = [&](const std::string& message) { csv.Fail(time_column, message); };
  while (csv.NextRow()) {
    builder.AddTime(csv.Number(time_column), fail);
    for (size_t c = 0; c < indices.size(); ++c) builder.column(c).push_back(csv.Number(indices[c]));
    builder.EndRow(csv.bytes_read());
  }
  return builder.Finish();
}

UniformSeries ReadCorrectedSeries(const std::string& path, const Calibration& calibration,
                                  const SamplesFormat& format, const std::vector<std::string>& columns,
                                  const UniformSeriesOptions& options, CorrectFileReport* report) {
  CheckTolerance(path, options);
  SamplesReader reader(path, /*require_segment=*/false, format);
  std::vector<std::string> names = columns;
  if (names.empty()) names.assign(std::begin(kCorrectedNames), std::begin(kCorrectedNames) + kCorrectedRates);
  std::vector<int> indices;
  for (const std::string& name : names) {
    const auto* found = std::find(std::begin(kCorrectedNames), std::end(kCorrectedNames), name);
    if (found == std::end(kCorrectedNames)) {
      throw InputError(path,
                       "column " + QuoteForMessage(name) +
                           " is not one a calibration corrects: with --calibration the columns are "
                           "gyro_x, gyro_y, gyro_z (rad/s), accel_x, accel_y, accel_z (m/s^2) and temp_c");
    }
    indices.push_back(static_cast<int>(found - std::begin(kCorrectedNames)));
  }
  SeriesBuilder builder(path, std::move(names), options);
  const auto fail = [&](const std::string& message) { reader.Fail("time_s", message); };
  *report = CorrectSamples(calibration, &reader, [&](const Sample& corrected) {
    builder.AddTime(corrected.time_s, fail);
    for (size_t c = 0; c < indices.size(); ++c)
      builder.column(c).push_back(CorrectedValue(corrected, indices[c]));
    builder.EndRow(reader.bytes_read());
  });
  return builder.Finish();
}

}  // namespace imufit
