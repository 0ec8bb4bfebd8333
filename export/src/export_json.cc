// --format json: the whole calibration in JSON for web and production-database consumers.
//
// The calibration file's own tree (docs/spec.md section 3: the coefficients, the sigma tree, the
// fit and noise blocks) written as JSON, so that ReadCalibration (a YAML 1.2 reader: JSON is YAML)
// reads it back bit for bit, with one key added: `export`, the provenance. Every number is written
// in its shortest round-trip form; a non-finite figure of the fit or noise blocks (YAML's .nan,
// .inf) is written as null: JSON has no such numbers. Schema: docs/calibration.schema.json.
#include <charconv>
#include <cmath>
#include <cstdio>

#include <yaml-cpp/yaml.h>

#include "export_internal.h"
#include "imufit/io/output_file.h"
#include "imufit/model/check.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer = "JSON (docs/calibration.schema.json)";

std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned char>(c));
      out += escape;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A plain (unquoted) YAML scalar as JSON: a number when it is one (in its shortest round-trip
// form), true, false, null; otherwise a string. Quoted scalars are always strings.
std::string JsonScalar(const YAML::Node& node) {
  const std::string& text = node.Scalar();
  if (node.Tag() != "?") return JsonString(text);
  if (text == "true" || text == "false" || text == "null") return text;
  if (text.empty() || text == "~") return "null";
  if (text == ".nan" || text == ".NaN" || text == ".inf" || text == "-.inf" || text == "+.inf" ||
      text == ".Inf" || text == "-.Inf") {
    return "null";
  }
  if (text.find_first_not_of("0123456789+-.eE") == std::string::npos) {
    const char* first = text.data() + (text[0] == '+' ? 1 : 0);
    double value = 0.0;
    const auto parsed = std::from_chars(first, text.data() + text.size(), value);
    if (parsed.ec == std::errc() && parsed.ptr == text.data() + text.size()) {
      return std::isfinite(value) ? FormatDouble(value) : "null";
    }
  }
  return JsonString(text);
}

bool AllScalars(const YAML::Node& sequence) {
  for (const YAML::Node& element : sequence) {
    if (!element.IsScalar()) return false;
  }
  return true;
}

void AppendJson(const YAML::Node& node, const std::string& indent, std::string* out) {
  if (node.IsMap()) {
    *out += "{";
    bool first = true;
    for (const auto& entry : node) {
      *out += (first ? "\n" : ",\n") + indent + "  " + JsonString(entry.first.Scalar()) + ": ";
      AppendJson(entry.second, indent + "  ", out);
      first = false;
    }
    *out += first ? "}" : "\n" + indent + "}";
  } else if (node.IsSequence()) {
    if (AllScalars(node)) {
      *out += "[";
      for (size_t i = 0; i < node.size(); ++i) *out += (i ? ", " : "") + JsonScalar(node[i]);
      *out += "]";
      return;
    }
    *out += "[";
    for (size_t i = 0; i < node.size(); ++i) {
      *out += (i ? ",\n" : "\n") + indent + "  ";
      AppendJson(node[i], indent + "  ", out);
    }
    *out += node.size() ? "\n" + indent + "]" : "]";
  } else if (node.IsScalar()) {
    *out += JsonScalar(node);
  } else {
    *out += "null";
  }
}

}  // namespace

ExportResult ExportJson(const Calibration& calibration, const ExportOptions& options) {
  ExportResult result;
  result.consumer = kConsumer;
  YAML::Node root = CalibrationTree(calibration);
  root.remove("export");  // a calibration read back from a JSON export: its provenance is replaced
  const std::vector<std::string> lines = ProvenanceLines(calibration, options, result);
  std::string out;
  AppendJson(root, "", &out);
  std::string export_block = ",\n  \"export\": {\n    \"software\": " + JsonString(options.software) +
                             ",\n    \"calibration_file\": " + JsonString(CalibrationFileName(options)) +
                             ",\n    \"calibration_sha256\": " + JsonString(options.calibration_sha256) +
                             ",\n    \"provenance\": [";
  for (size_t i = 0; i < lines.size(); ++i)
    export_block += (i ? ",\n      " : "\n      ") + JsonString(lines[i]);
  export_block += "\n    ]\n  }\n}";
  IMUFIT_CHECK(out.size() >= 2 && out.substr(out.size() - 2) == "\n}", "the calibration is a JSON object");
  result.content = out.substr(0, out.size() - 2) + export_block + "\n";
  return result;
}

}  // namespace imufit::export_internal
