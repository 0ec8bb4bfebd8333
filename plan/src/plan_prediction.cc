// The plan check after the run (plan_prediction.h): the run's windows at nominal values, checked,
// and the limiting row's predicted sigma next to the calibration's.
#include "imufit/plan/plan_prediction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "imufit/io/key_figures.h"
#include "imufit/model/constants.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/static_stretch.h"

namespace imufit {
namespace {

// The fit the calibration's record describes, with the bias stability its sigmas were weighted by
// (the information depends on it).
FitOptions FitOptionsOf(const FitRecord& record) {
  FitOptions options = FitOptionsOfRecord(record);
  options.gyro_bias_stability_radps = record.gyro_bias_stability_radps.value_or(0.0);
  options.accel_bias_stability_mps2 = record.accel_bias_stability_mps2.value_or(0.0);
  options.bias_correlation_s = record.bias_correlation_s.value_or(options.bias_correlation_s);
  return options;
}

// Scale factor of `axis` at `temp_c`, raw per SI unit.
double ScaleAt(const SensorModel& model, bool gyro, int axis, double temp_c) {
  const double* params =
      (gyro ? model.gyro.data() : model.accel.data()) + (kScaleCoefficient + axis) * kPolynomialTerms;
  return std::abs(EvaluateTemperaturePolynomial(params, model.basis.Argument(temp_c)));
}

// The calibration's 1-sigma of `row`'s term in the row's display unit: a raw-unit coefficient over
// the scale factor of its axis (the row of a g-sensitivity) at 25 degC, as the nominal unit (scale
// 1) states it. Exact for the 25 degC reference imufit writes.
double AchievedSigma(const Calibration& calibration, const PlanRow& row) {
  const SensorModel& model = calibration.model;
  const double* sigmas = row.gyro ? calibration.sigma->gyro.data() : calibration.sigma->accel.data();
  const int c = row.coefficient;
  double divisor = 1.0;
  if (c < kMisalignmentCoefficient) divisor = ScaleAt(model, row.gyro, c % 3, kReferenceTempC);
  if (c >= kGSensitivityCoefficient)
    divisor = ScaleAt(model, row.gyro, (c - kGSensitivityCoefficient) / 3, kReferenceTempC);
  const double sigma = sigmas[c * kPolynomialTerms + row.term] / std::pow(model.basis.half_range_c, row.term);
  return divisor > 0.0 ? sigma * PlanGroupFactor(row.group) / divisor : -1.0;
}

// The key figure (io/key_figures.h) of a 25 degC coefficient: its group's.
std::string FigureOf(const PlanRow& row) {
  if (row.term != 0) return "";
  for (const KeyFigure& quantity : kKeyFigures) {
    if (quantity.source == FigureSource::kCoefficient && row.group == quantity.path)
      return std::string(quantity.name) + "." + kCoefficientNames[row.coefficient].axis;
  }
  return "";
}

// A coefficient criterion's tolerance in its group's display unit (PlanGroupUnit): the limit on
// the value or on its sigma, a [min, max] limit's half-width; 0 when the criterion is not on a
// coefficient with a temperature curve. `quantity` is set to the criterion's key figure.
double CoefficientTolerance(const LimitCriterion& criterion, const KeyFigure** quantity) {
  *quantity = FindLimitQuantity(criterion.quantity);
  const double half_width = criterion.max_abs > 0.0          ? criterion.max_abs
                            : criterion.min && criterion.max ? 0.5 * (*criterion.max - *criterion.min)
                                                             : 0.0;
  if (!(half_width > 0.0) || *quantity == nullptr || !HasTemperatureCurve(**quantity)) return 0.0;
  // The figure's own unit, except a scale error's (PlanGroupUnit: ppm).
  const double factor = (*quantity)->source == FigureSource::kScaleError ? 1e6 / (*quantity)->per_unit : 1.0;
  return half_width * factor;
}

// A criterion in the limits file's terms: "accel_bias_mg x, y within -9.17 .. 35".
std::string CriterionName(const LimitCriterion& criterion) {
  std::string name = criterion.quantity;
  for (size_t i = 0; i < criterion.axes.size(); ++i) name += (i == 0 ? " " : ", ") + criterion.axes[i];
  char bound[96];
  if (criterion.max_abs > 0.0) {
    std::snprintf(bound, sizeof bound, " within +-%g", criterion.max_abs);
  } else if (criterion.min && criterion.max) {
    std::snprintf(bound, sizeof bound, " within %g .. %g", *criterion.min, *criterion.max);
  } else if (criterion.max) {
    std::snprintf(bound, sizeof bound, " at most %g", *criterion.max);
  } else if (criterion.min) {
    std::snprintf(bound, sizeof bound, " at least %g", *criterion.min);
  } else {
    bound[0] = '\0';
  }
  return name + bound;
}

}  // namespace

void TolerancesFromLimits(const Limits& limits, std::map<std::string, double>* tolerances, double min_ratio) {
  for (const LimitCriterion& criterion : limits.criteria) {
    const KeyFigure* quantity = nullptr;
    const double tolerance = CoefficientTolerance(criterion, &quantity) / min_ratio;
    if (!(tolerance > 0.0)) continue;
    auto [it, inserted] = tolerances->emplace(quantity->path, tolerance);
    if (!inserted) it->second = std::min(it->second, tolerance);
  }
}

std::vector<PlanCriterion> JudgeLimits(const Limits& limits, const PlanCheck& check,
                                       const PlanCheckOptions& options) {
  std::vector<PlanCriterion> criteria;
  for (const LimitCriterion& criterion : limits.criteria) {
    const KeyFigure* quantity = FindLimitQuantity(criterion.quantity);
    if (quantity == nullptr) continue;
    PlanCriterion judged;
    judged.name = CriterionName(criterion);
    if (quantity->source == FigureSource::kNoise) {
      judged.noise = true;
      judged.unit = quantity->unit;
      judged.needed_s = quantity->noise_term == kRandomWalk ? kMinAllanStretchS : kBiasInstabilityStretchS;
      judged.stretch_s = check.longest_static_s;
      judged.met = judged.stretch_s >= judged.needed_s;
      criteria.push_back(judged);
      continue;
    }
    judged.tolerance = CoefficientTolerance(criterion, &quantity);
    if (!(judged.tolerance > 0.0)) continue;
    judged.unit = PlanGroupUnit(quantity->path);
    for (const PlanRow& row : check.rows) {
      if (row.group != quantity->path || row.term != 0) continue;
      const std::string axis = kCoefficientNames[row.coefficient].axis;
      if (!criterion.axes.empty() &&
          std::find(criterion.axes.begin(), criterion.axes.end(), axis) == criterion.axes.end()) {
        continue;
      }
      judged.expanded = std::max(judged.expanded, options.z * std::max(row.sigma_range, row.sigma_spec));
    }
    if (!(judged.expanded > 0.0)) continue;  // a group the fit holds: nothing to judge
    judged.ratio = judged.tolerance / judged.expanded;
    judged.met = judged.ratio >= options.min_ratio;
    criteria.push_back(judged);
  }
  return criteria;
}

std::string PlanCriteriaText(const std::vector<PlanCriterion>& criteria, const PlanCheckOptions& options) {
  std::string out;
  std::string unmet;
  for (const PlanCriterion& c : criteria) {
    char line[512];
    if (c.noise) {
      std::snprintf(line, sizeof line,
                    "criterion %s: needs a static stretch of %.0f s, the plan's longest is %.0f s: %s\n",
                    c.name.c_str(), c.needed_s, c.stretch_s,
                    c.met ? "resolved"
                          : "not resolved (lengthen a static dwell, or measure the noise apart: imufit allan "
                            "--noise-yaml)");
    } else {
      std::snprintf(line, sizeof line,
                    "criterion %s: tolerance %.4g %s / U %.4g %s = %.3g:1 (at least %.3g:1): %s\n",
                    c.name.c_str(), c.tolerance, c.unit.c_str(), c.expanded, c.unit.c_str(), c.ratio,
                    options.min_ratio, c.met ? "met" : "NOT MET");
    }
    out += line;
    if (!c.met) unmet += (unmet.empty() ? "" : "; ") + c.name;
  }
  if (!unmet.empty()) out += "verdict: the plan cannot judge " + unmet + "\n";
  return out;
}

std::vector<Window> NominalWindows(const std::vector<Window>& run, const Plan& plan,
                                   const SensorModel& fitted) {
  std::map<int, const TableSegment*> segments;
  for (const TableSegment& s : plan.segments) segments[s.id] = &s;
  std::vector<Window> windows;
  for (Window w : run) {
    const auto segment = segments.find(w.segment);
    if (segment == segments.end()) continue;
    const SegmentTruth truth = segment->second->IsTurn()
                                   ? TurnTruth(plan.site, *segment->second, w.DurationS())
                                   : TruthOf(plan.site, *segment->second);
    w.gyro_mean = truth.omega_radps;
    w.accel_mean = truth.a_mps2;
    for (int axis = 0; axis < 3; ++axis) {
      const double gyro_scale = ScaleAt(fitted, true, axis, w.temp_c);
      const double accel_scale = ScaleAt(fitted, false, axis, w.temp_c);
      if (!(gyro_scale > 0.0) || !(accel_scale > 0.0)) return {};
      w.gyro_std[axis] /= gyro_scale;
      w.gyro_noise[axis] /= gyro_scale;
      w.accel_std[axis] /= accel_scale;
      w.accel_noise[axis] /= accel_scale;
    }
    windows.push_back(w);
  }
  return windows;
}

LimitingPrediction PredictLimiting(const Calibration& calibration, const Plan& plan,
                                   const std::vector<Window>& windows,
                                   const std::map<std::string, double>& tolerances) {
  LimitingPrediction prediction;
  if (!calibration.fit || !calibration.sigma) {
    prediction.why_not = "the calibration has no fit record or no sigmas";
    return prediction;
  }
  const std::vector<Window> nominal = NominalWindows(windows, plan, calibration.model);
  if (nominal.empty()) {
    prediction.why_not = "no window of the run belongs to the plan";
    return prediction;
  }
  PlanCheckOptions options;
  options.tolerances = tolerances;
  const PlanCheck check =
      CheckWindows(nominal, plan.segments, plan.site, FitOptionsOf(*calibration.fit), options);
  if (!check.undetermined.empty() || check.rows.empty()) {
    prediction.why_not = "the run's windows do not determine the model at nominal values";
    return prediction;
  }
  const PlanRow& row = check.rows.front();
  prediction.name = row.name;
  prediction.unit = row.unit;
  prediction.term = row.term;
  prediction.tolerance = row.tolerance;
  prediction.ratio = row.ratio;
  prediction.predicted_sigma = row.sigma;
  prediction.achieved_sigma = AchievedSigma(calibration, row);
  prediction.figure = FigureOf(row);
  return prediction;
}

std::string LimitingPredictionText(const LimitingPrediction& p) {
  if (!p.why_not.empty()) return "not predicted: " + p.why_not;
  const auto number = [&](double value) {
    char text[40];
    std::snprintf(text, sizeof text, "%.3g ", value);
    return text + p.unit;
  };
  std::string line = p.tolerance > 0.0
                         ? p.name
                         : "no tolerances given (no limits file); the sigma that grows most over "
                           "the range, " +
                               p.name;
  line += ": predicted sigma " + number(p.predicted_sigma) + ", achieved " +
          (p.achieved_sigma >= 0.0 ? number(p.achieved_sigma) : std::string("not stated"));
  if (p.achieved_expanded >= 0.0) line += " (U " + number(p.achieved_expanded) + ")";
  if (p.term == 0) line += ", at 25 degC";
  if (p.tolerance > 0.0) {
    char ratio[80];
    std::snprintf(ratio, sizeof ratio, ", predicted %g sigma over the range / tolerance %.3g",
                  PlanCheckOptions().z, p.ratio);
    line += "; tolerance " + number(p.tolerance) + ratio;
  }
  return line;
}

}  // namespace imufit
