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
  const bool guarded = verdict.rule == DecisionRule::kGuarded;
  const double guard = guarded ? verdict.guard_band_u * u : 0.0;
  r->pass = margin > guard;
  if (r->outcome == Outcome::kConditionalPass || r->outcome == Outcome::kConditionalFail) {
    r->reason = "within U = " + Number(u) + " " + r->unit + " of the limit";
    if (guarded && r->outcome == Outcome::kConditionalPass) {
      // Accepted only clear of the guard band w = guard_band x U (a band below 1 accepts some).
      r->reason += r->pass ? ", clear of the guard band w = " + Number(guard) + " " + r->unit + ": accepted"
                           : ": inside the guard band, not accepted";
    }
  } else if (r->outcome == Outcome::kPass && !r->pass) {
    // Clear of the limit by more than U but not by the guard band (guard_band > 1): not accepted,
    // and its row says so.
    r->outcome = Outcome::kFail;
    r->reason = "inside the guard band w = " + Number(verdict.guard_band_u) + " x U = " + Number(guard) +
                " " + r->unit + " of the limit: not accepted";
  }
}

// What a criterion is judged with beside its figures.
struct Context {
  const Limits& limits;
  const Calibration& calibration;
  const UncertaintyBudget* budget;  // nullptr: U = 2 x 1-sigma
};

// One figure's reading for a criterion: the value judged (a scale error relative to the nominal
// scale; the 1-sigma for a sigma criterion) and its U.
struct Reading {
  bool found = false;
  double value = 0.0;
  double expanded = -1.0;  // < 0: none
  bool extrapolated = false;
  std::string unresolved;  // Figure::unresolved
};

Reading Read(const Context& context, const std::string& name, bool sigma,
             const std::vector<Figure>& figures) {
  // U of a figure: its own (the budget's for a coefficient when there is one, else k x its 1-sigma).
  const auto expanded = [](const Figure& f) { return f.expanded; };
  Reading reading;
  // Scale errors are relative to the nominal scale the limits file gives.
  if (const KeyFigure* quantity = FindKeyFigure(name);
      quantity != nullptr && quantity->source == FigureSource::kScaleError) {
    const bool gyro = IsGyroFigure(*quantity);
    const std::string axis = name.substr(name.rfind('.') + 1);
    const Figure* scale = FindFigure(figures, std::string(quantity->path) + "." + axis);
    const double nominal = context.limits.NominalScaleFigure(gyro);
    const double factor = quantity->per_unit;
    reading.value = sigma ? scale->sigma / nominal * factor : (scale->value / nominal - 1.0) * factor;
    if (!sigma && expanded(*scale) >= 0.0) reading.expanded = expanded(*scale) / nominal * factor;
    reading.extrapolated = scale->extrapolated;
    reading.found = !sigma || scale->sigma >= 0.0;
    return reading;
  }
  // A figure this run could not resolve gives way to one of the same name that is known (a
  // calibration's `noise:` block).
  const Figure* figure = nullptr;
  for (const Figure& f : figures) {
    if (f.name != name && f.coefficient != name) continue;
    if (f.unresolved.empty()) {
      figure = &f;
      break;
    }
    if (reading.unresolved.empty()) reading.unresolved = f.unresolved;
  }
  reading.found = figure != nullptr && (!sigma || figure->sigma >= 0.0);
  if (!reading.found) return reading;
  reading.value = sigma ? figure->sigma : figure->value;
  if (!sigma) reading.expanded = expanded(*figure);
  reading.extrapolated = figure->extrapolated;
  return reading;
}

// A statistic over a temperature range (LimitStatistic::kLargest, kVariation), the polynomial
// evaluated at kRangeStatisticPoints temperatures: the value that binds, with its U there (the
// budget's at that temperature, the station's Type B sources included), and `*at_c`, where; for a variation,
// largest - smallest, without a U (the errors of its ends are correlated).
Reading ReadOverRange(const Context& context, const LimitCriterion& criterion, const std::string& name,
                      double* at_c) {
  const std::array<double, 2> range = criterion.over_c.value_or(context.calibration.fit_temp_range_c);
  Reading lowest, highest, largest;
  double lowest_c = range[0], highest_c = range[0], largest_c = range[0];
  for (int i = 0; i < kRangeStatisticPoints; ++i) {
    const double temp_c = range[0] + (range[1] - range[0]) * i / (kRangeStatisticPoints - 1);
    const Reading r = Read(context, name, false, KeyFigures(context.calibration, temp_c, context.budget));
    if (!r.found) return r;
    if (i == 0 || r.value < lowest.value) lowest = r, lowest_c = temp_c;
    if (i == 0 || r.value > highest.value) highest = r, highest_c = temp_c;
    if (i == 0 || std::abs(r.value) > std::abs(largest.value)) largest = r, largest_c = temp_c;
  }
  const auto& fitted = context.calibration.fit_temp_range_c;
  const bool beyond = range[0] < fitted[0] || range[1] > fitted[1];
  if (criterion.statistic == LimitStatistic::kVariation) {
    Reading variation = highest;
    variation.value = highest.value - lowest.value;
    variation.expanded = -1.0;
    variation.extrapolated = beyond;
    *at_c = highest_c;
    return variation;
  }
  Reading binding = largest;
  *at_c = largest_c;
  if (criterion.min || criterion.max) {  // the side nearer its bound
    const double above_min = criterion.min ? lowest.value - *criterion.min : HUGE_VAL;
    const double below_max = criterion.max ? *criterion.max - highest.value : HUGE_VAL;
    binding = below_max <= above_min ? highest : lowest;
    *at_c = below_max <= above_min ? highest_c : lowest_c;
  }
  binding.extrapolated = beyond;
  return binding;
}

// "largest over -40..85 degC" (the range a statistic is taken over), "" for a value at 25 degC.
std::string RangeText(const LimitCriterion& criterion, const Calibration& calibration) {
  if (criterion.statistic != LimitStatistic::kLargest && criterion.statistic != LimitStatistic::kVariation)
    return "";
  const std::array<double, 2> range = criterion.over_c.value_or(calibration.fit_temp_range_c);
  return std::string(criterion.statistic == LimitStatistic::kLargest ? "largest" : "variation") + " over " +
         Number(range[0]) + ".." + Number(range[1]) + " degC";
}

// The name and the words of a criterion on one figure (`name`, with its axis), and its limit.
CriterionResult Named(const LimitCriterion& criterion, const std::string& name,
                      const std::string& range_text) {
  const bool sigma = criterion.statistic == LimitStatistic::kSigma;
  const bool bounds = criterion.min || criterion.max;
  CriterionResult r;
  r.name = sigma                 ? "sigma(" + name + ")"
           : !range_text.empty() ? range_text.substr(0, range_text.find(' ')) + "(" + name + ")"
           : bounds || criterion.kind == LimitKind::kFigure ? name
                                                            : "|" + name + "|";
  r.title = FigureTitle(name) + (sigma ? ", 1-sigma" : range_text.empty() ? "" : ", " + range_text);
  r.unit = criterion.unit;
  r.limit = criterion.max_abs;
  r.limit_text = "< " + Number(criterion.max_abs) + " " + criterion.unit;
  if (bounds) {
    r.limit_text = criterion.min && criterion.max
                       ? Number(*criterion.min) + " .. " + Number(*criterion.max) + " " + criterion.unit
                   : criterion.min ? ">= " + Number(*criterion.min) + " " + criterion.unit
                                   : "<= " + Number(*criterion.max) + " " + criterion.unit;
  }
  return r;
}

// The outcome of one criterion on one figure (`name`, with its axis).
CriterionResult Judge(const LimitCriterion& criterion, const std::string& name,
                      const std::vector<Figure>& figures, const Context& context, const Verdict& verdict) {
  const std::string range_text = RangeText(criterion, context.calibration);
  CriterionResult r = Named(criterion, name, range_text);
  double at_c = kFigureTempC;
  const Reading reading = range_text.empty()
                              ? Read(context, name, criterion.statistic == LimitStatistic::kSigma, figures)
                              : ReadOverRange(context, criterion, name, &at_c);
  if (!reading.found) {
    r.measured_text = reading.unresolved.empty() ? "not in calibration" : "not resolved by this run";
    r.reason = reading.unresolved;
    const KeyFigure* quantity = FindKeyFigure(name);
    if (reading.unresolved.empty() && quantity != nullptr && quantity->source == FigureSource::kCertificate)
      r.reason = "measured on the certificate's windows (give --report)";
    r.margin = -r.limit;
    r.margin_text = "none";
    r.pass = false;
    return r;
  }
  r.measured = reading.value;
  r.expanded = reading.expanded;
  // A max_abs criterion judges |value|: that is what it shows (a residual RMS is >= 0 anyway);
  // min/max judge the signed value, its margin to the nearer bound.
  if (criterion.min || criterion.max) {
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
  if (criterion.statistic == LimitStatistic::kLargest) {
    r.reason += std::string(r.reason.empty() ? "" : "; ") + "at " + Number(at_c) + " degC";
  }
  if (reading.extrapolated) {
    const auto& range = context.calibration.fit_temp_range_c;
    r.reason += std::string(r.reason.empty() ? "" : "; ") +
                (range_text.empty() ? "evaluated at 25 degC" : "evaluated") + ", outside the fitted range " +
                Number(range[0]) + ".." + Number(range[1]) + " degC: extrapolated";
  }
  return r;
}

}  // namespace

std::string FigureTitle(const std::string& name) {
  const KeyFigure* quantity = FindKeyFigure(name);
  if (quantity == nullptr) return name;
  const size_t dot = name.find('.');
  const std::string axis = dot == std::string::npos ? "" : name.substr(dot + 1);
  const std::string title = quantity->title;
  const auto upper = [](char c) { return std::string(1, static_cast<char>(c - 'a' + 'A')); };
  if (quantity->pair_axes && axis.size() == 2)
    return title + " " + upper(axis[0]) + " from " + upper(axis[1]);
  if (axis.size() == 1) return title + " " + upper(axis[0]);
  return title;
}

namespace {

// The figures of a coefficient group (FigureSource::kCoefficient) at `temp_c`, one per coefficient of
// the group, in the model's layout.
void CoefficientFigures(const KeyFigure& quantity, const Calibration& calibration, double temp_c,
                        std::vector<Figure>* figures) {
  const SensorModel* sigma = calibration.sigma ? &*calibration.sigma : nullptr;
  const bool gyro = IsGyroFigure(quantity);
  const Sensor sensor = gyro ? Sensor::kGyro : Sensor::kAccel;
  const std::string group = std::string(quantity.path).substr(std::string(quantity.path).find('.') + 1);
  const auto& range = calibration.fit_temp_range_c;
  for (int coefficient = 0; coefficient < (gyro ? kGyroCoefficients : kAccelCoefficients); ++coefficient) {
    const CoefficientName& n = kCoefficientNames[coefficient];
    if (group != n.group) continue;
    const EngineeringValue v = EngineeringCoefficient(calibration.model, sigma, sensor, coefficient, temp_c);
    Figure figure = MakeFigure(std::string(quantity.name) + "." + n.axis,
                               std::string(quantity.path) + "." + n.axis, quantity.unit, v.value, v.sigma);
    figure.extrapolated = range[1] > range[0] && (temp_c < range[0] || temp_c > range[1]);
    figures->push_back(std::move(figure));
  }
}

}  // namespace

std::vector<Figure> KeyFigures(const Calibration& calibration, double temp_c,
                               const UncertaintyBudget* budget) {
  std::vector<Figure> figures;
  for (const KeyFigure& quantity : kKeyFigures) {
    switch (quantity.source) {
      case FigureSource::kCoefficient:
        CoefficientFigures(quantity, calibration, temp_c, &figures);
        break;
      case FigureSource::kNoise:
        // When the calibration carries a `noise:` block (imufit allan --noise-yaml, docs/allan.md):
        // [value, 1-sigma] per gyro column.
        for (const std::string& axis : KeyFigureAxes(quantity)) {
          if (const std::optional<std::array<double, 2>> pair =
                  NoiseFigure(calibration.noise, "gyro_" + axis, quantity.path)) {
            figures.push_back(MakeFigure(std::string(quantity.name) + "." + axis,
                                         "noise.gyro_" + axis + "." + quantity.path, quantity.unit,
                                         (*pair)[0], (*pair)[1]));
          }
        }
        break;
      case FigureSource::kFitRecord:
        // "Not run" values are negative.
        if (const std::optional<double> value =
                calibration.fit ? quantity.record(*calibration.fit) : std::nullopt;
            value && *value >= 0.0) {
          figures.push_back(MakeFigure(quantity.name, quantity.path, quantity.unit, *value));
        }
        break;
      case FigureSource::kScaleError:   // judged from the scale figures
      case FigureSource::kCertificate:  // measured by the certificate (MeasuredFigures)
      case FigureSource::kFitRange:     // judged as a range
        break;
    }
  }
  if (budget != nullptr) {
    for (const FigureBudget& b : budget->At(calibration, temp_c)) {
      for (Figure& f : figures) {
        if (f.name == b.name && f.sigma >= 0.0) f.expanded = b.expanded;
      }
    }
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

std::string DecisionRuleText(DecisionRule rule, double guard_band_u) {
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

std::string Verdict::FailedSummary(bool in_words) const {
  std::string text;
  for (const CriterionResult& c : criteria) {
    if (c.pass) continue;
    text += (text.empty() ? "" : "; ") + (in_words ? c.title : c.name) + " " + c.measured_text + " (limit " +
            c.limit_text + ")";
  }
  return text;
}

std::string Verdict::Table() const {
  std::string text;
  char line[256];
  std::snprintf(line, sizeof line, "  acceptance%s%s: %s (%d of %zu criteria failed)\n",
                limits_name.empty() ? "" : " ", limits_name.c_str(), VerdictName(pass), Failed(),
                criteria.size());
  text += line;
  std::snprintf(line, sizeof line, "    %-32s %22s %18s %20s  %s\n", "criterion", "measured", "limit",
                "margin", "verdict");
  text += line;
  for (const CriterionResult& c : criteria) {
    // The columns in the fixed buffer, the reason (of any length: a noise criterion's says what
    // to record) after it, so that no row is cut or runs into the next.
    std::snprintf(line, sizeof line, "    %-32s %22s %18s %20s  %s", c.name.c_str(), c.measured_text.c_str(),
                  c.limit_text.c_str(), c.margin_text.c_str(), OutcomeName(c.outcome));
    text += line;
    if (!c.reason.empty()) text += ": " + c.reason;
    text += '\n';
  }
  return text;
}

Verdict EvaluateLimits(const Limits& limits, const Calibration& calibration,
                       const std::vector<Figure>& measured, const UncertaintyBudget* budget) {
  Verdict verdict;
  verdict.limits_name = limits.name;
  verdict.rule = limits.decision_rule;
  verdict.guard_band_u = limits.guard_band_u;
  const Context context{limits, calibration, budget};
  std::vector<Figure> figures = measured;  // found first: they take the place of the calibration's
  for (const Figure& f : KeyFigures(calibration, kFigureTempC, budget)) figures.push_back(f);
  for (const LimitCriterion& criterion : limits.criteria) {
    if (criterion.kind == LimitKind::kCoverage) {
      CriterionResult r;
      r.name = criterion.quantity;
      r.title = FigureTitle(r.name);
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
    for (const std::string& name : names)
      verdict.criteria.push_back(Judge(criterion, name, figures, context, verdict));
  }
  for (const CriterionResult& c : verdict.criteria) verdict.pass = verdict.pass && c.pass;
  return verdict;
}

}  // namespace imufit
