#include "imufit/io/samples.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>

#include "imufit/io/csv_reader.h"
#include "imufit/io/error.h"

namespace imufit {
namespace {

constexpr const char* kGyroNames[3] = {"gyro_x", "gyro_y", "gyro_z"};
constexpr const char* kAccelNames[3] = {"accel_x", "accel_y", "accel_z"};
constexpr std::string_view kSerialKey = "serial:";

// A newline would end a comment line; other control characters have no place in a serial.
bool HasControlCharacter(const std::string& text) {
  return std::any_of(text.begin(), text.end(),
                     [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

// Whether a row's field, as written, is the column name `name` (blanks around it and case aside).
bool IsColumnName(std::string_view field, const std::string& name) {
  const size_t first = field.find_first_not_of(" \t\r");
  const size_t last = field.find_last_not_of(" \t\r");
  field = first == std::string_view::npos ? std::string_view() : field.substr(first, last - first + 1);
  return field.size() == name.size() &&
         std::equal(field.begin(), field.end(), name.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

// The serial a comment states (`serial: SN0001`, its text after the key, trimmed), and the column
// where it starts; nullopt for another comment. Throws for an empty serial.
std::optional<std::pair<std::string, long>> SerialOfComment(const std::string& path,
                                                            const CsvReader::Comment& comment) {
  if (comment.text.compare(0, kSerialKey.size(), kSerialKey) != 0) return std::nullopt;
  const size_t first = comment.text.find_first_not_of(" \t", kSerialKey.size());
  const long column = comment.column + static_cast<long>(std::min(first, comment.text.size()));
  if (first == std::string::npos) throw InputError(path, comment.line, column, "an empty serial");
  return std::make_pair(comment.text.substr(first), column);
}

// The serial of LocateSamplesSerial, from a reader that has read the header.
SamplesSerial SerialInHeader(const CsvReader& csv) {
  const std::string& path = csv.path();
  SamplesSerial serial;
  for (const CsvReader::Comment& comment : csv.header_comments()) {
    const auto stated = SerialOfComment(path, comment);
    if (!stated) continue;
    const auto& [found, column] = *stated;
    if (!serial.serial.empty() && found != serial.serial) {
      // Two units in one file, or a header pasted onto another unit's log: certify neither.
      throw InputError(
          path, comment.line, column,
          "a second serial " + QuoteForMessage(found) + " after " + QuoteForMessage(serial.serial));
    }
    if (HasControlCharacter(found)) {
      throw InputError(path, comment.line, column,
                       "the serial " + QuoteForMessage(found) + " holds a control character");
    }
    if (serial.serial.empty()) serial = {found, comment.line, column};
  }
  return serial;
}

// A figure of a message, to 4 significant digits.
std::string ShortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

}  // namespace

SamplesReader::SamplesReader(std::string path, bool require_segment, const SamplesFormat& format,
                             Sha256* raw_digest)
    : format_(format),
      csv_(std::move(path), raw_digest, format.dialect),
      seconds_per_time_unit_(format.seconds_per_time_unit),
      serial_(SerialInHeader(csv_)) {
  const std::optional<double>& temp_c = format.temp_c;
  const bool has_temp = FindColumn("temp_c").has_value();
  const bool read_temp = !temp_c && (has_temp || !format.temp_c_optional);
  // Every column needed, so that all that are absent are named at once.
  std::vector<std::string> names = {"time_s"};
  names.insert(names.end(), std::begin(kGyroNames), std::end(kGyroNames));
  names.insert(names.end(), std::begin(kAccelNames), std::end(kAccelNames));
  if (read_temp) names.push_back("temp_c");
  if (require_segment) names.push_back("segment");
  for (std::string& name : names) name = format.InFile(name);
  const std::vector<int> columns = csv_.RequireColumns(
      names, temp_c || has_temp ? "" : "; for a run without a thermometer give its temperature (--temp-c)");
  CheckDistinct(columns);
  time_column_ = columns[0];
  for (int axis = 0; axis < 3; ++axis) {
    gyro_columns_[axis] = columns[1 + axis];
    accel_columns_[axis] = columns[4 + axis];
  }
  if (read_temp) {
    temp_column_ = columns[7];
  } else if (!temp_c) {
    fixed_temp_c_ = std::nan("");  // temp_c_optional
  } else if (has_temp) {
    throw InputError(csv_.path(),
                     "has a temp_c column: a fixed temperature (--temp-c) is only for samples "
                     "without one (leave it out to use the readings)");
  } else {
    fixed_temp_c_ = *temp_c;
  }
  if (require_segment) {
    segment_column_ = columns.back();
  } else if (const auto column = FindColumn("segment")) {
    segment_column_ = *column;
  }
}

// A `# serial:` line among the rows naming another unit than the header: two units' logs in one
// file (two runs concatenated). Fitting them as one unit would give a calibration of neither.
void SamplesReader::CheckRowComments() const {
  for (const CsvReader::Comment& comment : csv_.row_comments()) {
    const auto stated = SerialOfComment(csv_.path(), comment);
    if (!stated || stated->first == serial_.serial) continue;
    const std::string header = serial_.serial.empty() ? "the header names no unit"
                                                      : "the header names " + QuoteForMessage(serial_.serial);
    throw InputError(csv_.path(), comment.line, stated->second,
                     "a second unit " + QuoteForMessage(stated->first) + " begins here, among the samples (" +
                         header +
                         "): two logs in one file? Split it at this line and fit each unit's log "
                         "alone");
  }
}

// The row's time; a row that repeats the column names (a second log's header, two files joined
// with cat) is said to be one.
double SamplesReader::TimeOfRow() const {
  try {
    return csv_.Number(time_column_);
  } catch (const InputError&) {
    bool header = csv_.field_count() == csv_.header().size();
    for (size_t i = 0; header && i < csv_.header().size(); ++i) {
      header = IsColumnName(csv_.Field(static_cast<int>(i)), csv_.header()[i]);
    }
    if (header) {
      csv_.Fail(time_column_,
                "the column names again, among the samples: two logs in one file? Split it at this line "
                "and fit each unit's log alone");
    }
    throw;
  }
}

bool SamplesReader::Next(Sample* sample) {
  const bool row = csv_.NextRow();
  if (!csv_.row_comments().empty()) CheckRowComments();
  if (!row) {
    if (rows_ > 1 && rows_ <= kIntervalProbeRows) CheckInterval();
    return false;
  }
  sample->time_s = TimeOfRow() * seconds_per_time_unit_;
  if (rows_ > 0 && !(sample->time_s > last_time_s_)) {
    csv_.Fail(time_column_, FormatDouble(sample->time_s) + " s does not increase (the row before has " +
                                FormatDouble(last_time_s_) + " s)");
  }
  if (rows_ == 0) first_time_s_ = sample->time_s;
  ++rows_;
  last_time_s_ = sample->time_s;
  if (rows_ == kIntervalProbeRows + 1) CheckInterval();
  if (temp_column_ >= 0) {
    sample->temp_c = csv_.Number(temp_column_);
    CheckTemperature(sample->temp_c);
  } else {
    sample->temp_c = fixed_temp_c_;
  }
  for (int axis = 0; axis < 3; ++axis) {
    sample->gyro(axis) = csv_.Number(gyro_columns_[axis]);
    sample->accel(axis) = csv_.Number(accel_columns_[axis]);
  }
  sample->segment = kTransitionSegment;
  if (segment_column_ >= 0) {
    const long segment = csv_.Integer(segment_column_, kTransitionSegment);
    if (segment < kTransitionSegment || segment > 1000000000L) {
      csv_.Fail(segment_column_,
                std::to_string(segment) + " is not a segment id (an id >= 0, or -1 while the table moves)");
    }
    sample->segment = static_cast<int>(segment);
  }
  return true;
}

void SamplesReader::CheckTemperature(double temp_c) const {
  if (temp_c >= kMinPlausibleTempC && temp_c <= kMaxPlausibleTempC) return;  // without a call, per row
  if (const std::string problem = TemperatureProblem(temp_c, rows_ == 1); !problem.empty())
    csv_.Fail(temp_column_, problem);
}

std::string TemperatureProblem(double temp_c, bool first) {
  if (temp_c >= kMinPlausibleTempC && temp_c <= kMaxPlausibleTempC) return "";
  std::string message = FormatDouble(temp_c) + " degC is outside " + FormatDouble(kMinPlausibleTempC) + ".." +
                        FormatDouble(kMaxPlausibleTempC) + " degC, what an IMU can report: ";
  const double as_kelvin_c = temp_c - kZeroCelsiusK;
  if (as_kelvin_c >= kMinPlausibleTempC && as_kelvin_c <= kMaxPlausibleTempC) {
    message += std::string(first ? "the column is in kelvin?" : "kelvin?") + " (" + FormatDouble(temp_c) +
               " K is " + FormatDouble(as_kelvin_c) + " degC; temp_c must be degC)";
  } else if (temp_c == -kZeroCelsiusK) {
    message += "absolute zero, a logger's fill value for a missing reading? (kelvin? temp_c must be degC)";
  } else {
    message += "a fill value or a broken reading? (kelvin? temp_c must be degC)";
  }
  return message;
}

void SamplesReader::CheckInterval() const {
  const long long intervals = rows_ - 1;
  const double interval_s = (last_time_s_ - first_time_s_) / static_cast<double>(intervals);
  if (const std::string problem = IntervalProblem(interval_s, intervals, seconds_per_time_unit_);
      !problem.empty()) {
    csv_.Fail(time_column_, problem);
  }
}

namespace {

bool PlausibleInterval(double interval_s) {
  return interval_s < kMaxSampleIntervalS && interval_s >= kMinSampleIntervalS;
}

// The hint naming the first other --time-unit under which `plausible(factor)` holds, `factor` being
// what times read in the declared unit are multiplied by; a plain question when none does.
std::string TimeUnitHint(double seconds_per_time_unit, const std::function<bool(double)>& plausible) {
  constexpr const char* kLongNames[] = {"seconds", "milliseconds", "microseconds", "nanoseconds"};
  for (size_t i = 0; i < std::size(kTimeUnitNames); ++i) {
    if (kTimeUnitNames[i].value == seconds_per_time_unit) continue;
    if (!plausible(kTimeUnitNames[i].value / seconds_per_time_unit)) continue;
    return std::string(": time in ") + kLongNames[i] + "? use --time-unit " + kTimeUnitNames[i].name;
  }
  return " (is --time-unit right?)";
}

}  // namespace

std::string IntervalProblem(double interval_s, long long intervals, double seconds_per_time_unit) {
  if (PlausibleInterval(interval_s)) return "";
  const std::string hint = TimeUnitHint(
      seconds_per_time_unit, [interval_s](double factor) { return PlausibleInterval(interval_s * factor); });
  return "the time steps by " + ShortNumber(interval_s) + " s per sample over the first " +
         std::to_string(intervals) + " intervals (" + ShortNumber(1.0 / interval_s) + " Hz), too " +
         (interval_s >= kMaxSampleIntervalS ? "slow" : "fast") +
         " for an IMU run whose dwells and turns last seconds" + hint;
}

std::string SpanProblem(double span_s, long long intervals, double needed_s, double seconds_per_time_unit) {
  if (span_s >= needed_s || intervals <= 0) return "";
  const double interval_s = span_s / static_cast<double>(intervals);
  const std::string hint = TimeUnitHint(seconds_per_time_unit, [&](double factor) {
    return span_s * factor >= needed_s && PlausibleInterval(interval_s * factor);
  });
  return "the run lasts " + ShortNumber(span_s) + " s (" + std::to_string(intervals + 1) + " samples at " +
         ShortNumber(1.0 / interval_s) + " Hz), shorter than the plan's segments can last (" +
         ShortNumber(needed_s) + " s)" + hint;
}

void SamplesReader::CheckDistinct(const std::vector<int>& columns) const {
  for (size_t i = 0; i < columns.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (columns[i] != columns[j]) continue;
      throw InputError(csv_.path(), csv_.header_line(), columns[i] + 1,
                       "column " + QuoteForMessage(csv_.header()[columns[i]]) +
                           " is read as two columns (a --column map names a column that has its own name?)");
    }
  }
}

std::string SamplesFormat::InFile(const std::string& name) const {
  for (const ColumnName& column : column_names) {
    if (column.name == name) return column.in_file;
  }
  return name;
}

void SamplesReader::Fail(const std::string& column, const std::string& message) const {
  const std::optional<int> index = FindColumn(column);
  if (!index) csv_.FailRow(message);
  csv_.Fail(*index, message);
}

std::string ReadSamplesSerial(const std::string& path) { return LocateSamplesSerial(path).serial; }

SamplesSerial LocateSamplesSerial(const std::string& path) { return SerialInHeader(CsvReader(path)); }

std::string SerialComment(const std::string& serial, const std::string& source) {
  if (serial.empty()) return "";
  if (HasControlCharacter(serial)) {
    throw InputError(source, "the serial " + QuoteForMessage(serial) + " holds a control character");
  }
  return std::string(kSerialKey) + " " + serial;
}

SamplesWriter::SamplesWriter(std::string path, SampleColumns columns, const std::string& comment,
                             OutputTransaction* transaction)
    : file_(std::move(path), transaction), columns_(columns) {
  if (!comment.empty()) {
    std::istringstream lines(comment);
    std::string line;
    while (std::getline(lines, line)) file_.Write("# " + line + "\n");
  }
  file_.Write(columns_.temp ? "time_s,temp_c," : "time_s,");
  if (columns_.segment) file_.Write("segment,");
  file_.Write("gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n");
}

char* SamplesWriter::FormatRow(const Sample& sample, SampleColumns columns, char* row) {
  // Non-finite numbers are spelled as WriteNumber spells them.
  char* end = row;
  const auto number = [&end, row](double value) {
    if (!std::isfinite(value)) {
      const std::string text = FormatDouble(value);
      end = std::copy(text.begin(), text.end(), end);
    } else {
      end = std::to_chars(end, row + kMaxRowBytes, value).ptr;
    }
    *end++ = ',';
  };
  number(sample.time_s);
  if (columns.temp) number(sample.temp_c);
  if (columns.segment) {
    end = std::to_chars(end, row + kMaxRowBytes, sample.segment).ptr;
    *end++ = ',';
  }
  for (int axis = 0; axis < 3; ++axis) number(sample.gyro(axis));
  for (int axis = 0; axis < 3; ++axis) number(sample.accel(axis));
  end[-1] = '\n';
  return end;
}

void SamplesWriter::AppendRow(const Sample& sample, SampleColumns columns, std::string* rows) {
  char row[kMaxRowBytes];
  rows->append(row, FormatRow(sample, columns, row) - row);
}

void SamplesWriter::Write(const Sample& sample) {
  // The row is formatted in one buffer and written at once: a write per field costs more than the
  // numbers' formatting.
  char row[kMaxRowBytes];
  file_.Write(std::string_view(row, FormatRow(sample, columns_, row) - row));
}

}  // namespace imufit
