#include "yaml_util.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "imufit/io/error.h"

namespace imufit::yaml {

YAML::Node LoadFile(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  std::stringstream text;
  text << stream.rdbuf();
  try {
    return YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, e.mark.column + 1, "YAML syntax: " + e.msg);
  }
}

void Located::Fail(const std::string& message) const {
  const YAML::Mark mark = node.Mark();
  const bool known = mark.line >= 0 && !node.IsNull();
  throw InputError(*file, known ? mark.line + 1 : 0, known ? mark.column + 1 : 0,
                   (key.empty() ? "" : key + ": ") + message);
}

bool Located::Has(const std::string& name) const {
  return node.IsMap() && node[name] && !node[name].IsNull();
}

Located Located::operator[](const std::string& name) const {
  RequireMap();
  const std::string path = key.empty() ? name : key + "." + name;
  if (!node[name] || node[name].IsNull()) {
    throw InputError(*file, node.Mark().line + 1, 0, path + ": missing (required)");
  }
  return Located{file, node[name], path};
}

Located Located::At(size_t index) const {
  return Located{file, node[index], key + "[" + std::to_string(index) + "]"};
}

size_t Located::Size() const {
  if (!node.IsSequence()) Fail("expected a list");
  return node.size();
}

void Located::RequireMap() const {
  if (!node.IsMap()) Fail("expected a mapping of keys to values");
}

void Located::RejectUnknownKeys(std::initializer_list<const char*> allowed) const {
  RequireMap();
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    bool known = false;
    std::string list;
    for (const char* a : allowed) {
      known = known || name == a;
      list += (list.empty() ? "" : ", ") + std::string(a);
    }
    if (!known) {
      Located{file, entry.first, key}.Fail("unknown key " + QuoteForMessage(name) + " (known: " + list + ")");
    }
  }
}

double Located::Double() const {
  if (!node.IsScalar()) Fail("expected a number");
  const std::string& text = node.Scalar();
  double value = 0.0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+') ++first;
  const auto result = std::from_chars(first, last, value);
  if (result.ec != std::errc() || result.ptr != last || text.empty()) {
    Fail(QuoteForMessage(text) + " is not a number");
  }
  if (!std::isfinite(value)) Fail(QuoteForMessage(text) + " is not a finite number");
  return value;
}

long Located::Integer() const {
  if (!node.IsScalar()) Fail("expected an integer");
  const std::string& text = node.Scalar();
  long value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size() || text.empty()) {
    Fail(QuoteForMessage(text) + " is not an integer");
  }
  return value;
}

std::string Located::String() const {
  if (!node.IsScalar()) Fail("expected a text value");
  return node.Scalar();
}

std::vector<double> Located::Doubles(size_t count) const {
  if (!node.IsSequence() || node.size() != count) {
    Fail("expected a list of exactly " + std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (size_t i = 0; i < count; ++i) values.push_back(At(i).Double());
  return values;
}

long Located::RequireFormat(const std::string& format, long max_version) const {
  if ((*this)["format"].String() != format) {
    (*this)["format"].Fail(QuoteForMessage((*this)["format"].String()) + " is not \"" + format + "\"");
  }
  const long version = (*this)["version"].Integer();
  if (version < 1 || version > max_version) {
    (*this)["version"].Fail("version " + std::to_string(version) + " is not supported (this imufit reads version " +
                            std::to_string(max_version) + ")");
  }
  return version;
}

}  // namespace imufit::yaml
