// imufit — the one error type of io/: bad input, located in its file.
//
// Every problem with a file a user gave (plan, samples, calibration, an output path) is thrown as
// an InputError carrying the file, the 1-based line and column where there is one (0 = unknown),
// and a message that quotes the offending text. what() reads like a compiler diagnostic:
//
//   samples.csv:412:5: gyro_y: "1.2.3" is not a number
//
// The file name and the message are made safe for a terminal (EscapeForMessage) and bounded.
//
// For CSV files the column is the 1-based field number; for YAML files it is the character
// column that yaml-cpp reports.
#ifndef IMUFIT_IO_ERROR_H_
#define IMUFIT_IO_ERROR_H_

#include <stdexcept>
#include <string>
#include <string_view>

namespace imufit {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, long line, long column, const std::string& message);
  InputError(std::string file, const std::string& message) : InputError(std::move(file), 0, 0, message) {}

  const std::string& file() const { return file_; }
  long line() const { return line_; }
  long column() const { return column_; }
  // The message without the location prefix.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  long line_;
  long column_;
  std::string message_;
};

// Quotes a piece of offending input for an error message, shortened when long and with
// control characters escaped: "1.2.3".
std::string QuoteForMessage(std::string_view text);

// `text` for an error message: control characters (ESC, BEL, CR, NUL, ...) and DEL escaped as
// \xHH, shortened to `max_shown` characters with "..." when longer.
std::string EscapeForMessage(std::string_view text, size_t max_shown);

// Every message is bounded: the text of an InputError (file name and message together) is at
// most about this many characters, whatever the input.
inline constexpr size_t kMaxMessageChars = 1000;

}  // namespace imufit

#endif  // IMUFIT_IO_ERROR_H_
