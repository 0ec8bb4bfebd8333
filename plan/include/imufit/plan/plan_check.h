// imufit — `imufit plan check`: what a plan will determine, before the chamber time is spent.
//
// The planned run (the plan's segments at the schedule of `imufit simulate`: soaks or a ramp, dwell,
// transition, sample rate) is reduced to the windows the fit would see, with the raw means of the
// nominal unit and the noise of the mean that the schedule's white noise gives; the fit's own
// problem on them gives the covariance it will report (fit/plan_information.h). From it: the
// predicted 1-sigma of every coefficient term against its tolerance, the weak directions, the most
// correlated pairs, what each segment contributes (leave-one-segment-out by a low-rank downdate of
// the information), the chamber hours the tolerances need and where the temperatures should be.
#ifndef IMUFIT_PLAN_PLAN_CHECK_H_
#define IMUFIT_PLAN_PLAN_CHECK_H_

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/fit/plan_information.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"

namespace imufit {

// The windows the fit will cut from a run of `segments` under `schedule` (the simulator's timing:
// every pass through the plan, dwell then transition): the run's time stamps, labels and
// temperatures through the fit's own WindowBuilder with `windows` (so trims, splits on a ramp,
// merged remainders and occurrences too short to keep are the fit's), with the nominal unit's raw
// means (raw = truth) and per-sample spreads from the schedule's white noise densities. What the
// windows leave out is counted in `stats` when not null.
std::vector<Window> PlannedWindows(const std::vector<TableSegment>& segments, const TableSite& site,
                                   const SimulationOptions& schedule, const WindowOptions& windows,
                                   WindowStats* stats = nullptr);

struct PlanCheckOptions {
  // Coverage factor: a tolerance is met when z * sigma <= tolerance.
  double z = 2.0;
  // Tolerances of the 25 degC value (and over the range) of a coefficient group, display units
  // (PlanGroupUnit): "gyro.bias", "accel.scale", ... (groups missing: no tolerance).
  std::map<std::string, double> tolerances;
  // The range the unit is specified over, degC (absent: the plan's own).
  std::optional<std::array<double, 2>> spec_range_c;
  // The table's latitude, deg (absent: the plan's own).
  std::optional<double> latitude_deg;
  // A direction weaker than this fraction of the strongest (column-normalised Jacobian) is named.
  double weak_tolerance = 1e-4;
  // A segment whose removal changes every sigma by less than this fraction could be cut.
  double cut_loss = 0.01;
  // The windows the fit will cut (run/windows.h): the same options as `imufit fit`'s.
  WindowOptions windows;
  // With a limits file: the least ratio of a criterion's tolerance to the expanded uncertainty
  // U = z sigma the plan will achieve (4 for the 4:1 of metrology's test uncertainty ratio).
  double min_ratio = 4.0;
};

// Every option of PlanCheckOptions, described once (model/option_table.h; plan_options.cc).
const OptionTable<PlanCheckOptions>& PlanCheckOptionTable();

// The coefficient groups a tolerance may be given for: "gyro.bias", ..., "accel.misalignment".
const std::vector<std::string>& PlanGroups();

// Reads "GROUP=VALUE" pairs (one a line, or separated by ',') into `values`, GROUP one of PlanGroups()
// and VALUE > 0 in its display unit: "" or what is wrong.
std::string ParseGroupValues(const std::string& text, std::map<std::string, double>* values);
// The same pairs written back, separated by ','.
std::string GroupValuesText(const std::map<std::string, double>& values);

// Sets the schedule's white noise and bias instability from a noise YAML (`imufit allan
// --noise-yaml`): the worst axis of each sensor. Throws InputError naming the file.
void ApplyNoiseYaml(const std::string& path, SimulationOptions* schedule);

// "deg/s", "mg", "ppm", "mrad", "deg/s/g" for a group "gyro.bias", ...; the factor SI -> display.
std::string PlanGroupUnit(const std::string& group);
double PlanGroupFactor(const std::string& group);

// One coefficient term's prediction, display units (per degC^term for term > 0).
struct PlanRow {
  std::string name;   // "gyro bias x (linear term)": the fit's naming
  std::string group;  // "gyro.bias"
  std::string unit;   // "deg/s/degC"
  bool gyro = true;
  int coefficient = 0;  // sensor_model.h layout
  int term = 0;
  double sigma = 0.0;        // 1-sigma of the term
  double sigma_range = 0.0;  // of the coefficient's value, the largest over the plan's range (term 0)
  double sigma_spec = 0.0;   // the same over the spec range (the plan's when not given)
  double tolerance = 0.0;    // of the group (0: none)
  double ratio = 0.0;        // z * sigma_spec / tolerance (z * sigma / tolerance for terms > 0); 0: none
  double white_share = 1.0;  // of the variance, the white noise's (the rest: wandering bias)
};

struct PlanSegmentEffect {
  int segment = 0;
  double limiting_loss = 0.0;  // relative growth of the limiting row's sigma without the segment
  double worst_loss = 0.0;     // the largest relative growth of any sigma (inf: essential)
};

struct PlanCheck {
  std::vector<std::string> undetermined;  // the fit's findings; nothing else is set when present
  std::vector<std::string> weak;
  std::vector<PlanRow> rows;  // sorted by ratio (then sigma / largest), the limiting one first
  struct Pair {
    std::string a, b;
    double correlation = 0.0;
  };
  std::vector<Pair> correlated;             // the most correlated pairs of 25 degC values
  std::vector<PlanSegmentEffect> segments;  // every segment, plan order
  std::vector<int> carriers;                // segments carrying the limiting row, most first
  std::vector<int> cuttable;                // segments cut with < cut_loss on every sigma
  double plan_hours = 0.0;                  // dwell and transitions
  double needed_hours = 0.0;                // for the tolerances (white-noise part); 0: no tolerance
  std::vector<std::string> warnings;        // a tolerance a longer dwell cannot meet, ...
  std::array<double, 4> best_soaks_c{};     // D-optimal soaks of a cubic over the plan's range
  std::array<double, 2> plan_range_c{};     // the planned temperatures
  double extrapolation_factor = 1.0;        // sigma at the spec ends / the largest over the plan
  double temperature_efficiency = 1.0;      // CubicDEfficiency of the windows' temperatures, spec range
  bool tolerance_unmet = false;             // some row's ratio above 1
  // What the fit's windows will leave out besides transitions and the trim (occurrences shorter
  // than the windows' minimum, ...), in words (LeftOutNote); "" when nothing.
  std::string left_out;
  double longest_static_s = 0.0;  // the longest dwell in a static segment (a noise stretch), s
};

// One criterion of a limits file judged against a plan (JudgeLimits).
struct PlanCriterion {
  std::string name;  // "accel_bias_mg x, y, z within -9.17 .. 35": the criterion in the file's terms
  std::string unit;  // the group's display unit (PlanGroupUnit), or the noise figure's
  bool noise = false;
  // A coefficient criterion: its tolerance (a [min, max] limit's half-width, else the limit), the U
  // the plan achieves (z times the largest sigma of the group's values over the spec range), and
  // their ratio against the minimum.
  double tolerance = 0.0;
  double expanded = 0.0;
  double ratio = 0.0;
  // A noise criterion: the static stretch it needs and the plan's longest, s.
  double needed_s = 0.0;
  double stretch_s = 0.0;
  bool met = false;  // ratio >= the minimum; or the stretch resolves the figure
};

// The D-efficiency for a cubic in temperature over `range_c` of a run whose windows (equal weights)
// lie at `temps_c`: (det M / det M*)^(1/4), M = mean of f f^T with f = (1, x, x^2, x^3), x the
// temperature scaled to [-1, 1], and M* that of the D-optimal soaks {-1, -1/sqrt(5), +1/sqrt(5), +1}
// (Hoel 1958; Kiefer-Wolfowitz: their variance function f^T M*^-1 f peaks at 4 exactly there).
// 1 for those soaks, 0.959 for four equally spaced, 0.603 for a uniform ramp ((25/189)^(1/4)); 0
// when M is singular.
double CubicDEfficiency(const std::vector<double>& temps_c, std::array<double, 2> range_c);

// Checks `segments` under `schedule` for the fit of `fit_options` (its bias stability from the
// schedule's bias instability and correlation time when those are given).
PlanCheck CheckPlan(const std::vector<TableSegment>& segments, const TableSite& site,
                    const SimulationOptions& schedule, const FitOptions& fit_options,
                    const PlanCheckOptions& options);

// CheckPlan's analysis of given windows (the planned ones, or a fitted run's: NominalWindows() of
// plan_prediction.h) for the fit of `fit`: everything but the hours, which need a schedule.
PlanCheck CheckWindows(const std::vector<Window>& windows, const std::vector<TableSegment>& segments,
                       const TableSite& site, const FitOptions& fit, const PlanCheckOptions& options);

// The people's table and the machines' YAML.
std::string PlanCheckText(const PlanCheck& check, const PlanCheckOptions& options);
std::string PlanCheckYaml(const PlanCheck& check, const std::vector<PlanCriterion>& criteria = {});
// The same content as the YAML, in JSON (every number finite).
std::string PlanCheckJson(const PlanCheck& check, const std::vector<PlanCriterion>& criteria = {});

}  // namespace imufit

#endif  // IMUFIT_PLAN_PLAN_CHECK_H_
