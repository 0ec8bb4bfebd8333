#include "yaml_util.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <unordered_set>

#include <yaml-cpp/eventhandler.h>

#include <fcntl.h>
#include <unistd.h>

#include "imufit/io/error.h"

namespace imufit::yaml {

namespace {

// Refuses a key that appears twice in one mapping (yaml-cpp would keep the first silently) and
// nesting deeper than kMaxYamlDepth. Linear in the size of the tree.
void CheckTree(const std::string& path, const YAML::Node& node, int depth) {
  if (depth > kMaxYamlDepth) {
    throw InputError(path, node.Mark().line + 1, node.Mark().column + 1,
                     "nested deeper than " + std::to_string(kMaxYamlDepth) + " levels");
  }
  if (node.IsSequence()) {
    for (const YAML::Node& element : node) CheckTree(path, element, depth + 1);
  } else if (node.IsMap()) {
    std::unordered_set<std::string> keys;
    keys.reserve(node.size());
    for (const auto& entry : node) {
      if (!entry.first.IsScalar()) {
        throw InputError(path, entry.first.Mark().line + 1, entry.first.Mark().column + 1,
                         "a key must be a plain name, not a list or a mapping");
      }
      if (!keys.insert(entry.first.Scalar()).second) {
        throw InputError(path, entry.first.Mark().line + 1, entry.first.Mark().column + 1,
                         "key " + QuoteForMessage(entry.first.Scalar()) +
                             " appears twice in the same mapping (which one is meant?)");
      }
      CheckTree(path, entry.second, depth + 1);
    }
  }
}

// Records where each document starts; ignores the rest.
struct DocumentStarts : YAML::EventHandler {
  YAML::Mark last = YAML::Mark::null_mark();
  void OnDocumentStart(const YAML::Mark& mark) override { last = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
  }
  void OnMapEnd() override {}
};

}  // namespace

YAML::Node LoadFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  std::string text;
  char block[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, block, sizeof block);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      throw InputError(path, std::string("cannot read: ") + std::strerror(error));
    }
    if (n == 0) break;
    if (text.size() + static_cast<size_t>(n) > kMaxYamlBytes) {
      ::close(fd);
      throw InputError(path, "larger than " + std::to_string(kMaxYamlBytes >> 20) +
                                 " MiB (the limit of a YAML file): not an imufit YAML file?");
    }
    text.append(block, static_cast<size_t>(n));
  }
  ::close(fd);
  return LoadText(text, path);
}

YAML::Node LoadText(const std::string& text, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(text);  // the first document
    // A second document would be ignored: refuse it. Its events are only counted, not built
    // (YAML::LoadAll can loop forever on some malformed input).
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    DocumentStarts starts;
    parser.HandleNextDocument(starts);
    if (parser.HandleNextDocument(starts)) {
      throw InputError(path, starts.last.line >= 0 ? starts.last.line + 1 : 0, 0,
                       "a second YAML document: an imufit file holds exactly one (remove the `---` and what "
                       "follows)");
    }
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, e.mark.column + 1, "YAML syntax: " + e.msg);
  }
  CheckTree(path, root, 0);
  return root;
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
    const std::string& name = entry.first.Scalar();
    bool known = false;
    for (const char* a : allowed) known = known || name == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      Located{file, entry.first, key}.Fail("unknown key " + QuoteForMessage(name) + " (known: " + list + ")");
    }
  }
}

// A quoted scalar ("9.81", '1') or one tagged !!str is text, even when it reads as a number.
void Located::RefuseText(const char* expected) const {
  if (node.Tag() == "!" || node.Tag() == "tag:yaml.org,2002:str") {
    Fail(QuoteForMessage(node.Scalar()) + " is quoted text; " + expected + " is written without quotes");
  }
}

double Located::Double() const {
  if (!node.IsScalar()) Fail("expected a number");
  RefuseText("a number");
  const std::string& text = node.Scalar();
  double value = 0.0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '-' || *first == '+')) Fail(QuoteForMessage(text) + " is not a number");
  }
  const auto result = std::from_chars(first, last, value);
  if (result.ec != std::errc() || result.ptr != last || text.empty()) {
    Fail(QuoteForMessage(text) + " is not a number");
  }
  if (!std::isfinite(value)) Fail(QuoteForMessage(text) + " is not a finite number");
  return value;
}

long Located::Integer() const {
  if (!node.IsScalar()) Fail("expected an integer");
  RefuseText("an integer");
  const std::string& text = node.Scalar();
  long value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size() || text.empty()) {
    Fail(QuoteForMessage(text) + " is not an integer");
  }
  return value;
}

bool Located::Bool() const {
  if (!node.IsScalar()) Fail("expected true or false");
  RefuseText("true or false");
  bool value = false;
  if (!YAML::convert<bool>::decode(node, value))
    Fail(QuoteForMessage(node.Scalar()) + " is not true or false");
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
    (*this)["version"].Fail("version " + std::to_string(version) +
                            " is not supported (this imufit reads version " + std::to_string(max_version) +
                            ")");
  }
  return version;
}

}  // namespace imufit::yaml
