// imufit — a unit's uncertainty budget (JCGM 100, the GUM): the fit's own covariance (Type A,
// with the bias stability when the fit was given one) and the Type B sources the station declares
// (io/station.h: the table's rate accuracy, its axis tilt, the fixture's orthogonality, the unit's
// alignment in it, local gravity, the thermometer), propagated to every coefficient key figure.
//
// Propagation (GUM 5.1.3, the law of propagation of uncertainty): the fit is re-solved with the
// plan's truth perturbed by one standard uncertainty of each component of each source
// (fit/truth_perturbation.h); the change of a figure is that component's contribution c_i u(x_i).
// Nothing is linearised by hand: the re-solved fit is the model the same data give under that truth,
// every coupling (a tilt seen as misalignment, a thermometer offset through the thermal slope)
// included. The components are independent; u_c^2 = u_A^2 + sum_i (c_i u(x_i))^2; U = k u_c, k = 2.
// MonteCarloTypeB() (GUM Supplement 1) draws every component at once from its distribution and
// re-solves: its spread checks the propagation (tests/budget_test.cc).
//
// Not covered: the unit's drift after calibration, its hysteresis and repeatability between runs
// (one run measures neither), the model's own error (a term the model does not have), the table's
// position (turn angle) accuracy, sources the station does not declare.
#ifndef IMUFIT_FACTORY_UNCERTAINTY_BUDGET_H_
#define IMUFIT_FACTORY_UNCERTAINTY_BUDGET_H_

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/io/station.h"
#include "imufit/run/windows.h"

namespace imufit {

// One component of one Type B source and what it contributes to a figure.
struct BudgetLine {
  std::string source;         // kStationUncertainties' title, with the component: "Fixture alignment about x"
  std::string taken_from;     // the station's `source` text
  std::string input_text;     // u(x_i) as declared: "10 ppm", "20 arcsec (half width, rectangular)"
  double contribution = 0.0;  // c_i u(x_i) in the figure's unit, signed
};

struct FigureBudget {
  std::string name;  // the key figure's name, e.g. "gyro_scale_per_dps.x"
  std::string unit;
  double value = 0.0;
  double type_a = 0.0;             // the fit's 1-sigma (Type A)
  std::vector<BudgetLine> type_b;  // largest |contribution| first
  double combined = 0.0;           // u_c
  double expanded = 0.0;           // U = k u_c
};

// The top contributors of a class of figures (a quantity over its axes): each source's root mean
// square contribution over the axes.
struct BudgetClassLine {
  std::string source;
  double rms = 0.0;
};
struct BudgetClass {
  std::string quantity;  // "gyro_scale_per_dps"
  std::string unit;
  double type_a_rms = 0.0;
  std::vector<BudgetClassLine> top;  // Type B, largest first, at most kBudgetTopContributors
};
inline constexpr size_t kBudgetTopContributors = 3;

struct UncertaintyBudget {
  double coverage_factor = kCoverageFactor;
  std::vector<StationUncertainty> inputs;  // the Type B sources propagated (empty: Type A alone)
  bool bias_stability_included = false;    // the fit's Type A includes the bias stability
  std::vector<FigureBudget> figures;       // every coefficient key figure (KeyFigures order)
  std::vector<BudgetClass> classes;
  std::string covers, not_covered;  // what U covers and what it does not, in words

  // The models the Type B contributions are differences of: the fit re-solved on the plan's truth
  // (`resolved`), and once per component with the truth off by its u (`moved`, with the component's
  // BudgetLine source, taken_from and input text; contribution unset). Empty without Type B sources.
  std::optional<SensorModel> resolved;
  std::vector<std::pair<BudgetLine, SensorModel>> moved;

  // The figure `name`'s budget; nullptr when it has none.
  const FigureBudget* Find(const std::string& name) const;
  // The budget of every coefficient key figure of `calibration` at `temp_c` (the same sources, the
  // contributions evaluated there: a statistic over a temperature range is judged with them); at
  // 25 degC, `figures`.
  std::vector<FigureBudget> At(const Calibration& calibration, double temp_c) const;
};

// The budget of `calibration`'s coefficient key figures: its Type A sigmas and the Type B `sources`
// propagated by re-solving the fit on `windows` of `plan` (the settings of its `fit:` record; a
// calibration without one, or `sources` empty, gets Type A alone).
UncertaintyBudget ComputeBudget(const Calibration& calibration, const Plan& plan,
                                const std::vector<Window>& windows,
                                const std::vector<StationUncertainty>& sources);

// The budget of a calibration by hand (fit --field, its `body_frame` set): no station, no table,
// no plan. Type A: the fit's sigmas (the session's noise and, through the fit's noise scales, the
// hand's tremor and drift during the session). Type B: the local gravity the fit took |a| = g from,
// by where it came from (`fit: field: gravity_source`): kGravityStandard, 9.80665 m/s^2 for a site
// not given, is anywhere on Earth's surface from the equator to the poles and from sea level to
// 1000 m: kStandardGravityHalfWidthMps2, rectangular; kGravityFromLatitude, WGS-84 normal gravity,
// is off by the site's gravity anomaly: kNormalGravityAnomalyMps2 (standard uncertainty);
// kGravityStated, the user's value, is taken as exact (its own uncertainty is not known here: the
// certificate says so). Propagation is exact: the field fit's cost is invariant under
// g -> g (1 + e), S_a -> S_a / (1 + e), H -> H / (1 + e), so the moved model is the calibration's
// with those terms scaled (every other coefficient unchanged).
inline constexpr double kStandardGravityHalfWidthMps2 = 0.03;
inline constexpr double kNormalGravityAnomalyMps2 = 5e-4;  // 50 mGal
UncertaintyBudget ComputeFieldBudget(const Calibration& calibration);

// GUM Supplement 1: `trials` fits, each with every component of `sources` drawn from its
// distribution (normal, or rectangular for a half width; seeded), and the standard deviation of
// each coefficient key figure (KeyFigures order) over them: the Type B part alone.
std::vector<double> MonteCarloTypeB(const Calibration& calibration, const Plan& plan,
                                    const std::vector<Window>& windows,
                                    const std::vector<StationUncertainty>& sources, int trials,
                                    unsigned seed);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_UNCERTAINTY_BUDGET_H_
