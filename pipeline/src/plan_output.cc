// `imufit plan check`'s outputs (plan_check.h): a table for people, YAML for machines.
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>

#include "imufit/pipeline/plan_check.h"

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
  if (check.extrapolation_factor > 1.0 + 1e-6) {
    out += Format("extrapolation: sigma at the spec ends is up to %.2f times the largest over the plan\n",
                  check.extrapolation_factor);
  }
  if (check.tolerance_unmet)
    out += "verdict: the plan cannot meet " + check.rows.front().name + "'s tolerance\n";
  return out;
}

std::string PlanCheckYaml(const PlanCheck& check) {
  std::string out = "format: imufit-plan-check\nversion: 1\n";
  out += "undetermined:" + std::string(check.undetermined.empty() ? " []\n" : "\n");
  for (const std::string& f : check.undetermined) out += "  - \"" + f + "\"\n";
  if (!check.undetermined.empty()) return out;
  out += Format("plan_hours: %.9g\nneeded_hours: %.9g\nplan_range_c: [%.9g, %.9g]\n", check.plan_hours,
                check.needed_hours, check.plan_range_c[0], check.plan_range_c[1]);
  out += Format("extrapolation_factor: %.9g\ntolerance_unmet: %s\n", check.extrapolation_factor,
                check.tolerance_unmet ? "true" : "false");
  out += Format("best_soaks_c: [%.9g, %.9g, %.9g, %.9g]\n", check.best_soaks_c[0], check.best_soaks_c[1],
                check.best_soaks_c[2], check.best_soaks_c[3]);
  out += "rows:\n";
  for (const PlanRow& r : check.rows) {
    out += Format(
        "  - {name: \"%s\", unit: \"%s\", sigma: %.9g, sigma_range: %.9g, sigma_spec: %.9g, "
        "tolerance: %.9g, ratio: %.9g, white_share: %.9g}\n",
        r.name.c_str(), r.unit.c_str(), r.sigma, r.sigma_range, r.sigma_spec, r.tolerance, r.ratio,
        r.white_share);
  }
  out += "weak:" + std::string(check.weak.empty() ? " []\n" : "\n");
  for (const std::string& w : check.weak) out += "  - \"" + w + "\"\n";
  out += "correlated:" + std::string(check.correlated.empty() ? " []\n" : "\n");
  for (const PlanCheck::Pair& p : check.correlated) {
    out += Format("  - {a: \"%s\", b: \"%s\", correlation: %.9g}\n", p.a.c_str(), p.b.c_str(), p.correlation);
  }
  out += "segments:\n";
  for (const PlanSegmentEffect& e : check.segments) {
    const bool essential = !std::isfinite(e.worst_loss);
    out += Format("  - {id: %d, essential: %s, limiting_loss: %.9g, worst_loss: %.9g}\n", e.segment,
                  essential ? "true" : "false", std::isfinite(e.limiting_loss) ? e.limiting_loss : -1.0,
                  essential ? -1.0 : e.worst_loss);
  }
  out += "carriers: [" + (check.carriers.empty() ? std::string() : Ids(check.carriers)) + "]\n";
  out += "cuttable: [" + (check.cuttable.empty() ? std::string() : Ids(check.cuttable)) + "]\n";
  out += "warnings:" + std::string(check.warnings.empty() ? " []\n" : "\n");
  for (const std::string& w : check.warnings) out += "  - \"" + w + "\"\n";
  return out;
}

}  // namespace imufit
