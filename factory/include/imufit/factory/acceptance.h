// imufit — a unit's key figures and its acceptance verdict against a limits file.
//
// Key figures (their table, names, units and sources: io/key_figures.h) are the calibration's
// coefficients at 25 degC, evaluated through the model's polynomial (whatever the calibration's
// reference_temp_c), in the units a test engineer reads (engineering_units.h: deg/s, mg,
// raw/(deg/s), raw/g, mrad, deg/s/g), each with its 1-sigma from the `sigma` tree; plus the fit's
// residual RMS (deg/s, mg) and segments missing from the calibration's `fit:` block and the gyro
// noise figures of a `noise:` block (io/noise_file.h).
#ifndef IMUFIT_FACTORY_ACCEPTANCE_H_
#define IMUFIT_FACTORY_ACCEPTANCE_H_

#include <string>
#include <utility>
#include <vector>

#include "imufit/base/verdict.h"
#include "imufit/io/calibration.h"
#include "imufit/io/key_figures.h"
#include "imufit/io/limits.h"
#include "imufit/report/engineering_units.h"

namespace imufit {
struct UncertaintyBudget;
}

namespace imufit {

struct Figure {
  std::string name;         // quantity.axis, e.g. "gyro_bias_dps.x", "gyro_residual_rms_dps"
  std::string coefficient;  // the calibration's path, e.g. "gyro.bias.x"; "fit.gyro_residual_rms"
  std::string unit;         // "deg/s", "mg", ...
  double value = 0.0;
  double sigma = -1.0;  // 1-sigma; < 0 when the calibration has none
  // U (k = kCoverageFactor): the one expanded uncertainty every output states for this figure. A
  // coefficient's is its uncertainty budget's (Type A and the station's Type B sources) when
  // KeyFigures() is given one, else k x sigma; < 0 when there is no sigma.
  double expanded = -1.0;
  // A coefficient evaluated at 25 degC outside the calibration's fitted temperature range: the
  // polynomial extrapolated.
  bool extrapolated = false;
  // Not measured by this run (a noise term the run cannot resolve): why, and how to supply it; the
  // figure is then judged as missing, with this as the reason.
  std::string unresolved;
};

// A figure of `value` and 1-sigma `sigma` (< 0: none), within the fitted range and resolved.
inline Figure MakeFigure(std::string name, std::string coefficient, std::string unit, double value = 0.0,
                         double sigma = -1.0) {
  Figure figure;
  figure.name = std::move(name);
  figure.coefficient = std::move(coefficient);
  figure.unit = std::move(unit);
  figure.value = value;
  figure.sigma = sigma;
  figure.expanded = sigma >= 0.0 ? kCoverageFactor * sigma : -1.0;
  return figure;
}

// A figure or limit quantity in words (its KeyFigure::title with the axis), for a reader:
// "gyro_bias_dps.x" -> "Gyro bias X", "gyro_g_sensitivity_dpsg.xy" -> "Gyro g-sensitivity X from Y",
// "gyro_misalignment_mrad.xy" -> "Gyro misalignment X from Y", "fit_temp_range_c" -> "Fitted
// temperature range"; a name it does not know is returned as it is.
std::string FigureTitle(const std::string& name);

// Every figure of the calibration at 25 degC (coefficients, noise figures, the fit record's), in
// the order of kKeyFigures.
// `temp_c`: the coefficients at another temperature (the statistics over a range of a limits file).
// `budget`: the coefficients' U are its (at `temp_c`: UncertaintyBudget::At); without, k x sigma.
std::vector<Figure> KeyFigures(const Calibration& calibration, double temp_c = kFigureTempC,
                               const UncertaintyBudget* budget = nullptr);
// The figure called `name` (or with that `coefficient` path); nullptr when there is none.
const Figure* FindFigure(const std::vector<Figure>& figures, const std::string& name);

// "PASS", "conditional pass", "conditional fail", "FAIL" (Outcome: base/verdict.h).
inline const char* OutcomeName(Outcome outcome) { return NameOf(kOutcomeNames, outcome); }
// The judgement of a figure the run does not measure (Figure::unresolved), as stored.
inline constexpr const char* kNotResolved = "not resolved";

struct CriterionResult {
  std::string name;   // e.g. "|gyro_bias_dps.x|", "sigma(gyro_bias_dps.x)", "fit_temp_range_c"
  std::string title;  // in words (FigureTitle): "Gyro bias X", "Gyro bias X, 1-sigma"
  std::string unit;
  double measured = 0.0;  // |value| for max_abs criteria; for coverage: the margin's side that binds
  double limit = 0.0;
  double margin = 0.0;  // limit - |measured| (coverage: degC to spare at the tighter end); >= 0 passes
  std::string measured_text;
  std::string limit_text;
  // The margin with its unit ("0.0207 deg/s/g", "20 degC"; coverage: "1 segment", segments to spare);
  // "none" when the value is not in the calibration (there is nothing to measure a margin from).
  std::string margin_text;
  double expanded = -1.0;  // U of the measured value (k = 2); < 0: none (then no conditional outcome)
  Outcome outcome = Outcome::kFail;
  // Accepted under the verdict's decision rule: simple, a value inside its limit; guarded, a value
  // inside its limit less the guard band.
  bool pass = false;
  std::string reason;  // why, when it is not a plain PASS: "within U = 0.002 deg/s of the limit"
};

// A decision rule in words, for the certificate and the lot page: "simple acceptance (ILAC-G8): ...";
// `guard_band_u`, the guard band in U, for guarded acceptance.
std::string DecisionRuleText(DecisionRule rule, double guard_band_u);

struct Verdict {
  std::string limits_name;
  std::vector<CriterionResult> criteria;
  bool pass = true;
  DecisionRule rule = DecisionRule::kSimple;
  double guard_band_u = 1.0;

  int Failed() const;
  // Criteria whose value lies within U of the limit (conditional pass or fail).
  int Conditional() const;
  // The rule in words (DecisionRuleText).
  std::string RuleText() const { return DecisionRuleText(rule, guard_band_u); }
  // "|gyro_g_sensitivity_dpsg.xx| 0.0712 > 0.05 deg/s/g; ..." — the failed criteria, one line.
  // `in_words`: the criteria by their titles ("Gyro g-sensitivity X from X 0.0712 deg/s/g (limit ...)").
  std::string FailedSummary(bool in_words = false) const;
  // The table `imufit fit --limits` prints: criterion, measured, limit, margin, PASS/FAIL.
  std::string Table() const;
};

// `measured`: figures measured elsewhere (a certificate's own Allan deviation: ARW, bias
// instability) that take the place of the calibration's figures of the same name.
// `budget`: the expanded uncertainty of each coefficient figure (uncertainty_budget.h), at 25 degC
// and at every temperature a statistic over a range is taken at; without it (or for a figure it
// lacks), U = 2 x the figure's 1-sigma. A measured figure's U is its own (Figure::expanded).
Verdict EvaluateLimits(const Limits& limits, const Calibration& calibration,
                       const std::vector<Figure>& measured = {}, const UncertaintyBudget* budget = nullptr);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_ACCEPTANCE_H_
