// imufit — the one writer of machine-readable text: a document built once as a tree of typed
// values (MachineDoc) and written as YAML or as JSON, so that every file imufit writes for a
// program (calibration, noise YAML, plan, plan check, the JSON and Kalibr exports) quotes and
// formats alike, and both syntaxes say the same.
//
// What a reader gets back is the type the document holds, whichever reader it is:
//  - numbers are numbers to YAML 1.1 (PyYAML's safe_load, Kalibr), YAML 1.2 (yaml-cpp) and JSON:
//    the shortest text that reads back as exactly the double, with ".0" added to a mantissa
//    without a point ("2.0e-06": YAML 1.1 reads "2e-06" as a string) and -0 as "-0.0" (YAML
//    reads "-0" as the integer 0). Not finite: .nan, .inf, -.inf in YAML, null in JSON.
//  - booleans are true and false, null is null.
//  - text is written plain only when no YAML 1.1 or 1.2 reader resolves it to anything else
//    (YamlPlainSafe: a letter, _ or / first, then letters, digits, spaces and _ . / + - ^ ( ) *,
//    no space last, and not a word such as yes, on, null or nan); otherwise double-quoted. Both
//    syntaxes escape what is not printable (control characters, DEL, C1 controls, U+2028/9,
//    U+FFFE/F) as \uXXXX (\n, \t, \r as such), and a byte that is not part of valid UTF-8 as the
//    code point of the same value (a Latin-1 byte 0xE9 becomes U+00E9, "é"): the text written is
//    always valid UTF-8.
//
// Styles: a list or map is written on one line (kFlow) or one item per line (kBlock), in YAML and
// in JSON alike. Comments (YAML only; JSON has none) go before an entry or after it on its line.
#ifndef IMUFIT_IO_MACHINE_TEXT_H_
#define IMUFIT_IO_MACHINE_TEXT_H_

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace imufit {

class MachineDoc {
 public:
  enum class Kind { kNull, kNumber, kInteger, kBool, kText, kList, kMap };
  enum class Style { kFlow, kBlock };

  // A map's key, with its comments (its value is the item of the same index).
  struct Key {
    std::string name;
    std::vector<std::string> comments_before;  // whole lines, without "# "
    std::string comment;                       // after the value, on its line ("" = none)
  };

  MachineDoc() = default;  // null
  static MachineDoc Null() { return MachineDoc(); }
  static MachineDoc Number(double value);
  static MachineDoc Integer(long long value);
  static MachineDoc Bool(bool value);
  static MachineDoc Text(std::string value);
  static MachineDoc List(Style style = Style::kFlow);
  static MachineDoc Map(Style style = Style::kBlock);
  static MachineDoc Numbers(const std::vector<double>& values, Style style = Style::kFlow);
  static MachineDoc Integers(const std::vector<int>& values, Style style = Style::kFlow);
  static MachineDoc Texts(const std::vector<std::string>& values, Style style = Style::kFlow);

  // A map's entry, after the others; `comment` goes after it on its line (YAML). The lines given
  // to Comment() since the last Add() are written before it.
  MachineDoc& Add(std::string key, MachineDoc value, std::string comment = "");
  // A comment line before the next entry of this map (at its end when none follows).
  MachineDoc& Comment(std::string line);
  // Comment lines before the first entry of this map, before those it has (a file's header).
  MachineDoc& CommentFirst(const std::vector<std::string>& lines);
  // A list's item, after the others.
  MachineDoc& Push(MachineDoc value);
  // The entry of a map named `key`, or nullptr; removes it (false when there is none).
  const MachineDoc* Find(const std::string& key) const;
  bool Remove(const std::string& key);

  Kind kind() const { return kind_; }
  Style style() const { return style_; }
  double number() const { return number_; }
  long long integer() const { return integer_; }
  bool flag() const { return flag_; }
  const std::string& text() const { return text_; }
  // A list's items, or a map's values; a map's keys, one per value.
  const std::vector<MachineDoc>& items() const { return items_; }
  const std::vector<Key>& keys() const { return keys_; }
  const std::vector<std::string>& trailing_comments() const { return pending_comments_; }
  bool IsScalar() const { return kind_ != Kind::kList && kind_ != Kind::kMap; }

 private:
  explicit MachineDoc(Kind kind, Style style = Style::kFlow);

  Kind kind_ = Kind::kNull;
  Style style_ = Style::kFlow;
  double number_ = 0.0;
  long long integer_ = 0;
  bool flag_ = false;
  std::string text_;
  std::vector<MachineDoc> items_;
  std::vector<Key> keys_;
  std::vector<std::string> pending_comments_;
};

// The document as YAML (a map: one key a line at the top level) and as JSON; both end with "\n".
std::string YamlText(const MachineDoc& doc);
std::string JsonText(const MachineDoc& doc);

// The pieces, for a writer that must place one value itself.
std::string YamlNumberText(double value);           // "2.0e-06", ".nan"
std::string JsonNumberText(double value);           // "2.0e-06", "null"
std::string YamlStringText(std::string_view text);  // plain when safe, else double-quoted
std::string JsonStringText(std::string_view text);  // always double-quoted
// Whether `text` reads back as this same string when written as a plain YAML scalar, to YAML 1.1
// and 1.2 readers alike (see above).
bool YamlPlainSafe(std::string_view text);
// `text` as valid UTF-8: a byte that is not part of a valid sequence becomes the code point of the
// same value (Latin-1's reading of it).
std::string ValidUtf8(std::string_view text);

// A YAML tree read from a file (a calibration's further keys) as a document: a plain scalar that
// YAML 1.2's core schema resolves to a number, true/false or null becomes one (numbers by value:
// read back bit for bit), every other scalar text (quoted ones always); styles as read (a list
// of scalars on one line, maps one key a line).
MachineDoc MachineDocOfYaml(const YAML::Node& node);

}  // namespace imufit

#endif  // IMUFIT_IO_MACHINE_TEXT_H_
