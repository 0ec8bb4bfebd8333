#include "imufit/io/csv_reader.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <unordered_set>
#include <utility>

#include "byte_source.h"
#include "imufit/io/error.h"

namespace imufit {
namespace {

// The read block. The fuzz build makes it tiny (IMUFIT_CSV_BLOCK_BYTES) so that lines straddle
// refills all the time.
#ifdef IMUFIT_CSV_BLOCK_BYTES
constexpr size_t kBlockBytes = IMUFIT_CSV_BLOCK_BYTES;
#else
constexpr size_t kBlockBytes = 4 << 20;
#endif

// The delimiters a file may use (CsvDialect), with their names in messages and on the command line.
constexpr char kDelimiters[] = {',', ';', '\t'};
std::string DelimiterName(char delimiter) {
  return delimiter == '\t' ? "tabs" : std::string("'") + delimiter + "'";
}
std::string DelimiterOption(char delimiter) {
  return delimiter == '\t' ? "tab" : std::string("'") + delimiter + "'";
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

// Numbers of up to 15 digits with at most one point and no exponent ("2122", "-0.00125"), the
// usual output of a logger, parse directly: their digits are an exact double and so is the power
// of ten, so one division rounds them exactly as std::from_chars does, several times cheaper.
// `point_allowed`: a point is the decimal mark (not in a file of decimal commas, which refuses it).
bool ParseShortDecimal(std::string_view text, bool point_allowed, double* value) {
  constexpr double kPowersOfTen[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  const char* p = text.data();
  const char* end = p + text.size();
  bool negative = false;
  if (p != end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  long long digits = 0;
  int count = 0;
  const char* point = nullptr;
  for (; p != end; ++p) {
    const unsigned digit = static_cast<unsigned>(*p - '0');
    if (digit <= 9) {
      if (++count > 15) return false;  // before the digits could overflow: from_chars reads it
      digits = digits * 10 + digit;
    } else if (*p == '.' && point == nullptr && point_allowed) {
      point = p;
    } else {
      return false;
    }
  }
  if (count == 0) return false;
  double magnitude = static_cast<double>(digits);
  if (point != nullptr) magnitude /= kPowersOfTen[end - point - 1];
  *value = negative ? -magnitude : magnitude;
  return true;
}

bool EqualIgnoringCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Edit distance, ignoring case, of two short names (a header name and one a reader needs).
size_t NameDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      const bool same = EqualIgnoringCase(a.substr(i - 1, 1), b.substr(j - 1, 1));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The header name nearest to `name` ("gyro x", "gyrox", "temp" for "temp_c"), or "" when none is
// near: within a third of the name's length, or a prefix of it.
std::string NearestName(const std::vector<std::string>& header, std::string_view name) {
  constexpr size_t kMaxNameBytes = 64;
  std::string best;
  size_t best_distance = std::max<size_t>(1, name.size() / 3) + 1;
  for (const std::string& candidate : header) {
    if (candidate.size() > kMaxNameBytes) continue;
    const bool prefix =
        candidate.size() >= 3 && EqualIgnoringCase(name.substr(0, candidate.size()), candidate);
    const size_t distance = prefix ? 1 : NameDistance(candidate, name);
    if (distance < best_distance) {
      best = candidate;
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace

// The file's bytes, decompressed when it is gzip (by its name or its magic bytes), hashed as read.
class CsvReader::Source : public ByteSource {
 public:
  using ByteSource::ByteSource;
};

CsvReader::CsvReader(std::string path, Sha256* raw_digest, const CsvDialect& dialect)
    : path_(std::move(path)), dialect_(dialect) {
  if (dialect_.decimal_comma && dialect_.delimiter == ',') {
    throw InputError(path_,
                     "--decimal-comma needs --delimiter ';' or tab (a decimal comma and a ',' between "
                     "fields cannot be told apart)");
  }
  errno = 0;
  source_ = std::make_unique<Source>(path_, raw_digest);
  buffer_.resize(kBlockBytes);
  text_ = buffer_.data();
  std::string_view line;
  while (NextLine(&line)) {
    if (line_number_ == 1) SkipByteOrderMark(&line);
    if (Trim(line).empty()) continue;
    if (line.front() == '#') {
      if (header_comments_.size() < kMaxHeaderComments) {
        const std::string_view text = Trim(line.substr(1));
        const long column = static_cast<long>(text.data() - line.data()) + 1;
        header_comments_.push_back(
            {line_number_, column, std::string(text.substr(0, kMaxHeaderCommentBytes))});
      }
      continue;
    }
    SplitLine(line);
    header_line_ = line_number_;
    std::unordered_set<std::string_view> seen;  // views into header_, reserved so they stay valid
    header_.reserve(field_count_);
    for (size_t i = 0; i < field_count_; ++i) {
      const std::string_view name = Trim(fields_[i]);
      header_.emplace_back(name);
      // A column without a name (pandas' index, a spreadsheet's row numbers, a delimiter at the end
      // of the line) is another column, never looked up: the readers ignore what they do not name.
      if (name.empty()) continue;
      if (!seen.insert(header_.back()).second) {
        throw InputError(path_, line_number_, static_cast<long>(i) + 1,
                         "column " + QuoteForMessage(name) + " appears twice in the header");
      }
    }
    return;
  }
  throw InputError(path_, "no header line: the file is empty");
}

CsvReader::CsvReader(const CsvReader& header_of, std::string_view rows, long line_before)
    : path_(header_of.path_),
      dialect_(header_of.dialect_),
      text_(rows.data()),
      end_(rows.size()),
      eof_(true),
      line_number_(line_before),
      header_line_(header_of.header_line_),
      header_(header_of.header_) {}

CsvReader::~CsvReader() = default;

std::optional<int> CsvReader::FindColumn(std::string_view name) const {
  for (size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == name) return static_cast<int>(i);
  }
  std::optional<int> found;
  for (size_t i = 0; i < header_.size(); ++i) {
    if (!EqualIgnoringCase(header_[i], name)) continue;
    if (found) return std::nullopt;  // "Gyro_X" and "GYRO_X": neither is chosen
    found = static_cast<int>(i);
  }
  return found;
}

int CsvReader::RequireColumn(std::string_view name) const {
  return RequireColumns({std::string(name)}).front();
}

std::vector<int> CsvReader::RequireColumns(const std::vector<std::string>& names,
                                           const std::string& hint) const {
  std::vector<int> columns;
  std::vector<std::string> missing;
  std::string guesses;
  // A near name is guessed among the columns no needed name takes ("accel_x" is no "accel_z").
  std::vector<std::string> unclaimed;
  for (const std::string& column : header_) {
    const bool claimed = std::any_of(names.begin(), names.end(), [&column](const std::string& name) {
      return EqualIgnoringCase(column, name);
    });
    if (!claimed) unclaimed.push_back(column);
  }
  for (const std::string& name : names) {
    if (const std::optional<int> column = FindColumn(name)) {
      columns.push_back(*column);
      continue;
    }
    missing.push_back(QuoteForMessage(name));
    if (const std::string near = NearestName(unclaimed, name); !near.empty()) {
      guesses += (guesses.empty() ? "; did you mean " : ", ") + QuoteForMessage(near) + " for " +
                 QuoteForMessage(name);
    }
  }
  if (missing.empty()) return columns;
  // One field holding another delimiter: the columns were never split.
  if (header_.size() == 1) {
    for (const char delimiter : kDelimiters) {
      if (delimiter == dialect_.delimiter || header_[0].find(delimiter) == std::string::npos) continue;
      std::string message = "the header is separated by " + DelimiterName(delimiter) + ", not " +
                            DelimiterName(dialect_.delimiter) + ": give --delimiter " +
                            DelimiterOption(delimiter);
      if (delimiter != ',') message += " (and --decimal-comma when its numbers are written 1,5)";
      throw InputError(path_, header_line_, 0,
                       message + " (header: " + EscapeForMessage(header_[0], 80) + ")");
    }
  }
  constexpr size_t kShown = 12;
  std::string have;
  for (size_t i = 0; i < header_.size() && i < kShown; ++i)
    have += (i ? "," : "") + EscapeForMessage(header_[i], 24);
  if (header_.size() > kShown) have += ",... " + std::to_string(header_.size()) + " columns in all";
  std::string list;
  for (size_t i = 0; i < missing.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == missing.size() ? " and " : ", ") + missing[i];
  }
  throw InputError(path_, header_line_, 0,
                   std::string(missing.size() == 1 ? "no column " : "no columns ") + list +
                       " in the header (it has: " + have + ")" + guesses + hint);
}

void CsvReader::SkipByteOrderMark(std::string_view* line) const {
  if (line->substr(0, 3) == "\xEF\xBB\xBF") {
    line->remove_prefix(3);  // UTF-8 byte-order mark, as spreadsheet programs write
  } else if (line->substr(0, 2) == "\xFF\xFE" || line->substr(0, 2) == "\xFE\xFF") {
    throw InputError(path_, 1, 1,
                     "UTF-16 text (it starts with the byte-order mark " +
                         std::string(line->front() == '\xFF' ? "FF FE" : "FE FF") +
                         "): save the file as UTF-8 or ASCII");
  }
}

void CsvReader::LineTooLong() const {
  throw InputError(path_, line_number_ + 1, 0,
                   "line longer than " + std::to_string(kMaxLineBytes) +
                       " bytes (the limit of a CSV line): not a CSV file of samples?");
}

void CsvReader::TooManyFields() const {
  throw InputError(
      path_, line_number_, 0,
      "more than " + std::to_string(kMaxColumns) + " fields on one line (the limit of a CSV line)");
}

bool CsvReader::NextLine(std::string_view* line) {
  for (;;) {
    const char* start = text_ + begin_;
    const void* newline = std::memchr(start, '\n', end_ - begin_);
    if (newline != nullptr) {
      const char* stop = static_cast<const char*>(newline);
      if (static_cast<size_t>(stop - start) > kMaxLineBytes) LineTooLong();
      *line = std::string_view(start, stop - start);
      if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
      bytes_read_ += (stop - start) + 1;
      begin_ = (stop - text_) + 1;
      ++line_number_;
      return true;
    }
    if (eof_) {
      if (begin_ == end_) return false;
      if (end_ - begin_ > kMaxLineBytes) LineTooLong();
      // A last line without a newline.
      *line = std::string_view(start, end_ - begin_);
      if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
      bytes_read_ += end_ - begin_;
      begin_ = end_;
      ++line_number_;
      return true;
    }
    Refill();
  }
}

void CsvReader::Refill() {
  // Move the partial line to the front and refill; grow for very long lines.
  const size_t partial = end_ - begin_;
  if (partial > kMaxLineBytes) LineTooLong();
  std::memmove(buffer_.data(), buffer_.data() + begin_, partial);
  begin_ = 0;
  end_ = partial;
  if (end_ == buffer_.size()) buffer_.resize(std::min(buffer_.size() * 2, kMaxLineBytes + 2));
  text_ = buffer_.data();
  const size_t got = source_->Read(buffer_.data() + end_, buffer_.size() - end_);
  if (got == 0) eof_ = true;
  end_ += got;
}

bool CsvReader::NextBlock(std::string* rows, size_t bytes) {
  if (read_error_) std::rethrow_exception(std::exchange(read_error_, nullptr));
  // The partial line the last block left (or what reading the header left), then the file's bytes.
  // `rows` is filled up to `size` and cut to it at the end: a reused string keeps its length, so
  // that its bytes are not cleared only to be read over.
  size_t size = end_ - begin_;
  if (rows->size() < size) rows->resize(size);
  std::memcpy(rows->data(), text_ + begin_, size);
  begin_ = end_ = 0;
  // After the last newline in rows (0 when there is none).
  const auto end_of_lines = [rows, &size] {
    const void* newline = size == 0 ? nullptr : ::memrchr(rows->data(), '\n', size);
    return newline == nullptr ? 0 : static_cast<size_t>(static_cast<const char*>(newline) - rows->data() + 1);
  };
  size_t last_line_end = 0;
  for (;;) {
    last_line_end = end_of_lines();
    // Full enough, or one line longer than any may be: it goes on as it is, to fail at its place.
    if (eof_ || (last_line_end > 0 && size >= bytes) || size > kMaxLineBytes) break;
    rows->resize(std::max({rows->size(), bytes, size + size / 2}));
    try {
      while (size < rows->size() && !eof_) {
        const size_t n = source_->Read(rows->data() + size, rows->size() - size);
        eof_ = n == 0;
        size += n;
      }
    } catch (...) {
      // A read error comes after the whole lines read before it, as NextRow() reads them.
      read_error_ = std::current_exception();
      eof_ = true;
      rows->resize(end_of_lines());
      if (rows->empty()) std::rethrow_exception(std::exchange(read_error_, nullptr));
      bytes_read_ += static_cast<long long>(rows->size());
      return true;
    }
  }
  if (!eof_ && last_line_end > 0) {  // the partial last line waits for the next block
    buffer_.assign(rows->begin() + last_line_end, rows->begin() + size);
    text_ = buffer_.data();
    end_ = buffer_.size();
    size = last_line_end;
  }
  rows->resize(size);
  bytes_read_ += static_cast<long long>(size);
  return size > 0;
}

void CsvReader::SplitLine(std::string_view line) {
  field_count_ = 0;
  {
    // Fast path: no quotes, so every delimiter separates two fields. One pass over the bytes (rows
    // are short: a call to memchr per field costs more).
    const char* data = line.data();
    const char* end = data + line.size();
    const char* start = data;
    const char delimiter = dialect_.delimiter;
    const char* p = data;
    for (; p != end; ++p) {
      if (*p == delimiter) {
        AddField(std::string_view(start, p - start));
        start = p + 1;
      } else if (*p == '"') {
        break;
      }
    }
    if (p == end) {
      AddField(std::string_view(start, end - start));
      return;
    }
    field_count_ = 0;
  }
  // Slow path: RFC 4180 quoting within one line. A field is either quoted whole ("...", with ""
  // for a quote, blanks allowed around it) or holds no quote at all; anything else ("1"2, 1"2",
  // an unterminated quote) is an error rather than a guess.
  unquoted_.clear();
  unquoted_.reserve(line.size() + 1);  // no reallocation: fields_ keeps views into these strings
  size_t i = 0;
  for (;;) {
    const long column = static_cast<long>(field_count_) + 1;
    size_t start = i;
    while (start < line.size() && (line[start] == ' ' || line[start] == '\t')) ++start;
    if (start < line.size() && line[start] == '"') {
      std::string field;
      i = start + 1;
      for (;;) {
        if (i >= line.size()) {
          throw InputError(path_, line_number_, column, "a quote is not closed (a field may not span lines)");
        }
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        field += line[i++];
      }
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i < line.size() && line[i] != dialect_.delimiter) {
        throw InputError(path_, line_number_, column,
                         "text after the closing quote of a field: " + QuoteForMessage(line.substr(start)));
      }
      unquoted_.push_back(std::move(field));
      AddField(unquoted_.back());
    } else {
      const size_t comma = std::min(line.find(dialect_.delimiter, i), line.size());
      const std::string_view field = line.substr(i, comma - i);
      if (field.find('"') != std::string_view::npos) {
        throw InputError(path_, line_number_, column,
                         "a quote inside an unquoted field: " + QuoteForMessage(field) +
                             " (quote the whole field, with \"\" for a quote)");
      }
      AddField(field);
      i = comma;
    }
    if (i >= line.size()) return;
    ++i;  // the delimiter
    if (i == line.size()) {
      AddField(std::string_view());
      return;
    }
  }
}

bool CsvReader::NextRow() {
  std::string_view line;
  row_comments_.clear();
  while (NextLine(&line)) {
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (row_comments_.size() < kMaxRowComments) {
        const std::string_view text = Trim(line.substr(1));
        const long column = static_cast<long>(text.data() - line.data()) + 1;
        row_comments_.push_back({line_number_, column, std::string(text.substr(0, kMaxHeaderCommentBytes))});
      }
      continue;
    }
    if (Trim(line).empty()) continue;
    SplitLine(line);
    if (field_count_ > header_.size()) {
      FailRow("the row has " + std::to_string(field_count_) + " fields, the header names " +
              std::to_string(header_.size()) +
              " (a decimal comma, or a comma inside a value that is not quoted?)");
    }
    return true;
  }
  return false;
}

std::string_view CsvReader::Field(int column) const {
  if (column >= static_cast<int>(field_count_)) {
    FailRow("the row has " + std::to_string(field_count_) + " fields, the header names " +
            std::to_string(header_.size()) + " (no value for " + QuoteForMessage(header_[column]) + ")");
  }
  return fields_[column];
}

double CsvReader::Number(int column) const {
  if (column >= static_cast<int>(field_count_)) Field(column);  // throws: the row is too short
  std::string_view text = fields_[column];
  double value = 0.0;
  if (ParseShortDecimal(text, !dialect_.decimal_comma, &value)) return value;
  text = Trim(text);
  if (text.empty()) Fail(column, "empty value, a number is needed");
  const std::string_view as_written = text;
  // A decimal comma becomes a point (a point in such a file is a thousands separator: refused).
  constexpr size_t kMaxNumberBytes = 64;
  char with_point[kMaxNumberBytes];
  if (dialect_.decimal_comma && text.size() <= kMaxNumberBytes) {
    if (text.find('.') != std::string_view::npos) {
      Fail(column, QuoteForMessage(text) + " has a '.' in a file with decimal commas (--decimal-comma)");
    }
    std::replace_copy(text.begin(), text.end(), with_point, ',', '.');
    text = std::string_view(with_point, text.size());
  } else if (dialect_.delimiter != ',' && text.find(',') != std::string_view::npos) {
    Fail(column, QuoteForMessage(text) + " is not a number (a decimal comma? give --decimal-comma)");
  }
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (*first == '+') {
    ++first;
    if (first != last && (*first == '-' || *first == '+'))
      Fail(column, QuoteForMessage(as_written) + " is not a number");
  }
  const auto result = std::from_chars(first, last, value);
  if (result.ec != std::errc() || result.ptr != last) {
    Fail(column, QuoteForMessage(as_written) + " is not a number");
  }
  if (!std::isfinite(value)) Fail(column, QuoteForMessage(as_written) + " is not a finite number");
  return value;
}

long CsvReader::Integer(int column, long if_empty) const {
  std::string_view text = Trim(Field(column));
  if (text.empty()) return if_empty;
  if (text.size() > 1 && text.front() == '+' && text[1] != '-' && text[1] != '+')
    text.remove_prefix(1);  // "+1"
  long value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    Fail(column, QuoteForMessage(text) + " is not an integer");
  }
  return value;
}

void CsvReader::FailAt(long line, int column, const std::string& message) const {
  throw InputError(path_, line, column + 1, EscapeForMessage(header_[column], 40) + ": " + message);
}

void CsvReader::FailRow(const std::string& message) const {
  throw InputError(path_, line_number_, 0, message);
}

}  // namespace imufit
