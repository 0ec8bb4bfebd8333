// imufit — `imufit plan check` of a hand procedure (io/hand_procedure.h; docs/plan.md, "A hand
// procedure"): the 1-sigma the field fit (fit/field_fit.h) will report for every coefficient of a
// session recorded by the procedure, before anyone records it.
//
// Method: sessions of the procedure are simulated (sim/field_session.h: its poses, dwells, turns,
// twists and rate, the nominal unit, the planned noise) and fitted by the field fit itself; the
// prediction of each coefficient is the RMS of the sigmas the fit reports over those sessions (the
// poses of a hand procedure are random: each session's sigma differs by a few per cent, which the
// check reports). What the fit refuses in any of them is the procedure's finding, in the fit's own
// words. Nothing is linearised beyond what the fit does: the prediction is the fit's answer, and
// tests/plan_test.cc compares it with the spread of the fitted values over many more sessions.
#ifndef IMUFIT_PLAN_HAND_CHECK_H_
#define IMUFIT_PLAN_HAND_CHECK_H_

#include <array>
#include <string>
#include <vector>

#include "imufit/fit/field_fit.h"
#include "imufit/io/hand_procedure.h"
#include "imufit/plan/plan_check.h"
#include "imufit/sim/field_session.h"
#include "imufit/sim/simulator.h"

namespace imufit {

// The simulated sessions a prediction averages over by default (`--sessions`).
inline constexpr int kHandCheckSessions = 3;

// What the check simulates and fits for `hand`: the session (poses, directions, twists, warm-up,
// gravity), the schedule (rate, dwell, temperature, and the noise of `noise`: its densities, bias
// instability and correlation time) and the field fit's options (orders, gravity).
struct HandSetup {
  FieldSessionOptions session;
  SimulationOptions schedule;
  FieldFitOptions fit;
};
HandSetup HandSetupOf(const HandProcedure& hand, const SimulationOptions& noise);

struct HandCheck {
  // What the fit refused in any simulated session, in its words, each with in how many of them
  // ("no pose with gravity near +y (the y axis down) (3 of 3 sessions)"). The procedure does not
  // reliably determine the model when not empty.
  std::vector<std::string> undetermined;
  // Every fitted coefficient term (held ones, such as the accelerometer misalignments of the body
  // frame, left out), display units; sigma the RMS over the sessions the fit accepted, sigma_range
  // (term 0) the largest over the session's temperatures, sigma_spec the same. Sorted by ratio
  // (z sigma_range / tolerance), then in the model's order.
  std::vector<PlanRow> rows;
  // Per row, the largest sigma of one session (term 0: over its temperatures): the poses and turns
  // a hand gives are random, and one session may fall short of the RMS.
  std::vector<double> sigma_worst;
  int sessions = 0;  // simulated
  int fitted = 0;    // of them, accepted by the fit (the rows' basis)
  // The largest relative difference of a row's sigma between two sessions (max / min - 1).
  double sigma_variation = 0.0;
  double session_s = 0.0;  // the mean length of a session, s
  std::array<double, 2> temp_range_c{0.0, 0.0};
  bool tolerance_unmet = false;
  // When a tolerance is unmet: each of a few changes of the procedure (longer dwells, more poses)
  // checked again, what it achieves.
  struct Alternative {
    std::string option;  // "--dwell 20", "--poses 18"
    double session_s = 0.0;
    double worst_ratio = 0.0;  // the largest ratio of the rows with a tolerance
    bool meets = false;
    std::string limiting;  // the first row's name
  };
  std::vector<Alternative> alternatives;
};

// The check of `setup` over `sessions` simulated sessions (seeds seed, seed + 1, ...), with the
// tolerances and z of `options`. `advise`: when a tolerance is unmet, check the alternatives too.
HandCheck CheckHandProcedure(const HandSetup& setup, const PlanCheckOptions& options, int sessions,
                             bool advise = true);

// The rows as a PlanCheck (rows, longest static stretch = the dwell) for JudgeLimits.
PlanCheck HandPlanCheck(const HandCheck& check, const HandSetup& setup);

std::string HandCheckText(const HandCheck& check, const HandSetup& setup, const PlanCheckOptions& options);
std::string HandCheckYaml(const HandCheck& check, const std::vector<PlanCriterion>& criteria, bool json);

}  // namespace imufit

#endif  // IMUFIT_PLAN_HAND_CHECK_H_
