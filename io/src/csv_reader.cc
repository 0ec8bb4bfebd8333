#include "imufit/io/csv_reader.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

#include "imufit/io/error.h"
#include "imufit/io/path.h"

namespace imufit {
namespace {

constexpr size_t kBlockBytes = 4 << 20;

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

// Integers of up to 15 digits, the usual raw output of a unit, are exact doubles: parse them
// directly, which is several times cheaper than the general conversion.
bool ParseSmallInteger(std::string_view text, double* value) {
  const char* p = text.data();
  const char* end = p + text.size();
  bool negative = false;
  if (p != end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  if (p == end || end - p > 15) return false;
  long long magnitude = 0;
  for (; p != end; ++p) {
    const unsigned digit = static_cast<unsigned>(*p - '0');
    if (digit > 9) return false;
    magnitude = magnitude * 10 + digit;
  }
  *value = negative ? -static_cast<double>(magnitude) : static_cast<double>(magnitude);
  return true;
}

}  // namespace

// Reads bytes from a plain file (read(2)) or a gzip stream (zlib).
class CsvReader::Source {
 public:
  explicit Source(const std::string& path) : path_(path) {
    if (IsGzipPath(path)) {
      gz_ = gzopen(path.c_str(), "rb");
      if (gz_ == nullptr) Throw();
      gzbuffer(gz_, 1 << 18);
    } else {
      fd_ = ::open(path.c_str(), O_RDONLY);
      if (fd_ < 0) Throw();
    }
  }
  ~Source() {
    if (gz_ != nullptr) gzclose(gz_);
    if (fd_ >= 0) ::close(fd_);
  }
  // Reads up to `size` bytes; 0 at the end.
  size_t Read(char* data, size_t size) {
    if (gz_ != nullptr) {
      const int n = gzread(gz_, data, static_cast<unsigned>(size));
      if (n < 0) {
        int code = 0;
        const char* message = gzerror(gz_, &code);
        throw InputError(path_, std::string("cannot decompress: ") + message);
      }
      return static_cast<size_t>(n);
    }
    for (;;) {
      const ssize_t n = ::read(fd_, data, size);
      if (n >= 0) return static_cast<size_t>(n);
      if (errno != EINTR) throw InputError(path_, std::string("cannot read: ") + std::strerror(errno));
    }
  }

 private:
  [[noreturn]] void Throw() {
    throw InputError(path_, std::string("cannot open: ") + std::strerror(errno ? errno : ENOENT));
  }
  std::string path_;
  gzFile gz_ = nullptr;
  int fd_ = -1;
};

CsvReader::CsvReader(std::string path) : path_(std::move(path)) {
  errno = 0;
  source_ = std::make_unique<Source>(path_);
  buffer_.resize(kBlockBytes);
  std::string_view line;
  while (NextLine(&line)) {
    if (Trim(line).empty() || line.front() == '#') continue;
    SplitLine(line);
    header_line_ = line_number_;
    for (size_t i = 0; i < field_count_; ++i) {
      const std::string name(Trim(fields_[i]));
      if (name.empty()) {
        throw InputError(path_, line_number_, static_cast<long>(i) + 1, "empty column name in the header");
      }
      for (size_t j = 0; j < header_.size(); ++j) {
        if (header_[j] == name) {
          throw InputError(path_, line_number_, static_cast<long>(i) + 1,
                           "column " + QuoteForMessage(name) + " appears twice in the header");
        }
      }
      header_.push_back(name);
    }
    return;
  }
  throw InputError(path_, "no header line: the file is empty");
}

CsvReader::~CsvReader() = default;

std::optional<int> CsvReader::FindColumn(std::string_view name) const {
  for (size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

int CsvReader::RequireColumn(std::string_view name) const {
  if (const std::optional<int> column = FindColumn(name)) return *column;
  std::string have;
  for (const std::string& h : header_) have += (have.empty() ? "" : ",") + h;
  throw InputError(path_, header_line_, 0,
                   "no column " + QuoteForMessage(name) + " in the header (it has: " + have + ")");
}

bool CsvReader::NextLine(std::string_view* line) {
  for (;;) {
    const char* start = buffer_.data() + begin_;
    const void* newline = std::memchr(start, '\n', end_ - begin_);
    if (newline != nullptr) {
      const char* stop = static_cast<const char*>(newline);
      *line = std::string_view(start, stop - start);
      if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
      bytes_read_ += (stop - start) + 1;
      begin_ = (stop - buffer_.data()) + 1;
      ++line_number_;
      return true;
    }
    if (eof_) {
      if (begin_ == end_) return false;
      // A last line without a newline.
      *line = std::string_view(start, end_ - begin_);
      if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
      bytes_read_ += end_ - begin_;
      begin_ = end_;
      ++line_number_;
      return true;
    }
    // Move the partial line to the front and refill; grow for very long lines.
    const size_t partial = end_ - begin_;
    std::memmove(buffer_.data(), buffer_.data() + begin_, partial);
    begin_ = 0;
    end_ = partial;
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
    const size_t got = source_->Read(buffer_.data() + end_, buffer_.size() - end_);
    if (got == 0) eof_ = true;
    end_ += got;
  }
}

void CsvReader::SplitLine(std::string_view line) {
  field_count_ = 0;
  if (std::memchr(line.data(), '"', line.size()) == nullptr) {
    // Fast path: no quotes, so every comma separates two fields.
    const char* data = line.data();
    const char* end = data + line.size();
    const char* start = data;
    for (;;) {
      const char* comma = static_cast<const char*>(std::memchr(start, ',', end - start));
      if (comma == nullptr) break;
      AddField(std::string_view(start, comma - start));
      start = comma + 1;
    }
    AddField(std::string_view(start, end - start));
    return;
  }
  // Slow path: RFC 4180 quoting within one line.
  unquoted_.clear();
  unquoted_.reserve(line.size() + 1);  // no reallocation: fields_ keeps views into these strings
  size_t i = 0;
  for (;;) {
    std::string field;
    while (i < line.size() && line[i] != ',') {
      if (line[i] == '"') {
        ++i;
        while (i < line.size()) {
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
      } else {
        field += line[i++];
      }
    }
    unquoted_.push_back(std::move(field));
    AddField(unquoted_.back());
    if (i >= line.size()) return;
    ++i;  // the comma
    if (i == line.size()) {
      AddField(std::string_view());
      return;
    }
  }
}

bool CsvReader::NextRow() {
  std::string_view line;
  while (NextLine(&line)) {
    if (line.empty() || line.front() == '#') continue;
    if (Trim(line).empty()) continue;
    SplitLine(line);
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
  if (ParseSmallInteger(text, &value)) return value;
  text = Trim(text);
  if (text.empty()) Fail(column, "empty value, a number is needed");
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (*first == '+') ++first;
  const auto result = std::from_chars(first, last, value);
  if (result.ec != std::errc() || result.ptr != last) {
    Fail(column, QuoteForMessage(text) + " is not a number");
  }
  if (!std::isfinite(value)) Fail(column, QuoteForMessage(text) + " is not a finite number");
  return value;
}

long CsvReader::Integer(int column, long if_empty) const {
  const std::string_view text = Trim(Field(column));
  if (text.empty()) return if_empty;
  long value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    Fail(column, QuoteForMessage(text) + " is not an integer");
  }
  return value;
}

void CsvReader::Fail(int column, const std::string& message) const {
  throw InputError(path_, line_number_, column + 1, header_[column] + ": " + message);
}

void CsvReader::FailRow(const std::string& message) const {
  throw InputError(path_, line_number_, 0, message);
}

}  // namespace imufit
