#include "imufit/io/error.h"

#include <cstdio>

namespace imufit {
namespace {

std::string Locate(const std::string& file, long line, long column) {
  std::string where = EscapeForMessage(file, 300);
  if (line > 0) {
    where += ":" + std::to_string(line);
    if (column > 0) where += ":" + std::to_string(column);
  }
  return where;
}

}  // namespace

InputError::InputError(std::string file, long line, long column, const std::string& message)
    : std::runtime_error(Locate(file, line, column) + ": " + EscapeForMessage(message, kMaxMessageChars)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(EscapeForMessage(message, kMaxMessageChars)) {}

std::string EscapeForMessage(std::string_view text, size_t max_shown) {
  std::string escaped;
  for (size_t i = 0; i < text.size() && i < max_shown; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      escaped += hex;
    } else {
      escaped += static_cast<char>(c);
    }
  }
  if (text.size() > max_shown) escaped += "...";
  return escaped;
}

std::string QuoteForMessage(std::string_view text) {
  constexpr size_t kMaxShown = 40;
  std::string quoted = "\"";
  for (size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    const char c = text[i];
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  quoted = EscapeForMessage(quoted, std::string::npos);
  if (text.size() > kMaxShown) quoted += "...";
  return quoted + "\"";
}

}  // namespace imufit
