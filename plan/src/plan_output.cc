// `imufit plan check`'s outputs (plan_check.h): a table for people, YAML or JSON for machines (one
// document, written by io's writer of machine-readable text: machine_text.h).
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "imufit/base/text.h"
#include "imufit/io/machine_text.h"
#include "imufit/model/check.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"

namespace imufit {
namespace {

constexpr auto Format = FormatText;  // base/text.h

std::string Ids(const std::vector<int>& ids) {
  std::string text;
  for (int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text.empty() ? "none" : text;
}

// A figure of the machines' document (finite: nothing non-finite is written).
MachineDoc Figure(double value) {
  IMUFIT_CHECK(std::isfinite(value), "a plan check figure is finite");
  return MachineDoc::Number(value);
}

MachineDoc Figures(const std::vector<double>& values) {
  MachineDoc list = MachineDoc::List();
  for (const double value : values) list.Push(Figure(value));
  return list;
}

// Texts and records one a line.
MachineDoc Lines(const std::vector<std::string>& values) {
  return MachineDoc::Texts(values, MachineDoc::Style::kBlock);
}

MachineDoc PlanCheckDoc(const PlanCheck& check, const std::vector<PlanCriterion>& criteria) {
  MachineDoc doc = MachineDoc::Map();
  doc.Add("format", MachineDoc::Text("imufit-plan-check")).Add("version", MachineDoc::Integer(1));
  doc.Add("undetermined", Lines(check.undetermined));
  if (!check.undetermined.empty()) return doc;
  doc.Add("plan_hours", Figure(check.plan_hours)).Add("needed_hours", Figure(check.needed_hours));
  doc.Add("plan_range_c", Figures({check.plan_range_c[0], check.plan_range_c[1]}));
  doc.Add("extrapolation_factor", Figure(check.extrapolation_factor));
  doc.Add("tolerance_unmet", MachineDoc::Bool(check.tolerance_unmet));
  doc.Add("temperature_efficiency", Figure(check.temperature_efficiency));
  doc.Add("best_soaks_c", Figures({check.best_soaks_c.begin(), check.best_soaks_c.end()}));
  MachineDoc rows = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const PlanRow& r : check.rows) {
    MachineDoc row = MachineDoc::Map(MachineDoc::Style::kFlow);
    row.Add("name", MachineDoc::Text(r.name))
        .Add("unit", MachineDoc::Text(r.unit))
        .Add("sigma", Figure(r.sigma));
    row.Add("sigma_range", Figure(r.sigma_range)).Add("sigma_spec", Figure(r.sigma_spec));
    row.Add("tolerance", Figure(r.tolerance)).Add("ratio", Figure(r.ratio));
    row.Add("white_share", Figure(r.white_share));
    rows.Push(std::move(row));
  }
  doc.Add("rows", rows);
  doc.Add("weak", Lines(check.weak));
  MachineDoc pairs = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const PlanCheck::Pair& p : check.correlated) {
    MachineDoc pair = MachineDoc::Map(MachineDoc::Style::kFlow);
    pair.Add("a", MachineDoc::Text(p.a))
        .Add("b", MachineDoc::Text(p.b))
        .Add("correlation", Figure(p.correlation));
    pairs.Push(std::move(pair));
  }
  doc.Add("correlated", pairs);
  MachineDoc segments = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const PlanSegmentEffect& e : check.segments) {
    // An essential segment's losses are infinite: written as -1 (nothing non-finite is written).
    const bool essential = !std::isfinite(e.worst_loss);
    MachineDoc segment = MachineDoc::Map(MachineDoc::Style::kFlow);
    segment.Add("id", MachineDoc::Integer(e.segment)).Add("essential", MachineDoc::Bool(essential));
    segment.Add("limiting_loss", Figure(std::isfinite(e.limiting_loss) ? e.limiting_loss : -1.0));
    segment.Add("worst_loss", Figure(essential ? -1.0 : e.worst_loss));
    segments.Push(std::move(segment));
  }
  doc.Add("segments", segments);
  doc.Add("carriers", MachineDoc::Integers(check.carriers));
  doc.Add("cuttable", MachineDoc::Integers(check.cuttable));
  doc.Add("warnings", Lines(check.warnings));
  doc.Add("left_out", MachineDoc::Text(check.left_out));
  doc.Add("longest_static_s", Figure(check.longest_static_s));
  MachineDoc judged = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const PlanCriterion& c : criteria) {
    MachineDoc row = MachineDoc::Map(MachineDoc::Style::kFlow);
    row.Add("name", MachineDoc::Text(c.name)).Add("unit", MachineDoc::Text(c.unit));
    row.Add("noise", MachineDoc::Bool(c.noise)).Add("met", MachineDoc::Bool(c.met));
    if (c.noise) {
      row.Add("needed_s", Figure(c.needed_s)).Add("stretch_s", Figure(c.stretch_s));
    } else {
      row.Add("tolerance", Figure(c.tolerance))
          .Add("expanded", Figure(c.expanded))
          .Add("ratio", Figure(c.ratio));
    }
    judged.Push(std::move(row));
  }
  doc.Add("criteria", judged);
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
  if (!check.left_out.empty()) out += "windows: the fit will leave out " + check.left_out + "\n";
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

std::string PlanCheckYaml(const PlanCheck& check, const std::vector<PlanCriterion>& criteria) {
  return YamlText(PlanCheckDoc(check, criteria));
}

std::string PlanCheckJson(const PlanCheck& check, const std::vector<PlanCriterion>& criteria) {
  return JsonText(PlanCheckDoc(check, criteria));
}

}  // namespace imufit
