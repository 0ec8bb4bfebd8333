// imufit — the plan check after the run: what `plan check` predicts for the run that was made, next
// to what the fit achieved, for the certificate's settings.
//
// A fitted run's windows (its temperatures, durations and measured noise; windows lost are simply
// absent) are turned into those of the nominal unit (NominalWindows: raw means = truth, the noise
// stated in SI through the fitted scale factors, which is the fit's own weighting at nominal
// values) and checked as `plan check` checks planned ones (CheckWindows), for the fit the
// calibration's record describes (orders, groups fitted, bias stability) and the tolerances of the
// limits file. The first row of that check is the limiting coefficient; its predicted 1-sigma is
// compared with the sigma the fit wrote into the calibration, in the same display units.
#ifndef IMUFIT_PLAN_PLAN_PREDICTION_H_
#define IMUFIT_PLAN_PLAN_PREDICTION_H_

#include <map>
#include <string>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/plan/plan_check.h"

namespace imufit {

// The limits file's coefficient criteria as tolerances of their groups (a limit on the value or on
// its sigma: z sigma must fit inside it; a [min, max] limit: its half-width), in the groups'
// display units (PlanGroupUnit); the smallest where several criteria name one group.
// With min_ratio > 1 each tolerance is divided by it: a plan meets it when the criterion's
// tolerance is at least min_ratio times the U = z sigma it achieves (plan check's --min-ratio).
void TolerancesFromLimits(const Limits& limits, std::map<std::string, double>* tolerances,
                          double min_ratio = 1.0);

// The limits file's criteria judged against a plan's check, as metrology judges a calibration
// procedure: each coefficient criterion by the ratio of its tolerance (TolerancesFromLimits) to
// the U = z sigma the plan will achieve (the largest over the spec range of the criterion's
// axes), met when at least options.min_ratio; each noise criterion (ARW, bias instability) by
// whether the plan's longest static dwell is as long as measuring it needs (kMinAllanStretchS,
// kBiasInstabilityStretchS). Criteria of the fit record and coverage are not a plan's: left out.
std::vector<PlanCriterion> JudgeLimits(const Limits& limits, const PlanCheck& check,
                                       const PlanCheckOptions& options);

// The criteria for people: one line each, and a verdict line when one is not met.
std::string PlanCriteriaText(const std::vector<PlanCriterion>& criteria, const PlanCheckOptions& options);

// The windows of a fitted run as the plan check sees them: every window's raw means those of the
// nominal unit (the truth of its segment in `plan`), its per-sample spreads divided by the fitted
// scale factor of each axis at the window's temperature (the unit's noise in SI).
std::vector<Window> NominalWindows(const std::vector<Window>& run, const Plan& plan,
                                   const SensorModel& fitted);

// The plan's limiting coefficient, predicted on the run's own windows, and what the fit achieved.
struct LimitingPrediction {
  std::string why_not;  // "" when predicted; else why not (no fit record, no sigmas, ...)
  std::string name;     // the check's first row, "gyro bias z (linear term)"
  std::string unit;     // its display unit (PlanGroupUnit, per degC^term)
  int term = 0;
  double tolerance = 0.0;        // of its group; 0: no tolerances were given (then the row is the
                                 // check's first without them: the sigma that grows most over the range)
  double ratio = 0.0;            // z sigma / tolerance the check predicts (its largest over the range)
  double predicted_sigma = 0.0;  // 1-sigma of the term (term 0: the value at 25 degC)
  double achieved_sigma = -1.0;  // the calibration's sigma of the same term, same unit; < 0: none
  // The key figure of the same coefficient at 25 degC (term 0: "gyro_bias_dps.z"; "" otherwise), and
  // its expanded uncertainty U (k = 2) in the row's unit, which the certificate fills (< 0: none).
  std::string figure;
  double achieved_expanded = -1.0;
};

// `calibration` (its model, sigma and fit record) fitted to `windows` of a run of `plan`.
LimitingPrediction PredictLimiting(const Calibration& calibration, const Plan& plan,
                                   const std::vector<Window>& windows,
                                   const std::map<std::string, double>& tolerances);

// The certificate's one line: "gyro bias z: predicted sigma 1.2e-04 deg/s, achieved 1.3e-04 deg/s
// (U 2.7e-04 deg/s), at 25 degC; tolerance 0.01 deg/s, z sigma / tolerance 0.024 predicted".
std::string LimitingPredictionText(const LimitingPrediction& prediction);

}  // namespace imufit

#endif  // IMUFIT_PLAN_PLAN_PREDICTION_H_
