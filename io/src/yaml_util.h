// Helpers for reading YAML files with errors located at file:line:column and key path.
#ifndef IMUFIT_IO_SRC_YAML_UTIL_H_
#define IMUFIT_IO_SRC_YAML_UTIL_H_

#include <initializer_list>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace imufit::yaml {

// Input limits of a YAML file (docs/conventions.md).
inline constexpr size_t kMaxYamlBytes = 16 << 20;
inline constexpr int kMaxYamlDepth = 64;

// Parses `path`; throws InputError located where the YAML syntax is broken. Also refused: a
// file over kMaxYamlBytes, more than one document, a key repeated in one mapping, nesting
// deeper than kMaxYamlDepth.
YAML::Node LoadFile(const std::string& path);
// The same of `text`, which messages name `path`.
YAML::Node LoadText(const std::string& text, const std::string& path);

// A node with the file and the dotted key path it was reached by, for error messages.
struct Located {
  const std::string* file;
  YAML::Node node;
  std::string key;  // e.g. "segments[3].up"

  [[noreturn]] void Fail(const std::string& message) const;
  bool Has(const std::string& name) const;
  Located operator[](const std::string& name) const;  // required map key
  Located At(size_t index) const;                     // sequence element
  size_t Size() const;                                // sequence length; fails if not one
  void RequireMap() const;
  // Fails on any key not in `allowed`.
  void RejectUnknownKeys(std::initializer_list<const char*> allowed) const;
  double Double() const;
  long Integer() const;
  bool Bool() const;  // true or false (YAML's other spellings of them too)
  std::string String() const;
  std::vector<double> Doubles(size_t count) const;  // a sequence of exactly `count` numbers
  // Checks the `format` and `version` keys of a versioned imufit file; returns the version.
  long RequireFormat(const std::string& format, long max_version) const;

 private:
  void RefuseText(const char* expected) const;
};

}  // namespace imufit::yaml

#endif  // IMUFIT_IO_SRC_YAML_UTIL_H_
