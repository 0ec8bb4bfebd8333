#include "imufit/io/limits.h"

#include "imufit/base/enum_names.h"
#include "imufit/io/error.h"
#include "yaml_util.h"

namespace imufit {

const KeyFigure* FindLimitQuantity(const std::string& quantity) {
  const KeyFigure* figure = FindKeyFigure(quantity);
  return figure != nullptr && figure->in_limits && quantity == figure->name ? figure : nullptr;
}

std::string LimitQuantityNames() {
  std::string names;
  for (const KeyFigure& figure : kKeyFigures) {
    if (figure.in_limits) names += (names.empty() ? "" : ", ") + std::string(figure.name);
  }
  return names;
}

namespace {

// The limits file's words for what is judged and by which rule.
constexpr EnumName<LimitStatistic> kLimitStatisticNames[] = {{LimitStatistic::kValue, "value"},
                                                             {LimitStatistic::kSigma, "sigma"},
                                                             {LimitStatistic::kLargest, "largest"},
                                                             {LimitStatistic::kVariation, "variation"}};
constexpr EnumName<DecisionRule> kDecisionRuleNames[] = {{DecisionRule::kSimple, "simple"},
                                                         {DecisionRule::kGuarded, "guarded"}};

double PositiveNumber(const yaml::Located& value) {
  const double number = value.Double();
  if (!(number > 0.0)) value.Fail(QuoteForMessage(value.String()) + " must be greater than 0");
  return number;
}

// A criterion's `statistic:` and `over:`.
void ReadStatistic(const yaml::Located& entry, LimitCriterion* criterion) {
  if (entry.Has("statistic")) {
    const yaml::Located statistic = entry["statistic"];
    const std::string text = statistic.String();
    const bool coefficient = criterion->kind == LimitKind::kCoefficient;
    // The noise figures are measured at one temperature: they have no curve to take a range of.
    const bool has_curve = HasTemperatureCurve(*FindLimitQuantity(criterion->quantity));
    if (!ValueOf(kLimitStatisticNames, text, &criterion->statistic)) {
      statistic.Fail(QuoteForMessage(text) + " is not a statistic (known: " + AllNames(kLimitStatisticNames) +
                     ")");
    }
    if (criterion->statistic == LimitStatistic::kSigma && !coefficient)
      statistic.Fail(criterion->quantity + " has no 1-sigma");
    if ((criterion->statistic == LimitStatistic::kLargest ||
         criterion->statistic == LimitStatistic::kVariation) &&
        !has_curve)
      statistic.Fail(criterion->quantity + " does not vary with temperature in the model");
  }
  if (entry.Has("over")) {
    const yaml::Located over = entry["over"];
    if (criterion->statistic != LimitStatistic::kLargest &&
        criterion->statistic != LimitStatistic::kVariation)
      over.Fail("a range takes `statistic: largest` or `statistic: variation`");
    const std::vector<double> range = over.Doubles(2);
    if (!(range[0] < range[1])) over.Fail("expected [lo, hi] with lo < hi");
    criterion->over_c = std::array<double, 2>{range[0], range[1]};
  }
}

LimitCriterion ReadCriterion(const yaml::Located& entry, const Limits& limits) {
  entry.RejectUnknownKeys(
      {"quantity", "axes", "statistic", "over", "max_abs", "min", "max", "covers", "covers_tolerance"});
  LimitCriterion criterion;
  const yaml::Located quantity = entry["quantity"];
  criterion.quantity = quantity.String();
  const KeyFigure* known = FindLimitQuantity(criterion.quantity);
  if (known == nullptr) {
    quantity.Fail("unknown quantity " + QuoteForMessage(criterion.quantity) +
                  " (known: " + LimitQuantityNames() + ")");
  }
  criterion.kind = LimitKindOf(*known);
  criterion.unit = known->unit;
  const std::vector<std::string> all_axes = KeyFigureAxes(*known);
  if (known->source == FigureSource::kScaleError) {
    const bool gyro = IsGyroFigure(*known);
    if ((gyro ? limits.nominal_gyro_scale : limits.nominal_accel_scale) == 0.0) {
      quantity.Fail(std::string("needs nominal.") + (gyro ? "gyro_scale" : "accel_scale") +
                    " (raw per rad/s or per m/s^2) in the limits file");
    }
  }

  if (entry.Has("axes")) {
    const yaml::Located axes = entry["axes"];
    if (all_axes.empty()) axes.Fail(criterion.quantity + " has no axes");
    for (size_t i = 0; i < axes.Size(); ++i) {
      const std::string axis = axes.At(i).String();
      bool valid = false;
      for (const std::string& a : all_axes) valid = valid || a == axis;
      if (!valid) axes.At(i).Fail("unknown axis " + QuoteForMessage(axis) + " (known: " + known->axes + ")");
      criterion.axes.push_back(axis);
    }
    if (criterion.axes.empty()) axes.Fail("an empty list of axes checks nothing");
  } else {
    criterion.axes = all_axes;
  }

  ReadStatistic(entry, &criterion);
  if (criterion.kind == LimitKind::kCoverage) {
    if (entry.Has("max_abs"))
      entry["max_abs"].Fail(criterion.quantity + " takes `covers: [lo, hi]`, not max_abs");
    const yaml::Located covers = entry["covers"];
    const std::vector<double> range = covers.Doubles(2);
    if (!(range[0] < range[1])) covers.Fail("expected [lo, hi] with lo < hi");
    criterion.covers_c = {range[0], range[1]};
    if (entry.Has("covers_tolerance")) {
      const yaml::Located tolerance = entry["covers_tolerance"];
      criterion.covers_tolerance_c = tolerance.Double();
      if (!(criterion.covers_tolerance_c >= 0.0)) tolerance.Fail("must be a number >= 0");
    }
  } else {
    if (entry.Has("covers")) entry["covers"].Fail("only fit_temp_range_c takes `covers`");
    if (entry.Has("covers_tolerance")) entry["covers_tolerance"].Fail("only fit_temp_range_c takes it");
    const bool bounds = entry.Has("min") || entry.Has("max");
    if (bounds && entry.Has("max_abs")) entry["max_abs"].Fail("give max_abs, or min and/or max, not both");
    if (!bounds) {
      criterion.max_abs = PositiveNumber(entry["max_abs"]);
    } else {
      if (criterion.statistic == LimitStatistic::kSigma) entry.Fail("a 1-sigma takes max_abs, not min/max");
      if (criterion.statistic == LimitStatistic::kVariation)
        entry.Fail("a variation takes max_abs, not min/max");
      if (entry.Has("min")) criterion.min = entry["min"].Double();
      if (entry.Has("max")) criterion.max = entry["max"].Double();
      if (criterion.min && criterion.max && !(*criterion.min < *criterion.max))
        entry["max"].Fail("expected min < max");
    }
  }
  return criterion;
}

}  // namespace

const char* DecisionRuleName(DecisionRule rule) { return NameOf(kDecisionRuleNames, rule); }

Limits ReadLimits(const std::string& path) {
  const YAML::Node root_node = yaml::LoadFile(path);
  const yaml::Located root{&path, root_node, ""};
  root.RejectUnknownKeys({"format", "version", "name", "nominal", "criteria", "decision_rule", "guard_band"});
  root.RequireFormat("imufit-limits", kLimitsFormatVersion);
  Limits limits;
  limits.path = path;
  if (root.Has("name")) limits.name = root["name"].String();
  if (root.Has("nominal")) {
    const yaml::Located nominal = root["nominal"];
    nominal.RejectUnknownKeys({"gyro_scale", "accel_scale"});
    if (nominal.Has("gyro_scale")) limits.nominal_gyro_scale = PositiveNumber(nominal["gyro_scale"]);
    if (nominal.Has("accel_scale")) limits.nominal_accel_scale = PositiveNumber(nominal["accel_scale"]);
  }
  if (root.Has("decision_rule")) {
    const yaml::Located rule = root["decision_rule"];
    const std::string text = rule.String();
    if (!ValueOf(kDecisionRuleNames, text, &limits.decision_rule))
      rule.Fail(QuoteForMessage(text) + " is not a decision rule (known: " + AllNames(kDecisionRuleNames) +
                ")");
  }
  if (root.Has("guard_band")) {
    if (limits.decision_rule != DecisionRule::kGuarded) {
      root["guard_band"].Fail("a guard band needs `decision_rule: guarded`");
    }
    limits.guard_band_u = PositiveNumber(root["guard_band"]);
  }
  const yaml::Located criteria = root["criteria"];
  for (size_t i = 0; i < criteria.Size(); ++i)
    limits.criteria.push_back(ReadCriterion(criteria.At(i), limits));
  if (limits.criteria.empty()) criteria.Fail("no criteria: a limits file must check something");
  return limits;
}

}  // namespace imufit
