// imufit — samples files (docs/spec.md section 2): what the unit said, sample by sample.
//
// Columns, by name and in any order: time_s (s, strictly increasing; the intervals may vary),
// temp_c (degC; may be absent when the caller gives one temperature for the whole run), segment
// (plan segment id, -1 or empty while the table moves), gyro_x..z (raw B), accel_x..z (raw A).
// The reader streams: one row at a time, nothing kept. The writer writes the same layout, numbers
// in their shortest round-trip form, so a written file reads back bit-exactly.
#ifndef IMUFIT_IO_SAMPLES_H_
#define IMUFIT_IO_SAMPLES_H_

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "imufit/io/csv_reader.h"
#include "imufit/io/output_file.h"
#include "imufit/model/sample.h"

namespace imufit {

// The units a time_s column may be written in (--time-unit, model/enum_names.h), as seconds per
// unit: loggers write seconds, milliseconds, microseconds or nanoseconds.
struct TimeUnitName {
  double value;
  const char* name;
};
inline constexpr TimeUnitName kTimeUnitNames[] = {{1.0, "s"}, {1e-3, "ms"}, {1e-6, "us"}, {1e-9, "ns"}};

// What an IMU log can plausibly hold (docs/conventions.md). A calibration plan dwells and turns
// for seconds, so its samples come faster than one a second: a slower time column is one in
// milliseconds or finer read as seconds. Faster than 50 kHz (no IMU samples so fast) is the opposite
// mistake: seconds read as a finer unit.
inline constexpr double kMaxSampleIntervalS = 1.0;   // refused from here on (1 Hz or slower)
inline constexpr double kMinSampleIntervalS = 2e-5;  // refused below (50 kHz or faster: no IMU's rate)
// The rows whose mean interval is judged (fewer in a shorter file).
inline constexpr int kIntervalProbeRows = 16;
// A temperature an IMU can report, degC (a kelvin column, 233..358, or a fill value lies outside).
inline constexpr double kMinPlausibleTempC = -100.0;
inline constexpr double kMaxPlausibleTempC = 200.0;
inline constexpr double kZeroCelsiusK = 273.15;

// A column the file names its own way (--column time_s=Time): the name imufit reads, the file's.
struct ColumnName {
  std::string name;
  std::string in_file;
};

// The names a samples file's columns are read by (time_s, temp_c, segment, gyro_x..accel_z).
inline constexpr const char* kSamplesColumnNames[] = {"time_s", "temp_c",  "segment", "gyro_x", "gyro_y",
                                                      "gyro_z", "accel_x", "accel_y", "accel_z"};

// How a samples file is read beyond its column names: what a command's options say about it.
struct SamplesFormat {
  // The temperature of every sample of a file without a temp_c column (a file with one is then
  // refused, so that no reading is silently replaced).
  std::optional<double> temp_c;
  // Seconds per unit of the time_s column (kTimeUnitNames): times are read as seconds times this.
  double seconds_per_time_unit = 1.0;
  // Its delimiter and decimal mark (--delimiter, --decimal-comma).
  CsvDialect dialect;
  // Columns under the file's own names (--column); the others are found by their names.
  std::vector<ColumnName> column_names;
  // Without temp_c above: a file without a temp_c column is read with NaN in its place (imufit segment,
  // which needs no temperature) instead of being refused.
  bool temp_c_optional = false;

  // The name of column `name` in the file.
  std::string InFile(const std::string& name) const;
};

// The serial of a samples header and where it is stated (its first `# serial:` line, at the text
// after "serial:"), so that a contradiction can be reported at its place (pipeline/unit_serial.h).
struct SamplesSerial {
  std::string serial;  // "" when no line states one (then line and column are 0)
  long line = 0;
  long column = 0;
};

class SamplesReader {
 public:
  // Opens a samples file; `require_segment` makes the segment column mandatory (imufit fit).
  // `format` says how it is read (SamplesFormat). Throws InputError naming every missing column,
  // or a column read under two names.
  // `raw_digest`, when not null, hashes the file as it is read (CsvReader).
  SamplesReader(std::string path, bool require_segment, const SamplesFormat& format = {},
                Sha256* raw_digest = nullptr);

  // Reads `rows`, lines of the file of `header_of` after its line `line_before`, with its header
  // and columns; `last_time_s`, when given, is the time of the row before; `probe_interval` judges
  // the sample interval over its first rows, as Next() does at a file's start (ParallelSamplesReader).
  SamplesReader(const SamplesReader& header_of, std::string_view rows, long line_before,
                std::optional<double> last_time_s = std::nullopt, bool probe_interval = false);

  // Reads the next sample; false at the end. Throws InputError on a bad value, a time that does
  // not increase, a segment id below -1, a temperature outside kMin..kMaxPlausibleTempC (with a
  // "kelvin?" hint), or a sample interval outside kMin..kMaxSampleIntervalS over the first
  // kIntervalProbeRows rows (with a --time-unit hint).
  bool Next(Sample* sample);

  bool has_segment() const { return segment_column_ >= 0; }
  // The unit's serial from the header's `# serial:` line (ReadSamplesSerial), or "".
  const std::string& serial() const { return serial_.serial; }
  // The same with its place in the header (LocateSamplesSerial).
  const SamplesSerial& located_serial() const { return serial_; }
  bool has_temp() const { return temp_column_ >= 0; }
  // The comment lines before the column names (CsvReader::header_comments()).
  const std::vector<CsvReader::Comment>& header_comments() const { return csv_.header_comments(); }
  // Throws an InputError located at the current row and the column called `column`.
  [[noreturn]] void Fail(const std::string& column, const std::string& message) const;
  const std::string& path() const { return csv_.path(); }
  long line_number() const { return csv_.line_number(); }
  long long bytes_read() const { return csv_.bytes_read(); }
  // The rows read so far and the time from the first to the last, s.
  long long rows() const { return rows_; }
  double time_span_s() const { return rows_ > 0 ? last_time_s_ - first_time_s_ : 0.0; }

 private:
  friend class ParallelSamplesReader;  // reads the file's blocks (parallel_samples.h)
  void CheckTemperature(double temp_c) const;
  void CheckRowComments() const;
  double TimeOfRow() const;
  void CheckInterval() const;
  // Throws when two of `columns` (RequireColumns' answer) are one column of the file.
  void CheckDistinct(const std::vector<int>& columns) const;
  // The index of column `name` (a kSamplesColumnNames name), if the file has it.
  std::optional<int> FindColumn(const std::string& name) const {
    return csv_.FindColumn(format_.InFile(name));
  }

  SamplesFormat format_;  // before csv_, which reads with its dialect
  CsvReader csv_;
  double seconds_per_time_unit_ = 1.0;
  int time_column_;
  int temp_column_ = -1;
  double fixed_temp_c_ = 0.0;  // without a temp_c column
  int segment_column_ = -1;
  SamplesSerial serial_;
  int gyro_columns_[3];
  int accel_columns_[3];
  long long rows_ = 0;
  double first_time_s_ = 0.0;
  double last_time_s_ = 0.0;
};

// What is wrong with a temp_c reading outside kMin..kMaxPlausibleTempC, with its likely cause
// (kelvin, a fill value), or "" when it is plausible; `first`: the first row's.
std::string TemperatureProblem(double temp_c, bool first);
// What is wrong with a mean sample interval of `interval_s` over the first `intervals` intervals,
// with the --time-unit to give (the column read in `seconds_per_time_unit`), or "" when plausible.
std::string IntervalProblem(double interval_s, long long intervals, double seconds_per_time_unit);
// What is wrong with a run lasting `span_s` over `intervals` sample intervals when the plan needs
// at least `needed_s` (the column read in `seconds_per_time_unit`), with the --time-unit that makes
// it long enough at a plausible rate, or "" when it lasts long enough.
std::string SpanProblem(double span_s, long long intervals, double needed_s, double seconds_per_time_unit);

// The unit's serial as a samples file's header states it: a comment line `# serial: SN0001`
// before the column names (what `imufit simulate --serial` writes, and a logger can). Returns the
// text after "serial:", trimmed, or "" when no such line exists. Reads the file only up to its
// header. Throws InputError for an unreadable file, an empty serial, or two different serials.
std::string ReadSamplesSerial(const std::string& path);

// As ReadSamplesSerial, with the place.
SamplesSerial LocateSamplesSerial(const std::string& path);

// The comment text (without the '#') that states `serial` in a samples header, for SamplesWriter;
// "" for an empty serial (no line). Throws InputError (naming `source`) when the serial holds a
// control character. Commands that write samples from samples (apply, segment) carry it over.
std::string SerialComment(const std::string& serial, const std::string& source);

// The optional columns a SamplesWriter writes.
struct SampleColumns {
  bool segment = true;
  bool temp = true;
};

class SamplesWriter {
 public:
  // Starts `path` (atomically: nothing appears until Commit(), or until the commit of
  // `transaction` when not null). `with_segment` adds the segment column. `comment`, if not
  // empty, is written first as '#' lines.
  SamplesWriter(std::string path, bool with_segment, const std::string& comment = "")
      : SamplesWriter(std::move(path), SampleColumns{with_segment, true}, comment) {}
  SamplesWriter(std::string path, SampleColumns columns, const std::string& comment = "",
                OutputTransaction* transaction = nullptr);

  void Write(const Sample& sample);
  // Rows made by AppendRow with columns(), written as they are.
  void WriteRows(std::string_view rows) { file_.Write(rows); }
  void Commit() { file_.Commit(); }
  SampleColumns columns() const { return columns_; }
  // Appends the row Write() writes for `sample` to `rows` (on any thread).
  static void AppendRow(const Sample& sample, SampleColumns columns, std::string* rows);

 private:
  // Formats the row of `sample` into `row` (kMaxRowBytes); returns its end.
  static char* FormatRow(const Sample& sample, SampleColumns columns, char* row);
  // A row's bytes at most: 8 numbers of at most 24 characters and a segment id, with delimiters.
  static constexpr size_t kMaxRowBytes = 256;
  OutputFile file_;
  SampleColumns columns_;
};

}  // namespace imufit

#endif  // IMUFIT_IO_SAMPLES_H_
