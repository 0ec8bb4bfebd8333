// imufit — a streaming reader for the CSV files of docs/spec.md (plain or gzip-compressed).
//
// The first line that is neither empty nor a comment (starting with '#') is the header; columns
// are found by name, in any order; columns nobody asks for are never parsed. Rows are read in
// blocks of a few MiB, so memory does not grow with the file. Fields may be quoted ("...", with
// "" for a quote) but may not span lines; a row may not have more fields than the header. A
// UTF-8 byte-order mark before the header is skipped. Numbers are parsed with std::from_chars.
//
// The reader can hash the file as it streams it (the SHA-256 of its bytes as they are on disk), so
// that a file whose hash is recorded need not be read again for it.
//
// Errors are InputErrors located at file:line:field, e.g.
//   samples.csv:412:5: gyro_y: "1.2.3" is not a number
#ifndef IMUFIT_IO_CSV_READER_H_
#define IMUFIT_IO_CSV_READER_H_

#include <algorithm>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace imufit {

class Sha256;

// How a CSV file separates its fields and writes its numbers: ',' and '.' by default; a spreadsheet
// in a German (or French, ...) locale exports ';' between fields and a decimal comma.
struct CsvDialect {
  char delimiter = ',';        // ',', ';' or '\t'
  bool decimal_comma = false;  // numbers as "1,5" (only with a delimiter other than ',')
};

class CsvReader {
 public:
  // Input limits (docs/conventions.md): a longer line or more fields is an InputError, so a
  // file that is not a CSV of samples (a binary, /dev/zero, one huge line) costs bounded memory.
  static constexpr size_t kMaxLineBytes = 1 << 20;
  static constexpr size_t kMaxColumns = 10000;
  // Comment lines before the header that are kept (header_comments()), and their length kept:
  // a file of endless comments still costs bounded memory.
  static constexpr size_t kMaxHeaderComments = 256;
  static constexpr size_t kMaxHeaderCommentBytes = 1024;

  // Opens `path` (gzip when it ends in ".gz") and reads its header. Throws InputError. When
  // `raw_digest` is not null, every byte of the file as it is on disk (compressed, for .gz) is fed
  // to it as it is read: once NextRow() has returned false, it has seen the whole file. It must
  // outlive the reader.
  // `dialect` says how its fields are separated and its numbers written.
  explicit CsvReader(std::string path, Sha256* raw_digest = nullptr, const CsvDialect& dialect = {});
  // Reads `rows`, lines of the file of `header_of` after its line `line_before`, with its header
  // and dialect (parallel_samples.h parses the blocks of one file in several of these at once).
  // `rows` is read where it is, not copied: it must outlive the reader.
  CsvReader(const CsvReader& header_of, std::string_view rows, long line_before);
  ~CsvReader();
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;

  const std::vector<std::string>& header() const { return header_; }
  // How many fields the current row has.
  size_t field_count() const { return field_count_; }
  // A comment line before the header: its line number, its text after the '#', trimmed, and the
  // 1-based character column where that text starts (the
  // first kMaxHeaderComments, each cut to kMaxHeaderCommentBytes). Loggers put what describes
  // the whole file there (`# serial: SN0001`, samples.h).
  struct Comment {
    long line;
    long column;
    std::string text;
  };
  const std::vector<Comment>& header_comments() const { return header_comments_; }
  // The comment lines after the header that NextRow() passed over since the row before (the
  // first kMaxRowComments of them): a `# serial:` there means a second run begins.
  static constexpr size_t kMaxRowComments = 16;
  const std::vector<Comment>& row_comments() const { return row_comments_; }
  // The index of the column called `name`, if there is one: the column of that exact name, else the
  // one column whose name differs from it in case only (a logger's "Time_S").
  std::optional<int> FindColumn(std::string_view name) const;
  // The index of the column called `name`; throws InputError naming the header line if absent.
  int RequireColumn(std::string_view name) const;
  // The indices of the columns called `names`, in order; when any is absent, throws one InputError
  // at the header line naming every absent one, with a "did you mean" for a near name, and the
  // delimiter when the header is not separated by the reader's delimiter (a spreadsheet's ';'
  // export read with ','), with the options to give. `hint`, when
  // not empty, is added to the message.
  std::vector<int> RequireColumns(const std::vector<std::string>& names, const std::string& hint = "") const;

  // Advances to the next data row (skipping comments and blank lines); false at the end.
  bool NextRow();
  // The text of field `column` of the current row (unquoted). Throws InputError when the row is
  // too short. Valid until the next NextRow().
  std::string_view Field(int column) const;
  // Field `column` as a finite number; throws InputError naming line, field and column name.
  double Number(int column) const;
  // Field `column` as an integer; an empty field gives `if_empty`.
  long Integer(int column, long if_empty) const;

  // Replaces `rows` with the next block of whole lines of the file's text (newlines and all): at
  // least `bytes` when the file has them, more to end at a line's end (a line longer than
  // kMaxLineBytes goes as it is, for its reader to refuse at its place). False at the end. A read
  // error is thrown after the whole lines read before it have been returned. Lines are not counted
  // (line_number() stays at the header): a block's reader counts its own. Read either blocks or
  // rows after the header.
  bool NextBlock(std::string* rows, size_t bytes);

  // Throws an InputError located at the current row and `column` (1-based field = column + 1).
  [[noreturn]] void Fail(int column, const std::string& message) const {
    FailAt(line_number_, column, message);
  }
  // The same at line `line`.
  [[noreturn]] void FailAt(long line, int column, const std::string& message) const;
  [[noreturn]] void FailRow(const std::string& message) const;

  const std::string& path() const { return path_; }
  long header_line() const { return header_line_; }
  long line_number() const { return line_number_; }
  // Bytes of (decompressed) input consumed so far.
  long long bytes_read() const { return bytes_read_; }

 private:
  class Source;
  bool NextLine(std::string_view* line);
  // Moves the partial line to the front of buffer_ and reads more after it; sets eof_ at the end.
  void Refill();
  void SplitLine(std::string_view line);
  void SkipByteOrderMark(std::string_view* line) const;
  [[noreturn]] void LineTooLong() const;
  [[noreturn]] void TooManyFields() const;

  std::string path_;
  CsvDialect dialect_;
  std::unique_ptr<Source> source_;
  std::vector<char> buffer_;
  const char* text_ = nullptr;  // the text read: buffer_'s, or a block's (the constructor for rows)
  size_t begin_ = 0;            // start of unconsumed bytes in text_
  size_t end_ = 0;              // end of valid bytes in text_
  bool eof_ = false;
  long line_number_ = 0;
  long header_line_ = 0;  // line number of the header, for errors about columns
  long long bytes_read_ = 0;
  std::vector<std::string> header_;
  std::vector<Comment> header_comments_;
  std::vector<Comment> row_comments_;
  void AddField(std::string_view field) {
    if (field_count_ == fields_.size()) {
      if (field_count_ >= kMaxColumns) TooManyFields();
      fields_.resize(std::min(2 * fields_.size() + 16, kMaxColumns));
    }
    fields_[field_count_++] = field;
  }
  std::vector<std::string_view> fields_;  // the first field_count_ are the current row's
  size_t field_count_ = 0;
  std::vector<std::string> unquoted_;  // storage for fields that had quotes
  std::exception_ptr read_error_;      // NextBlock's, thrown at its next call
};

}  // namespace imufit

#endif  // IMUFIT_IO_CSV_READER_H_
