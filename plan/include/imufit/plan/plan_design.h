// imufit — `imufit plan design`: the plan that meets the tolerances in the fewest hours.
//
// The candidates are table segments (static positions: the cube's 6 faces, 12 edges, 8 corners, or
// the segments of a given plan; rates: each magnitude as a +- pair about each face's axis, on a
// one-axis table, or about every position's direction on a two-axis one) and temperature
// set-points. An element is a segment at a soak: its windows' information I(s, t) = J^T J comes
// from the fit's own Jacobian (plan_information.h) of the plan of every candidate at every
// set-point. With F = P + sum I over the chosen segments S and soaks T (P: a prior from data-sheet
// values, so that F is invertible from the first step) the design
//
//   1. greedily adds the segment or soak with the largest fall of phi(F) = sum_r (z sigma_r / tol_r)^2
//      (the values over the range; a group without a tolerance must beat its data-sheet value) per
//      second of cost: a segment costs (transition +
//      dwell) at every chosen soak, a soak its thermal settling plus every chosen segment;
//   2. then exchanges (Fedorov): drops what the tolerances can spare, the dearest first, and swaps
//      a chosen element for an unchosen one of no higher cost when phi falls;
//
// until the white-noise covariance without the prior meets every tolerance. The result is checked
// with CheckPlan (with the wandering bias); where it still misses, the target tightens and the
// steps run again.
#ifndef IMUFIT_PLAN_PLAN_DESIGN_H_
#define IMUFIT_PLAN_PLAN_DESIGN_H_

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/plan/plan_check.h"

namespace imufit {

struct PlanDesignOptions {
  PlanCheckOptions check;  // the tolerances (at least one), z, spec range, latitude
  // Candidate positions: any of "faces", "edges", "corners", ',' separated (not used with a given
  // list of candidates).
  std::string positions = "faces,edges";
  // Rate magnitudes, deg/s, each run as a +- pair; none above max_rate_dps (the table's limit).
  std::vector<double> rates_dps = {100.0, 300.0};
  double max_rate_dps = 1000.0;
  // A two-axis table turns about any candidate direction; a one-axis table about a face's axis.
  bool two_axis = false;
  // The temperature set-points a soak may be at, degC.
  std::vector<double> set_points_c = {-40.0, -15.0, 10.0, 35.0, 60.0, 85.0};
  // Thermal settling of a soak (its cost before the first segment), s.
  double soak_settle_s = 1800.0;
  // Data-sheet 1-sigma of each group's value over the range (display units, PlanGroupUnit): the
  // prior. Groups missing take kDefaultPrior's.
  std::map<std::string, double> prior;
  // Exchange rounds at most.
  int max_exchange_rounds = 100;
  // The station's gravity, m/s^2, written into the plan (absent: the candidates' plan's; without
  // one, WGS84 normal gravity at --latitude; else standard gravity).
  std::optional<double> gravity_mps2;
  // The fit the plan is designed for (orders, groups fitted): `imufit fit`'s options of the model.
  FitOptions fit;
};

// Every option of PlanDesignOptions (with PlanCheckOptionTable()'s), described once.
const OptionTable<PlanDesignOptions>& PlanDesignOptionTable();

// The data-sheet values a MEMS unit typically states (the prior where none is given).
const std::map<std::string, double>& DefaultPlanPrior();

struct PlanDesign {
  std::vector<std::string> undetermined;  // what even every candidate cannot determine
  int candidate_segments = 0;
  int candidate_set_points = 0;
  bool met = false;                  // the final plan meets every tolerance (CheckPlan)
  std::vector<TableSegment> greedy;  // after the greedy steps
  std::vector<double> greedy_soaks_c;
  double greedy_hours = 0.0;
  PlanCheck greedy_check;
  std::vector<TableSegment> segments;  // the design: ids 1.. in plan order
  std::vector<double> soaks_c;         // ascending
  double hours = 0.0;                  // soaks' settling, transitions and dwells
  PlanCheck check;
};

// Hours of a plan of `segments` run at `soaks` (settling, then every segment's transition and dwell).
double PlanDesignHours(size_t segments, size_t soaks, const SimulationOptions& schedule,
                       const PlanDesignOptions& options);

// The candidate segments the options name (ids 1..).
std::vector<TableSegment> DesignCandidates(const PlanDesignOptions& options);

// Designs a plan from `candidates` (DesignCandidates() when empty) on `site`, run under `schedule`
// (its soak temperatures are the design's). Throws std::invalid_argument for options that cannot
// work (no tolerance, a rate above the limit).
PlanDesign DesignPlan(std::vector<TableSegment> candidates, const TableSite& site,
                      const SimulationOptions& schedule, const PlanDesignOptions& options);

// For people: the candidates, the design before and after the exchange, their hours and tables.
std::string PlanDesignText(const PlanDesign& design, const PlanDesignOptions& options);

}  // namespace imufit

#endif  // IMUFIT_PLAN_PLAN_DESIGN_H_
