// `imufit plan check`'s outputs (plan_check.h): a table for people, YAML or JSON for machines.
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "imufit/model/check.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"

namespace imufit {
namespace {

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char text[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  return text;
}

std::string Ids(const std::vector<int>& ids) {
  std::string text;
  for (int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text.empty() ? "none" : text;
}

// The machines' document, built once and written as YAML or as JSON, so that both say the same.
struct Doc {
  enum class Kind { kNumber, kBool, kText, kList, kMap } kind = Kind::kMap;
  double number = 0.0;
  bool flag = false;
  std::string text;
  std::vector<Doc> list;
  std::vector<std::pair<std::string, Doc>> map;

  static Doc Number(double value) {
    IMUFIT_CHECK(std::isfinite(value), "a plan check figure is finite");
    Doc d;
    d.kind = Kind::kNumber;
    d.number = value;
    return d;
  }
  static Doc Bool(bool value) {
    Doc d;
    d.kind = Kind::kBool;
    d.flag = value;
    return d;
  }
  static Doc Text(std::string value) {
    Doc d;
    d.kind = Kind::kText;
    d.text = std::move(value);
    return d;
  }
  static Doc List() {
    Doc d;
    d.kind = Kind::kList;
    return d;
  }
  static Doc Numbers(const std::vector<double>& values) {
    Doc d = List();
    for (double v : values) d.list.push_back(Number(v));
    return d;
  }
  static Doc Texts(const std::vector<std::string>& values) {
    Doc d = List();
    for (const std::string& v : values) d.list.push_back(Text(v));
    return d;
  }
  Doc& Add(const std::string& key, Doc value) {
    map.emplace_back(key, std::move(value));
    return *this;
  }
};

// A string quoted for YAML's double-quoted style and JSON alike (both read \" \\ \uXXXX).
std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += Format("\\u%04x", static_cast<unsigned>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// One line of flow style: {a: 1, b: "x"} in YAML, {"a": 1, "b": "x"} in JSON.
std::string Flow(const Doc& d, bool json) {
  switch (d.kind) {
    case Doc::Kind::kNumber:
      return Format("%.9g", d.number);
    case Doc::Kind::kBool:
      return d.flag ? "true" : "false";
    case Doc::Kind::kText:
      return Quoted(d.text);
    case Doc::Kind::kList: {
      std::string out;
      for (const Doc& e : d.list) out += (out.empty() ? "" : ", ") + Flow(e, json);
      return "[" + out + "]";
    }
    case Doc::Kind::kMap:
      break;
  }
  std::string out;
  for (const auto& [key, value] : d.map) {
    out += (out.empty() ? "" : ", ") + (json ? Quoted(key) : key) + ": " + Flow(value, json);
  }
  return "{" + out + "}";
}

// A list of maps or texts one element a line; everything else on the key's line.
bool OneALine(const Doc& d) {
  return d.kind == Doc::Kind::kList && !d.list.empty() && d.list.front().kind != Doc::Kind::kNumber;
}

std::string YamlOf(const Doc& top) {
  std::string out;
  for (const auto& [key, value] : top.map) {
    if (!OneALine(value)) {
      out += key + ": " + Flow(value, false) + "\n";
      continue;
    }
    out += key + ":\n";
    for (const Doc& e : value.list) out += "  - " + Flow(e, false) + "\n";
  }
  return out;
}

std::string JsonOf(const Doc& top) {
  std::string out = "{";
  for (size_t i = 0; i < top.map.size(); ++i) {
    const auto& [key, value] = top.map[i];
    out += std::string(i == 0 ? "\n" : ",\n") + "  " + Quoted(key) + ": ";
    if (!OneALine(value)) {
      out += Flow(value, true);
      continue;
    }
    out += "[";
    for (size_t j = 0; j < value.list.size(); ++j) {
      out += std::string(j == 0 ? "\n" : ",\n") + "    " + Flow(value.list[j], true);
    }
    out += "\n  ]";
  }
  return out + "\n}\n";
}

Doc PlanCheckDoc(const PlanCheck& check) {
  Doc doc;
  doc.Add("format", Doc::Text("imufit-plan-check")).Add("version", Doc::Number(1));
  doc.Add("undetermined", Doc::Texts(check.undetermined));
  if (!check.undetermined.empty()) return doc;
  doc.Add("plan_hours", Doc::Number(check.plan_hours)).Add("needed_hours", Doc::Number(check.needed_hours));
  doc.Add("plan_range_c", Doc::Numbers({check.plan_range_c[0], check.plan_range_c[1]}));
  doc.Add("extrapolation_factor", Doc::Number(check.extrapolation_factor));
  doc.Add("tolerance_unmet", Doc::Bool(check.tolerance_unmet));
  doc.Add("temperature_efficiency", Doc::Number(check.temperature_efficiency));
  doc.Add("best_soaks_c", Doc::Numbers({check.best_soaks_c.begin(), check.best_soaks_c.end()}));
  Doc rows = Doc::List();
  for (const PlanRow& r : check.rows) {
    Doc row;
    row.Add("name", Doc::Text(r.name)).Add("unit", Doc::Text(r.unit)).Add("sigma", Doc::Number(r.sigma));
    row.Add("sigma_range", Doc::Number(r.sigma_range)).Add("sigma_spec", Doc::Number(r.sigma_spec));
    row.Add("tolerance", Doc::Number(r.tolerance)).Add("ratio", Doc::Number(r.ratio));
    row.Add("white_share", Doc::Number(r.white_share));
    rows.list.push_back(row);
  }
  doc.Add("rows", rows);
  doc.Add("weak", Doc::Texts(check.weak));
  Doc pairs = Doc::List();
  for (const PlanCheck::Pair& p : check.correlated) {
    Doc pair;
    pair.Add("a", Doc::Text(p.a)).Add("b", Doc::Text(p.b)).Add("correlation", Doc::Number(p.correlation));
    pairs.list.push_back(pair);
  }
  doc.Add("correlated", pairs);
  Doc segments = Doc::List();
  for (const PlanSegmentEffect& e : check.segments) {
    // An essential segment's losses are infinite: written as -1 (nothing non-finite is written).
    const bool essential = !std::isfinite(e.worst_loss);
    Doc segment;
    segment.Add("id", Doc::Number(e.segment)).Add("essential", Doc::Bool(essential));
    segment.Add("limiting_loss", Doc::Number(std::isfinite(e.limiting_loss) ? e.limiting_loss : -1.0));
    segment.Add("worst_loss", Doc::Number(essential ? -1.0 : e.worst_loss));
    segments.list.push_back(segment);
  }
  doc.Add("segments", segments);
  doc.Add("carriers", Doc::Numbers({check.carriers.begin(), check.carriers.end()}));
  doc.Add("cuttable", Doc::Numbers({check.cuttable.begin(), check.cuttable.end()}));
  doc.Add("warnings", Doc::Texts(check.warnings));
  return doc;
}

}  // namespace

std::string PlanCheckText(const PlanCheck& check, const PlanCheckOptions& options) {
  std::string out;
  if (!check.undetermined.empty()) {
    for (const std::string& f : check.undetermined) out += "undetermined: " + f + "\n";
    return out;
  }
  out += Format("plan: %.2f h over %.4g..%.4g degC; z = %.3g\n", check.plan_hours, check.plan_range_c[0],
                check.plan_range_c[1], options.z);
  out += Format("%-44s %12s %12s %12s %10s %7s  %s\n", "coefficient", "sigma", "sigma_range", "sigma_spec",
                "tolerance", "ratio", "unit");
  for (const PlanRow& r : check.rows) {
    out += Format("%-44s %12.4g %12.4g %12.4g %10s %7s  %s\n", r.name.c_str(), r.sigma, r.sigma_range,
                  r.sigma_spec, r.tolerance > 0.0 ? Format("%.4g", r.tolerance).c_str() : "-",
                  r.tolerance > 0.0 ? Format("%.3g", r.ratio).c_str() : "-", r.unit.c_str());
  }
  if (!check.rows.empty()) out += "limiting: " + check.rows.front().name + "\n";
  for (const std::string& w : check.weak) out += "weak: " + w + "\n";
  for (const PlanCheck::Pair& p : check.correlated) {
    out += Format("correlated: %s ~ %s (%.3f)\n", p.a.c_str(), p.b.c_str(), p.correlation);
  }
  out += "segments carrying the limiting coefficient: " + Ids(check.carriers) + "\n";
  out += Format("segments that could be cut (< %.3g %% on every sigma): ", 100.0 * options.cut_loss) +
         Ids(check.cuttable) + "\n";
  if (check.needed_hours > 0.0) {
    out += Format("chamber hours: %.2f planned, %.2f needed for the tolerances (white noise)\n",
                  check.plan_hours, check.needed_hours);
  }
  for (const std::string& w : check.warnings) out += "warning: " + w + "\n";
  out += Format("temperatures: a cubic is best determined by soaks at %.4g, %.4g, %.4g, %.4g degC\n",
                check.best_soaks_c[0], check.best_soaks_c[1], check.best_soaks_c[2], check.best_soaks_c[3]);
  out += Format("temperatures: the planned ones reach D-efficiency %.3f of those (1: as good)\n",
                check.temperature_efficiency);
  if (check.extrapolation_factor > 1.0 + 1e-6) {
    out += Format("extrapolation: sigma at the spec ends is up to %.2f times the largest over the plan\n",
                  check.extrapolation_factor);
  }
  if (check.tolerance_unmet)
    out += "verdict: the plan cannot meet " + check.rows.front().name + "'s tolerance\n";
  return out;
}

std::string PlanDesignText(const PlanDesign& design, const PlanDesignOptions& options) {
  std::string out = Format("candidates: %d segments x %d set-points\n", design.candidate_segments,
                           design.candidate_set_points);
  if (!design.undetermined.empty()) {
    for (const std::string& f : design.undetermined) out += "undetermined: " + f + "\n";
    return out;
  }
  const auto soaks = [](const std::vector<double>& temps) {
    std::string text;
    for (double t : temps) text += (text.empty() ? "" : ",") + Format("%.6g", t);
    return text;
  };
  out += Format("greedy: %zu segments x %zu soaks (--temps=%s): %.2f h\n", design.greedy.size(),
                design.greedy_soaks_c.size(), soaks(design.greedy_soaks_c).c_str(), design.greedy_hours);
  out += Format("after exchange: %zu segments x %zu soaks (--temps=%s): %.2f h\n", design.segments.size(),
                design.soaks_c.size(), soaks(design.soaks_c).c_str(), design.hours);
  out += "\npredicted before the exchange:\n" + PlanCheckText(design.greedy_check, options.check);
  out += "\npredicted after the exchange:\n" + PlanCheckText(design.check, options.check);
  out += design.met ? "verdict: the design meets every tolerance\n"
                    : "verdict: no plan of these candidates meets the tolerances\n";
  return out;
}

std::string PlanCheckYaml(const PlanCheck& check) { return YamlOf(PlanCheckDoc(check)); }

std::string PlanCheckJson(const PlanCheck& check) { return JsonOf(PlanCheckDoc(check)); }

}  // namespace imufit
