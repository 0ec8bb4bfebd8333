// imufit — the plan file (docs/spec.md section 2): what the rate table did, segment by segment.
//
// The reader converts at the edge: rate_dps -> rad/s, latitude_deg -> rad; `up` and `north` are
// normalised, and `north` is made exactly perpendicular to `up` (it may be off by at most 1
// degree in the file); angle_deg -> angle_rad, `axis` normalised. A plan is refused (InputError)
// when a vector is zero or not three numbers, `north` is not horizontal or is given on a rate or
// turn segment, `axis` is given on a static segment, `angle_deg` is 0 or comes with `rate_dps` or
// `lever_arm_m`, a lever arm is longer than kMaxLeverArmM (millimetres written as metres), an id
// repeats, a key is unknown, or format/version are not ones this reader knows. The truth of each
// kind of segment: docs/conventions.md.
#ifndef IMUFIT_IO_PLAN_H_
#define IMUFIT_IO_PLAN_H_

#include <string>
#include <vector>

#include "imufit/model/rate_table.h"

namespace imufit {

inline constexpr int kPlanFormatVersion = 1;
// The longest lever arm (sensor from the table's axis) a plan may give, m: past any rate table's
// offsets; a centrifuge's arm is out of scope.
inline constexpr double kMaxLeverArmM = 3.0;

struct Plan {
  std::string path;    // the file it was read from
  std::string serial;  // may be empty
  // The climatic chamber's soak set-points, degC, as the plan states them (`soak_temps_c`); empty
  // when the plan does not say. A log whose temperatures disagree with them is refused
  // (pipeline/consistency.h, CheckRunTemperatures): a thermometer logged in Fahrenheit, a run of another
  // plan.
  std::vector<double> soak_temps_c;
  TableSite site;
  std::vector<TableSegment> segments;

  // The segment with `id`, or nullptr.
  const TableSegment* Find(int id) const;
};

Plan ReadPlan(const std::string& path);
// A plan from its YAML (or JSON) `text`, which messages and Plan::path name `name`.
Plan ReadPlanText(const std::string& text, const std::string& name);
// The YAML of `plan` (its path is not written; `comment`, when not empty, opens the file as '#'
// lines): ReadPlanText reads it back to the same site and segments (shortest round-trip numbers).
std::string PlanYaml(const Plan& plan, const std::string& comment);

}  // namespace imufit

#endif  // IMUFIT_IO_PLAN_H_
