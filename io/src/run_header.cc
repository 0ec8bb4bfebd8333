#include "imufit/io/run_header.h"

#include <algorithm>

#include "imufit/io/error.h"

namespace imufit {
namespace {

bool IsLeapYear(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

bool AllDigits(const std::string& text, size_t from, size_t count) {
  if (from + count > text.size()) return false;
  return std::all_of(text.begin() + from, text.begin() + from + count,
                     [](char c) { return c >= '0' && c <= '9'; });
}

// "HH:MM" or "HH:MM:SS" at the start of `time` (a real time of day); "HH:MM:SS" or "" when not.
std::string TimeOfDay(const std::string& time) {
  if (!AllDigits(time, 0, 2) || time.size() < 5 || time[2] != ':' || !AllDigits(time, 3, 2)) return "";
  std::string seconds = "00";
  if (time.size() > 5) {
    if (time[5] != ':' || !AllDigits(time, 6, 2)) return "";
    seconds = time.substr(6, 2);
    const std::string rest = time.substr(8);
    if (!rest.empty() && (rest[0] != '.' || rest.size() == 1 || !AllDigits(rest, 1, rest.size() - 1)))
      return "";
  }
  const int hour = std::stoi(time.substr(0, 2)), minute = std::stoi(time.substr(3, 2));
  const int second = std::stoi(seconds);
  // A leap second is 23:59:60 UTC; any other :60 is not a time (PyYAML refuses it in a timestamp).
  if (hour > 23 || minute > 59 || second > 60 || (second == 60 && (hour != 23 || minute != 59))) return "";
  return time.substr(0, 5) + ":" + seconds;
}

struct HeaderKey {
  const char* key;
  std::string RunHeader::*member;
};
const HeaderKey kHeaderKeys[] = {{"acquired:", &RunHeader::acquired_utc},
                                 {"model:", &RunHeader::model},
                                 {"firmware:", &RunHeader::firmware},
                                 {"ambient:", &RunHeader::ambient}};

}  // namespace

bool IsIsoDate(const std::string& text) {
  if (text.size() != 10 || text[4] != '-' || text[7] != '-') return false;
  if (!AllDigits(text, 0, 4) || !AllDigits(text, 5, 2) || !AllDigits(text, 8, 2)) return false;
  const int year = std::stoi(text.substr(0, 4)), month = std::stoi(text.substr(5, 2));
  const int day = std::stoi(text.substr(8, 2));
  constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month < 1 || month > 12 || day < 1) return false;
  return day <= kDays[month - 1] + (month == 2 && IsLeapYear(year) ? 1 : 0);
}

std::string NormalisedUtc(const std::string& text) {
  if (text.size() < 17 || !IsIsoDate(text.substr(0, 10)) || (text[10] != 'T' && text[10] != ' ')) return "";
  std::string time = text.substr(11);
  for (const char* utc : {"Z", "+00:00", "+0000"}) {
    const std::string suffix = utc;
    if (time.size() > suffix.size() &&
        time.compare(time.size() - suffix.size(), suffix.size(), suffix) == 0) {
      const std::string clock = TimeOfDay(time.substr(0, time.size() - suffix.size()));
      return clock.empty() ? "" : text.substr(0, 10) + "T" + clock + "Z";
    }
  }
  return "";
}

RunHeader RunHeaderOf(const std::string& path, const std::vector<CsvReader::Comment>& comments) {
  RunHeader header;
  for (const CsvReader::Comment& comment : comments) {
    for (const HeaderKey& key : kHeaderKeys) {
      const std::string name = key.key;
      if (comment.text.compare(0, name.size(), name) != 0) continue;
      const size_t first = comment.text.find_first_not_of(" \t", name.size());
      const long column = comment.column + static_cast<long>(std::min(first, comment.text.size()));
      const std::string what = name.substr(0, name.size() - 1);
      if (first == std::string::npos) throw InputError(path, comment.line, column, "an empty " + what);
      std::string found = comment.text.substr(first);
      if (std::any_of(found.begin(), found.end(),
                      [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
        throw InputError(path, comment.line, column, "the " + what + " holds a control character");
      }
      if (key.member == &RunHeader::acquired_utc) {
        const std::string utc = NormalisedUtc(found);
        if (utc.empty()) {
          throw InputError(
              path, comment.line, column,
              QuoteForMessage(found) + " is not a UTC time written as ISO 8601 (e.g. 2026-11-20T14:03:00Z)");
        }
        found = utc;
      }
      std::string& value = header.*key.member;
      if (!value.empty() && value != found) {
        throw InputError(
            path, comment.line, column,
            "a second " + what + " " + QuoteForMessage(found) + " after " + QuoteForMessage(value));
      }
      value = found;
    }
  }
  return header;
}

RunHeader ReadRunHeader(const std::string& path) {
  const CsvReader csv(path);
  return RunHeaderOf(path, csv.header_comments());
}

}  // namespace imufit
