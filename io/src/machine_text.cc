#include "imufit/io/machine_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include "imufit/model/check.h"

namespace imufit {
namespace {

// ---------------------------------------------------------------- text

// The code points of `text`, a byte outside a valid UTF-8 sequence taken as the code point of
// its value (Latin-1).
template <typename Visit>
void ForEachCodePoint(std::string_view text, Visit&& visit) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(text[i]); };
  const auto continuation = [&](size_t i) { return i < text.size() && (byte(i) & 0xC0) == 0x80; };
  for (size_t i = 0; i < text.size();) {
    const unsigned char b = byte(i);
    int length = 0;
    char32_t cp = 0;
    if (b < 0x80) {
      length = 1;
      cp = b;
    } else if (b >= 0xC2 && b < 0xE0 && continuation(i + 1)) {
      length = 2;
      cp = (b & 0x1Fu) << 6 | (byte(i + 1) & 0x3Fu);
    } else if (b >= 0xE0 && b < 0xF0 && continuation(i + 1) && continuation(i + 2)) {
      cp = (b & 0x0Fu) << 12 | (byte(i + 1) & 0x3Fu) << 6 | (byte(i + 2) & 0x3Fu);
      if (cp >= 0x800 && (cp < 0xD800 || cp > 0xDFFF)) length = 3;  // not overlong, not a surrogate
    } else if (b >= 0xF0 && b < 0xF5 && continuation(i + 1) && continuation(i + 2) && continuation(i + 3)) {
      cp = (b & 0x07u) << 18 | (byte(i + 1) & 0x3Fu) << 12 | (byte(i + 2) & 0x3Fu) << 6 |
           (byte(i + 3) & 0x3Fu);
      if (cp >= 0x10000 && cp <= 0x10FFFF) length = 4;
    }
    if (length == 0) {  // not valid UTF-8: the byte's Latin-1 reading
      length = 1;
      cp = b;
    }
    visit(cp);
    i += static_cast<size_t>(length);
  }
}

void AppendUtf8(char32_t cp, std::string* out) {
  if (cp < 0x80) {
    *out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    *out += static_cast<char>(0xC0 | (cp >> 6));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    *out += static_cast<char>(0xE0 | (cp >> 12));
    *out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    *out += static_cast<char>(0xF0 | (cp >> 18));
    *out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    *out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    *out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// What YAML 1.1 (PyYAML) refuses raw or reads as a line break, and JSON's control characters.
bool Printable(char32_t cp) {
  if (cp < 0x20 || cp == 0x7F) return false;
  if (cp >= 0x80 && cp < 0xA0) return false;  // C1 controls, NEL
  if (cp == 0x2028 || cp == 0x2029 || cp == 0xFFFE || cp == 0xFFFF) return false;
  return true;
}

// Double-quoted for YAML and JSON alike: both read \" \\ \uXXXX.
std::string DoubleQuoted(std::string_view text) {
  std::string out = "\"";
  ForEachCodePoint(text, [&out](char32_t cp) {
    if (cp == '"' || cp == '\\') {
      out += '\\';
      out += static_cast<char>(cp);
    } else if (cp == '\n' || cp == '\t' || cp == '\r') {
      out += cp == '\n' ? "\\n" : cp == '\t' ? "\\t" : "\\r";
    } else if (!Printable(cp)) {
      char escape[16];  // "\u" and 4 hex digits: every code point Printable() refuses is below U+10000
      std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(cp));
      out += escape;
    } else {
      AppendUtf8(cp, &out);
    }
  });
  return out + "\"";
}

// A comment's text: one line, printable, valid UTF-8.
std::string CommentText(std::string_view text) {
  std::string out;
  ForEachCodePoint(text, [&out](char32_t cp) {
    if (Printable(cp)) {
      AppendUtf8(cp, &out);
    } else {
      out += '?';
    }
  });
  return out;
}

bool PlainChar(char c, bool first) {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '/') return true;
  if (first) return false;
  if (c >= '0' && c <= '9') return true;
  switch (c) {
    case '.':
    case '+':
    case '-':
    case '^':
    case '(':
    case ')':
    case '*':
      return true;
    default:
      return false;
  }
}

bool EqualsIgnoringCase(std::string_view a, const char* b) {
  size_t i = 0;
  for (; i < a.size() && b[i] != '\0'; ++i) {
    char c = a[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != b[i]) return false;
  }
  return i == a.size() && b[i] == '\0';
}

// ---------------------------------------------------------------- numbers

std::string FiniteNumberText(double value) {
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  std::string text(digits, result.ptr);
  if (text.find_first_of(".e") == std::string::npos) return text == "-0" ? "-0.0" : text;
  const size_t e = text.find('e');
  if (e != std::string::npos && text.find('.') == std::string::npos) text.insert(e, ".0");
  return text;
}

// ---------------------------------------------------------------- writing

std::string FlowText(const MachineDoc& doc, bool json) {
  switch (doc.kind()) {
    case MachineDoc::Kind::kNull:
      return "null";
    case MachineDoc::Kind::kNumber:
      return json ? JsonNumberText(doc.number()) : YamlNumberText(doc.number());
    case MachineDoc::Kind::kInteger:
      return std::to_string(doc.integer());
    case MachineDoc::Kind::kBool:
      return doc.flag() ? "true" : "false";
    case MachineDoc::Kind::kText:
      return json ? JsonStringText(doc.text()) : YamlStringText(doc.text());
    case MachineDoc::Kind::kList: {
      std::string out = "[";
      for (size_t i = 0; i < doc.items().size(); ++i) out += (i ? ", " : "") + FlowText(doc.items()[i], json);
      return out + "]";
    }
    case MachineDoc::Kind::kMap:
      break;
  }
  std::string out = "{";
  for (size_t i = 0; i < doc.items().size(); ++i) {
    const std::string& key = doc.keys()[i].name;
    out += (i ? ", " : "") + (json ? JsonStringText(key) : YamlStringText(key)) + ": " +
           FlowText(doc.items()[i], json);
  }
  return out + "}";
}

bool Expanded(const MachineDoc& doc) {
  return (doc.kind() == MachineDoc::Kind::kMap || doc.kind() == MachineDoc::Kind::kList) &&
         doc.style() == MachineDoc::Style::kBlock && !doc.items().empty();
}

void AppendCommentLines(const std::vector<std::string>& lines, const std::string& indent, std::string* out) {
  for (const std::string& line : lines) *out += indent + "# " + CommentText(line) + "\n";
}

// "  # first line\n", further lines of `comment` each on a line of its own at `indent`.
std::string LineEnd(const std::string& comment, const std::string& indent) {
  if (comment.empty()) return "\n";
  std::string out;
  size_t start = 0;
  bool first = true;
  while (start <= comment.size()) {
    const size_t end = std::min(comment.find('\n', start), comment.size());
    const std::string line = CommentText(comment.substr(start, end - start));
    out += (first ? "  # " : indent + "# ") + line + "\n";
    first = false;
    start = end + 1;
  }
  return out;
}

void AppendYamlMap(const MachineDoc& map, const std::string& indent, const std::string& first_prefix,
                   std::string* out);

void AppendYamlList(const MachineDoc& list, const std::string& indent, std::string* out) {
  for (const MachineDoc& item : list.items()) {
    if (item.kind() == MachineDoc::Kind::kMap && Expanded(item)) {
      AppendYamlMap(item, indent + "  ", indent + "- ", out);
    } else {
      *out += indent + "- " + FlowText(item, false) + "\n";  // a list in a list: on one line
    }
  }
}

// The entries of `map` one a line at `indent`; the first line starts with `first_prefix` when it
// is not empty (a list's "- ").
void AppendYamlMap(const MachineDoc& map, const std::string& indent, const std::string& first_prefix,
                   std::string* out) {
  for (size_t i = 0; i < map.items().size(); ++i) {
    const MachineDoc::Key& key = map.keys()[i];
    const MachineDoc& value = map.items()[i];
    AppendCommentLines(key.comments_before, indent, out);
    *out += (i == 0 && !first_prefix.empty() ? first_prefix : indent) + YamlStringText(key.name) + ":";
    if (Expanded(value)) {
      *out += LineEnd(key.comment, indent + "  ");
      if (value.kind() == MachineDoc::Kind::kMap) {
        AppendYamlMap(value, indent + "  ", "", out);
      } else {
        AppendYamlList(value, indent + "  ", out);
      }
    } else {
      *out += " " + FlowText(value, false) + LineEnd(key.comment, indent);
    }
  }
  AppendCommentLines(map.trailing_comments(), indent, out);
}

void AppendJson(const MachineDoc& doc, const std::string& indent, std::string* out) {
  if (!Expanded(doc)) {
    *out += FlowText(doc, true);
    return;
  }
  const bool map = doc.kind() == MachineDoc::Kind::kMap;
  *out += map ? "{" : "[";
  for (size_t i = 0; i < doc.items().size(); ++i) {
    *out += (i ? ",\n" : "\n") + indent + "  ";
    if (map) *out += JsonStringText(doc.keys()[i].name) + ": ";
    AppendJson(doc.items()[i], indent + "  ", out);
  }
  *out += "\n" + indent + (map ? "}" : "]");
}

// ---------------------------------------------------------------- reading a YAML tree

bool AllDigits(std::string_view text, size_t from) {
  if (from >= text.size()) return false;
  for (size_t i = from; i < text.size(); ++i) {
    if (text[i] < '0' || text[i] > '9') return false;
  }
  return true;
}

// YAML 1.2 core schema's float: [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?
bool CoreFloat(std::string_view text) {
  size_t i = 0;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
  size_t digits = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    size_t fraction = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++fraction;
    if (digits == 0 && fraction == 0) return false;
  } else if (digits == 0) {
    return false;
  }
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
    return AllDigits(text, i);
  }
  return i == text.size();
}

MachineDoc PlainScalar(const std::string& text) {
  if (text.empty() || text == "~" || text == "null" || text == "Null" || text == "NULL") return MachineDoc();
  if (text == "true" || text == "True" || text == "TRUE") return MachineDoc::Bool(true);
  if (text == "false" || text == "False" || text == "FALSE") return MachineDoc::Bool(false);
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    return MachineDoc::Number(std::numeric_limits<double>::quiet_NaN());
  }
  const bool negative = text[0] == '-';
  const std::string_view unsigned_text =
      std::string_view(text).substr(text[0] == '-' || text[0] == '+' ? 1 : 0);
  if (unsigned_text == ".inf" || unsigned_text == ".Inf" || unsigned_text == ".INF") {
    return MachineDoc::Number(negative ? -std::numeric_limits<double>::infinity()
                                       : std::numeric_limits<double>::infinity());
  }
  const char* first = text.data() + (text[0] == '+' ? 1 : 0);
  const char* last = text.data() + text.size();
  if (AllDigits(unsigned_text, 0)) {
    long long value = 0;
    const auto parsed = std::from_chars(first, last, value);
    if (parsed.ec == std::errc() && parsed.ptr == last) return MachineDoc::Integer(value);
  }
  if (CoreFloat(text)) {
    double value = 0.0;
    const auto parsed = std::from_chars(first, last, value);
    if (parsed.ec == std::errc() && parsed.ptr == last) return MachineDoc::Number(value);
  }
  const auto prefixed = [&](const char* prefix, int base) -> std::optional<long long> {
    if (text.size() <= 2 || text.compare(0, 2, prefix) != 0) return std::nullopt;
    long long value = 0;
    const auto parsed = std::from_chars(text.data() + 2, last, value, base);
    if (parsed.ec != std::errc() || parsed.ptr != last) return std::nullopt;
    return value;
  };
  if (const auto octal = prefixed("0o", 8)) return MachineDoc::Integer(*octal);
  if (const auto hex = prefixed("0x", 16)) return MachineDoc::Integer(*hex);
  return MachineDoc::Text(text);
}

}  // namespace

// ---------------------------------------------------------------- MachineDoc

MachineDoc::MachineDoc(Kind kind, Style style) : kind_(kind), style_(style) {}

MachineDoc MachineDoc::Number(double value) {
  MachineDoc doc(Kind::kNumber);
  doc.number_ = value;
  return doc;
}

MachineDoc MachineDoc::Integer(long long value) {
  MachineDoc doc(Kind::kInteger);
  doc.integer_ = value;
  return doc;
}

MachineDoc MachineDoc::Bool(bool value) {
  MachineDoc doc(Kind::kBool);
  doc.flag_ = value;
  return doc;
}

MachineDoc MachineDoc::Text(std::string value) {
  MachineDoc doc(Kind::kText);
  doc.text_ = std::move(value);
  return doc;
}

MachineDoc MachineDoc::List(Style style) { return MachineDoc(Kind::kList, style); }

MachineDoc MachineDoc::Map(Style style) { return MachineDoc(Kind::kMap, style); }

MachineDoc MachineDoc::Numbers(const std::vector<double>& values, Style style) {
  MachineDoc doc = List(style);
  for (const double value : values) doc.Push(Number(value));
  return doc;
}

MachineDoc MachineDoc::Integers(const std::vector<int>& values, Style style) {
  MachineDoc doc = List(style);
  for (const int value : values) doc.Push(Integer(value));
  return doc;
}

MachineDoc MachineDoc::Texts(const std::vector<std::string>& values, Style style) {
  MachineDoc doc = List(style);
  for (const std::string& value : values) doc.Push(Text(value));
  return doc;
}

MachineDoc& MachineDoc::Add(std::string key, MachineDoc value, std::string comment) {
  IMUFIT_CHECK(kind_ == Kind::kMap, "Add() is for a map");
  keys_.push_back(Key{std::move(key), std::move(pending_comments_), std::move(comment)});
  pending_comments_.clear();
  items_.push_back(std::move(value));
  return *this;
}

MachineDoc& MachineDoc::Comment(std::string line) {
  IMUFIT_CHECK(kind_ == Kind::kMap, "comments are a map's");
  pending_comments_.push_back(std::move(line));
  return *this;
}

MachineDoc& MachineDoc::CommentFirst(const std::vector<std::string>& lines) {
  IMUFIT_CHECK(kind_ == Kind::kMap, "comments are a map's");
  std::vector<std::string>& before = keys_.empty() ? pending_comments_ : keys_.front().comments_before;
  before.insert(before.begin(), lines.begin(), lines.end());
  return *this;
}

MachineDoc& MachineDoc::Push(MachineDoc value) {
  IMUFIT_CHECK(kind_ == Kind::kList, "Push() is for a list");
  items_.push_back(std::move(value));
  return *this;
}

const MachineDoc* MachineDoc::Find(const std::string& key) const {
  for (size_t i = 0; i < keys_.size(); ++i) {
    if (keys_[i].name == key) return &items_[i];
  }
  return nullptr;
}

bool MachineDoc::Remove(const std::string& key) {
  for (size_t i = 0; i < keys_.size(); ++i) {
    if (keys_[i].name == key) {
      keys_.erase(keys_.begin() + static_cast<std::ptrdiff_t>(i));
      items_.erase(items_.begin() + static_cast<std::ptrdiff_t>(i));
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------- text

std::string YamlNumberText(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  return FiniteNumberText(value);
}

std::string JsonNumberText(double value) { return std::isfinite(value) ? FiniteNumberText(value) : "null"; }

bool YamlPlainSafe(std::string_view text) {
  if (text.empty() || text.back() == ' ') return false;
  for (size_t i = 0; i < text.size(); ++i) {
    if (!PlainChar(text[i], i == 0) && !(text[i] == ' ' && i > 0)) return false;
  }
  for (const char* word :
       {"y", "n", "yes", "no", "on", "off", "true", "false", "null", "nan", "inf", "infinity"}) {
    if (EqualsIgnoringCase(text, word)) return false;
  }
  return true;
}

std::string YamlStringText(std::string_view text) {
  return YamlPlainSafe(text) ? std::string(text) : DoubleQuoted(text);
}

std::string JsonStringText(std::string_view text) { return DoubleQuoted(text); }

std::string ValidUtf8(std::string_view text) {
  std::string out;
  ForEachCodePoint(text, [&out](char32_t cp) { AppendUtf8(cp, &out); });
  return out;
}

std::string YamlText(const MachineDoc& doc) {
  std::string out;
  if (doc.kind() == MachineDoc::Kind::kMap) {
    if (Expanded(doc)) {
      AppendYamlMap(doc, "", "", &out);
    } else {
      AppendCommentLines(doc.trailing_comments(), "", &out);
      out += FlowText(doc, false) + "\n";
    }
  } else if (Expanded(doc)) {
    AppendYamlList(doc, "", &out);
  } else {
    out += FlowText(doc, false) + "\n";
  }
  return out;
}

std::string JsonText(const MachineDoc& doc) {
  std::string out;
  AppendJson(doc, "", &out);
  return out + "\n";
}

MachineDoc MachineDocOfYaml(const YAML::Node& node) {
  if (!node || node.IsNull()) return MachineDoc();
  if (node.IsScalar())
    return node.Tag() == "?" ? PlainScalar(node.Scalar()) : MachineDoc::Text(node.Scalar());
  if (node.IsSequence()) {
    bool scalars = true;
    for (const YAML::Node& item : node) scalars = scalars && item.IsScalar();
    const bool flow =
        node.Style() == YAML::EmitterStyle::Flow || (node.Style() != YAML::EmitterStyle::Block && scalars);
    MachineDoc list = MachineDoc::List(flow ? MachineDoc::Style::kFlow : MachineDoc::Style::kBlock);
    for (const YAML::Node& item : node) list.Push(MachineDocOfYaml(item));
    return list;
  }
  MachineDoc map = MachineDoc::Map(node.Style() == YAML::EmitterStyle::Flow ? MachineDoc::Style::kFlow
                                                                            : MachineDoc::Style::kBlock);
  for (const auto& entry : node) map.Add(entry.first.Scalar(), MachineDocOfYaml(entry.second));
  return map;
}

}  // namespace imufit
