#include "imufit/factory/acceptance.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "imufit/factory/uncertainty_budget.h"
#include "imufit/io/noise_file.h"

namespace imufit {
namespace {

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// A figure of the fit's record, when the calibration has one and it says (>= 0: "not run" values
// are negative).
std::optional<double> FitFigure(const Calibration& calibration, std::optional<double> FitRecord::*member) {
  if (!calibration.fit) return std::nullopt;
  const std::optional<double>& value = (*calibration.fit).*member;
  if (!value || !(*value >= 0.0)) return std::nullopt;
  return value;
}

// The outcome of a criterion with U `expanded` under the verdict's rule.
// (The margin is the distance inside the nearest limit, negative outside.)
void Decide(const Verdict& verdict, CriterionResult* r) {
  const double margin = r->margin, u = r->expanded;
  if (!(u > 0.0)) {
    r->outcome = margin > 0.0 ? Outcome::kPass : Outcome::kFail;
    r->pass = r->outcome == Outcome::kPass;
    return;
  }
  r->outcome = margin > u     ? Outcome::kPass
               : margin > 0.0 ? Outcome::kConditionalPass
               : margin > -u  ? Outcome::kConditionalFail
                              : Outcome::kFail;
  const double guard = verdict.rule == DecisionRule::kGuarded ? verdict.guard_band_u * u : 0.0;
  r->pass = margin > guard;
  if (r->outcome == Outcome::kConditionalPass || r->outcome == Outcome::kConditionalFail) {
    r->reason = "within U = " + Number(u) + " " + r->unit + " of the limit";
    if (verdict.rule == DecisionRule::kGuarded && r->outcome == Outcome::kConditionalPass) {
      r->reason += ": inside the guard band, not accepted";
    }
  }
}

}  // namespace

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kPass:
      return "PASS";
    case Outcome::kConditionalPass:
      return "conditional pass";
    case Outcome::kConditionalFail:
      return "conditional fail";
    case Outcome::kFail:
      return "FAIL";
  }
  return "FAIL";
}

std::vector<Figure> KeyFigures(const Calibration& calibration) {
  const SensorModel* sigma = calibration.sigma ? &*calibration.sigma : nullptr;
  std::vector<Figure> figures;
  const auto add = [&](const std::string& quantity, Sensor sensor, int coefficient) {
    const CoefficientName& n = kCoefficientNames[coefficient];
    const EngineeringValue v =
        EngineeringCoefficient(calibration.model, sigma, sensor, coefficient, kFigureTempC);
    const auto& range = calibration.fit_temp_range_c;
    figures.push_back({quantity + "." + n.axis,
                       std::string(sensor == Sensor::kGyro ? "gyro." : "accel.") + n.group + "." + n.axis,
                       EngineeringUnit(sensor, coefficient), v.value, v.sigma,
                       range[1] > range[0] && (kFigureTempC < range[0] || kFigureTempC > range[1])});
  };
  for (int i = 0; i < 3; ++i) add("gyro_bias_dps", Sensor::kGyro, kBiasCoefficient + i);
  for (int i = 0; i < 3; ++i) add("accel_bias_mg", Sensor::kAccel, kBiasCoefficient + i);
  for (int i = 0; i < 3; ++i) add("gyro_scale_per_dps", Sensor::kGyro, kScaleCoefficient + i);
  for (int i = 0; i < 3; ++i) add("accel_scale_per_g", Sensor::kAccel, kScaleCoefficient + i);
  for (int m = 0; m < 6; ++m) add("gyro_misalignment_mrad", Sensor::kGyro, kMisalignmentCoefficient + m);
  for (int m = 0; m < 6; ++m) add("accel_misalignment_mrad", Sensor::kAccel, kMisalignmentCoefficient + m);
  for (int h = 0; h < 9; ++h) add("gyro_g_sensitivity_dpsg", Sensor::kGyro, kGSensitivityCoefficient + h);
  // Noise figures, when the calibration carries a `noise:` block (imufit allan --noise-yaml,
  // docs/allan.md): [value, 1-sigma] per gyro column.
  const char* axes[] = {"x", "y", "z"};
  struct NoiseKey {
    const char* name;
    const char* key;
    const char* unit;
  };
  const NoiseKey noise_keys[] = {{"gyro_arw_deg_per_sqrt_hr", "arw_deg_per_sqrt_hr", "deg/sqrt(h)"},
                                 {"gyro_bias_instability_dph", "bias_instability_deg_per_hr", "deg/h"}};
  for (const auto& [name, key, unit] : noise_keys) {
    for (const char* axis : axes) {
      if (const std::optional<std::array<double, 2>> pair =
              ReadNoiseFigure(calibration.extra, std::string("gyro_") + axis, key)) {
        figures.push_back({std::string(name) + "." + axis, std::string("noise.gyro_") + axis + "." + key,
                           unit, (*pair)[0], (*pair)[1]});
      }
    }
  }
  if (const std::optional<double> rms = FitFigure(calibration, &FitRecord::gyro_residual_rms_radps)) {
    figures.push_back({"gyro_residual_rms_dps", "fit.gyro_residual_rms", "deg/s", DpsFromRadps(*rms), -1.0});
  }
  if (calibration.fit && calibration.fit->missing_segments && *calibration.fit->missing_segments >= 0) {
    figures.push_back({"coverage", "fit.missing_segments", "segments missing",
                       static_cast<double>(*calibration.fit->missing_segments), -1.0});
  }
  if (const std::optional<double> rms = FitFigure(calibration, &FitRecord::accel_residual_rms_mps2)) {
    figures.push_back({"accel_residual_rms_mg", "fit.accel_residual_rms", "mg", MgFromMps2(*rms), -1.0});
  }
  return figures;
}

const Figure* FindFigure(const std::vector<Figure>& figures, const std::string& name) {
  for (const Figure& f : figures) {
    if (f.name == name || f.coefficient == name) return &f;
  }
  return nullptr;
}

int Verdict::Failed() const {
  int failed = 0;
  for (const CriterionResult& c : criteria) failed += c.pass ? 0 : 1;
  return failed;
}

int Verdict::Conditional() const {
  int conditional = 0;
  for (const CriterionResult& c : criteria) {
    conditional += c.outcome == Outcome::kConditionalPass || c.outcome == Outcome::kConditionalFail ? 1 : 0;
  }
  return conditional;
}

std::string Verdict::RuleText() const {
  if (rule == DecisionRule::kGuarded) {
    return "guarded acceptance (ILAC-G8): a value passes when it lies inside its limit by more than the "
           "guard "
           "band w = " +
           Number(guard_band_u) +
           " x U; a value within U of a limit is reported as a conditional pass (inside, not accepted) or a "
           "conditional fail (outside).";
  }
  return "simple acceptance (ILAC-G8): a value passes when it lies inside its limit, whatever its U; a value "
         "within U of a limit is reported as a conditional pass (inside) or a conditional fail (outside).";
}

std::string Verdict::FailedSummary() const {
  std::string text;
  for (const CriterionResult& c : criteria) {
    if (c.pass) continue;
    text += (text.empty() ? "" : "; ") + c.name + " " + c.measured_text + " (limit " + c.limit_text + ")";
  }
  return text;
}

std::string Verdict::Table() const {
  std::string text;
  char line[256];
  std::snprintf(line, sizeof line, "  acceptance%s%s: %s (%d of %zu criteria failed)\n",
                limits_name.empty() ? "" : " ", limits_name.c_str(), pass ? "PASS" : "FAIL", Failed(),
                criteria.size());
  text += line;
  std::snprintf(line, sizeof line, "    %-32s %22s %18s %20s  %s\n", "criterion", "measured", "limit",
                "margin", "verdict");
  text += line;
  for (const CriterionResult& c : criteria) {
    std::snprintf(line, sizeof line, "    %-32s %22s %18s %20s  %s%s%s\n", c.name.c_str(),
                  c.measured_text.c_str(), c.limit_text.c_str(), c.margin_text.c_str(),
                  OutcomeName(c.outcome), c.reason.empty() ? "" : ": ", c.reason.c_str());
    text += line;
  }
  return text;
}

Verdict EvaluateLimits(const Limits& limits, const Calibration& calibration,
                       const std::vector<Figure>& measured, const UncertaintyBudget* budget) {
  Verdict verdict;
  verdict.limits_name = limits.name;
  verdict.rule = limits.decision_rule;
  verdict.guard_band_u = limits.guard_band_u;
  // U of a figure: the budget's, else k = 2 times its 1-sigma; < 0: none.
  const auto expanded = [&](const Figure& f) {
    const FigureBudget* b = budget != nullptr ? budget->Find(f.name) : nullptr;
    return b != nullptr ? b->expanded : f.sigma >= 0.0 ? 2.0 * f.sigma : -1.0;
  };
  std::vector<Figure> figures = measured;  // found first: they take the place of the calibration's
  for (const Figure& f : KeyFigures(calibration)) figures.push_back(f);
  for (const LimitCriterion& criterion : limits.criteria) {
    const bool sigma = criterion.statistic == LimitStatistic::kSigma;
    if (criterion.kind == LimitKind::kCoverage) {
      CriterionResult r;
      r.name = criterion.quantity;
      r.unit = criterion.unit;
      const auto& range = calibration.fit_temp_range_c;
      r.margin = std::min(criterion.covers_c[0] - range[0], range[1] - criterion.covers_c[1]);
      r.measured = r.margin;
      r.limit = 0.0;
      r.measured_text = Number(range[0]) + ".." + Number(range[1]) + " degC";
      r.limit_text = "covers " + Number(criterion.covers_c[0]) + ".." + Number(criterion.covers_c[1]) +
                     " (tolerance " + Number(criterion.covers_tolerance_c) + " degC)";
      r.margin_text = Number(r.margin) + " " + criterion.unit;
      r.pass = r.margin >= -criterion.covers_tolerance_c;
      if (r.pass && r.margin < 0.0) r.reason = "short of the range by less than its tolerance";
      r.outcome = r.pass ? Outcome::kPass : Outcome::kFail;
      verdict.criteria.push_back(r);
      continue;
    }
    std::vector<std::string> names;
    if (criterion.axes.empty()) names.push_back(criterion.quantity);
    for (const std::string& axis : criterion.axes) names.push_back(criterion.quantity + "." + axis);
    for (const std::string& name : names) {
      CriterionResult r;
      r.name = sigma ? "sigma(" + name + ")" : criterion.kind == LimitKind::kFigure ? name : "|" + name + "|";
      r.unit = criterion.unit;
      const bool bounds = criterion.min || criterion.max;
      if (bounds) r.name = name;
      r.limit = criterion.max_abs;
      r.limit_text = "< " + Number(criterion.max_abs) + " " + criterion.unit;
      if (bounds) {
        r.limit_text = criterion.min && criterion.max
                           ? Number(*criterion.min) + " .. " + Number(*criterion.max) + " " + criterion.unit
                       : criterion.min ? ">= " + Number(*criterion.min) + " " + criterion.unit
                                       : "<= " + Number(*criterion.max) + " " + criterion.unit;
      }
      bool extrapolated = false;
      // Scale errors are relative to the nominal scale the limits file gives.
      const size_t error_at = name.find("_scale_error_");
      bool found = true;
      if (error_at != std::string::npos) {
        const bool gyro = name.rfind("gyro", 0) == 0;
        const std::string axis = name.substr(name.rfind('.') + 1);
        const Figure* scale = FindFigure(figures, std::string(gyro ? "gyro" : "accel") + ".scale." + axis);
        const double nominal =
            gyro ? limits.nominal_gyro_scale / kRadToDeg : limits.nominal_accel_scale * kStandardGravityMps2;
        const double factor = name.find("_ppm") != std::string::npos ? 1e6 : 1e2;
        r.measured = sigma ? scale->sigma / nominal * factor : (scale->value / nominal - 1.0) * factor;
        if (!sigma && expanded(*scale) >= 0.0) r.expanded = expanded(*scale) / nominal * factor;
        extrapolated = scale->extrapolated;
        found = !sigma || scale->sigma >= 0.0;
      } else {
        const Figure* figure = FindFigure(figures, name);
        found = figure != nullptr && (!sigma || figure->sigma >= 0.0);
        if (found) r.measured = sigma ? figure->sigma : figure->value;
        if (found && !sigma) r.expanded = expanded(*figure);
        extrapolated = found && figure->extrapolated;
      }
      if (!found) {
        r.measured_text = "not in calibration";
        r.margin = -r.limit;
        r.margin_text = "none";
        r.pass = false;
      } else {
        // A max_abs criterion judges |value|: that is what it shows (a residual RMS is >= 0 anyway);
        // min/max judge the signed value, its margin to the nearer bound.
        if (bounds) {
          const double above_min = criterion.min ? r.measured - *criterion.min : HUGE_VAL;
          const double below_max = criterion.max ? *criterion.max - r.measured : HUGE_VAL;
          r.margin = std::min(above_min, below_max);
          r.limit = below_max <= above_min ? *criterion.max : *criterion.min;
        } else {
          r.measured = std::abs(r.measured);
          r.margin = r.limit - r.measured;
        }
        r.measured_text = Number(r.measured) + " " + criterion.unit;
        // Coverage counts segments missing; its margin is segments to spare, not missing ones.
        r.margin_text = criterion.quantity == "coverage"
                            ? Number(r.margin) + (r.margin == 1.0 ? " segment" : " segments")
                            : Number(r.margin) + " " + criterion.unit;
        Decide(verdict, &r);
        if (extrapolated) {
          const auto& range = calibration.fit_temp_range_c;
          r.reason += std::string(r.reason.empty() ? "" : "; ") +
                      "evaluated at 25 degC, outside the fitted range " + Number(range[0]) + ".." +
                      Number(range[1]) + " degC: extrapolated";
        }
      }
      verdict.criteria.push_back(r);
    }
  }
  for (const CriterionResult& c : verdict.criteria) verdict.pass = verdict.pass && c.pass;
  return verdict;
}

}  // namespace imufit
