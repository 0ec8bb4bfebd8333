// imufit — small text helpers: a printf format's text, one double through a printf format, a list
// joined, a CSV cell.
#ifndef IMUFIT_BASE_TEXT_H_
#define IMUFIT_BASE_TEXT_H_

#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace imufit {

// The text of a printf `format` with its arguments, at most 511 characters (messages, lines).
inline std::string FormatText(const char* format, ...) __attribute__((format(printf, 1, 2)));
inline std::string FormatText(const char* format, ...) {
  char text[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  return text;
}

// `value` through `format`, a printf format of one double ("%.3g", "%+.1f").
inline std::string NumberText(const char* format, double value) {
  char text[96];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// `parts` with `separator` between each two ("a; b; c"); "" for none.
inline std::string Join(const std::vector<std::string>& parts, const char* separator) {
  std::string text;
  for (std::size_t i = 0; i < parts.size(); ++i) text += (i == 0 ? "" : separator) + parts[i];
  return text;
}

// A CSV cell (RFC 4180): quoted when it holds a comma, a quote or a line break (a line break
// becomes a space).
inline std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return quoted + "\"";
}

}  // namespace imufit

#endif  // IMUFIT_BASE_TEXT_H_
