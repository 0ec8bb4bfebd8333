// imufit Python module: plan_check() and plan_design() (pipeline/plan_check.h, plan_design.h),
// what `imufit plan check` and `imufit plan design` print, as arrays.
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "binding.h"
#include "imufit/io/plan.h"
#include "imufit/model/constants.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"
#include "keyword_options.h"

namespace imufit::python {
namespace {

// The keywords split between the schedule (SimulationOptionTable()) and the function's own table;
// `tolerance` and `prior` may be dicts {group: value}. noise_yaml (a path) sets the noise first.
template <typename Options>
SimulationOptions SplitKeywords(const OptionTable<Options>& table, const std::string& where,
                                const py::dict& kwargs, Options* options) {
  py::dict own, schedule_keywords;
  py::object noise_yaml = py::none();
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name == "noise_yaml") {
      noise_yaml = py::reinterpret_borrow<py::object>(value);
    } else if (table.Find(name) != nullptr) {
      own[key] = (name == "tolerance" || name == "prior") && py::isinstance<py::dict>(value)
                     ? py::str(GroupValuesText(value.template cast<std::map<std::string, double>>()))
                     : py::reinterpret_borrow<py::object>(value);
    } else {
      schedule_keywords[key] = value;
    }
  }
  ApplyKeywords(table, where, own, options);
  if (const std::string problem = ValidateOptions(table, *options); !problem.empty())
    ThrowBadArgument(where, problem);
  SimulationOptions schedule;
  if (!noise_yaml.is_none()) ApplyNoiseYaml(PathString(noise_yaml), &schedule);
  ApplyKeywords(SimulationOptionTable(), where, schedule_keywords, &schedule);
  if (const std::string problem = schedule.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  if (!(schedule.gyro_noise_density > 0.0) || !(schedule.accel_noise_density > 0.0)) {
    ThrowBadArgument(
        where, "give the unit's white noise: noise_yaml, or gyro_noise_density and accel_noise_density");
  }
  return schedule;
}

Plan PlanArgument(const py::object& plan, const std::string& where) {
  if (!py::isinstance<py::dict>(plan)) return ReadPlan(PathString(plan));
  // JSON is YAML: the dict is read by the plan reader, with its checks and messages.
  return ReadPlanText(py::str(py::module_::import("json").attr("dumps")(plan)), where + " plan");
}

// The check as arrays: rows (one entry a coefficient term, limiting first), segments, the rest.
py::dict CheckDict(const PlanCheck& check) {
  py::dict out;
  out["undetermined"] = py::cast(check.undetermined);
  out["weak"] = py::cast(check.weak);
  std::vector<std::string> names, units;
  std::vector<double> sigma, sigma_range, sigma_spec, tolerance, ratio, white_share;
  for (const PlanRow& r : check.rows) {
    names.push_back(r.name);
    units.push_back(r.unit);
    sigma.push_back(r.sigma);
    sigma_range.push_back(r.sigma_range);
    sigma_spec.push_back(r.sigma_spec);
    tolerance.push_back(r.tolerance);
    ratio.push_back(r.ratio);
    white_share.push_back(r.white_share);
  }
  py::dict rows;
  rows["name"] = py::cast(names);
  rows["unit"] = py::cast(units);
  rows["sigma"] = ToArray(sigma);
  rows["sigma_range"] = ToArray(sigma_range);
  rows["sigma_spec"] = ToArray(sigma_spec);
  rows["tolerance"] = ToArray(tolerance);
  rows["ratio"] = ToArray(ratio);
  rows["white_share"] = ToArray(white_share);
  out["rows"] = rows;
  out["limiting"] = check.rows.empty() ? py::none() : py::cast(check.rows.front().name);
  std::vector<double> ids, limiting_loss, worst_loss;
  for (const PlanSegmentEffect& e : check.segments) {
    ids.push_back(e.segment);
    limiting_loss.push_back(e.limiting_loss);
    worst_loss.push_back(e.worst_loss);  // inf: the segment is essential
  }
  py::dict segments;
  segments["id"] = ToArray(ids);
  segments["limiting_loss"] = ToArray(limiting_loss);
  segments["worst_loss"] = ToArray(worst_loss);
  out["segments"] = segments;
  py::list correlated;
  for (const PlanCheck::Pair& p : check.correlated)
    correlated.append(py::make_tuple(p.a, p.b, p.correlation));
  out["correlated"] = correlated;
  out["carriers"] = py::cast(check.carriers);
  out["cuttable"] = py::cast(check.cuttable);
  out["plan_hours"] = check.plan_hours;
  out["needed_hours"] = check.needed_hours;
  out["plan_range_c"] = py::make_tuple(check.plan_range_c[0], check.plan_range_c[1]);
  out["best_soaks_c"] = ToArray({check.best_soaks_c.begin(), check.best_soaks_c.end()});
  out["temperature_efficiency"] = check.temperature_efficiency;
  out["extrapolation_factor"] = check.extrapolation_factor;
  out["tolerance_unmet"] = check.tolerance_unmet;
  out["warnings"] = py::cast(check.warnings);
  return out;
}

py::dict PlanCheckCall(const py::object& plan, const py::dict& kwargs) {
  const std::string where = "imufit.plan_check";
  PlanCheckOptions options;
  const SimulationOptions schedule = SplitKeywords(PlanCheckOptionTable(), where, kwargs, &options);
  const Plan read = PlanArgument(plan, where);
  PlanCheck check;
  {
    py::gil_scoped_release release;
    check = CheckPlan(read.segments, read.site, schedule, FitOptions(), options);
  }
  return CheckDict(check);
}

py::dict PlanDesignCall(const py::object& candidates, const py::dict& kwargs) {
  const std::string where = "imufit.plan_design";
  PlanDesignOptions options;
  const SimulationOptions schedule = SplitKeywords(PlanDesignOptionTable(), where, kwargs, &options);
  Plan plan;
  if (!candidates.is_none()) plan = PlanArgument(candidates, where);
  PlanDesign design;
  {
    py::gil_scoped_release release;
    try {
      design = DesignPlan(plan.segments, plan.site, schedule, options);
    } catch (const std::invalid_argument& e) {
      py::gil_scoped_acquire acquire;
      ThrowBadArgument(where, e.what());
    }
  }
  py::dict out;
  out["undetermined"] = py::cast(design.undetermined);
  out["met"] = design.met;
  out["soaks_c"] = ToArray(design.soaks_c);
  out["hours"] = design.hours;
  out["greedy_soaks_c"] = ToArray(design.greedy_soaks_c);
  out["greedy_hours"] = design.greedy_hours;
  if (options.check.latitude_deg) plan.site.latitude_rad = *options.check.latitude_deg * kDegToRad;
  plan.segments = design.segments;
  out["plan_yaml"] = PlanYaml(plan, "");
  out["segment_count"] = design.segments.size();
  out["check"] = CheckDict(design.check);
  out["greedy_check"] = CheckDict(design.greedy_check);
  return out;
}

}  // namespace

void BindPlan(py::module_& m) {
  m.def(
      "plan_check",
      [](const py::object& plan, const py::kwargs& kwargs) { return PlanCheckCall(plan, kwargs); },
      py::arg("plan"),
      "What `imufit plan check` prints, as arrays: the predicted 1-sigma of every coefficient a run of "
      "`plan` "
      "(a path or a dict) gives the fit. Keywords: the schedule and noise of simulate_options(), noise_yaml "
      "(a path: `imufit allan --noise-yaml`), and plan_check_options() (tolerance may be a dict {group: "
      "value}).");
  m.def(
      "plan_check_options", [] { return DescribeKeywords(PlanCheckOptionTable()); },
      "{name: (default, description)} of plan_check()'s own keywords (the schedule's: simulate_options()).");
  m.def(
      "plan_design",
      [](const py::object& candidates, const py::kwargs& kwargs) {
        return PlanDesignCall(candidates, kwargs);
      },
      py::arg("candidates") = py::none(),
      "What `imufit plan design` finds, as arrays: the plan (plan_yaml), its soaks and hours, and the "
      "predicted "
      "tables before (greedy_check) and after (check) the exchange. candidates: a plan (path or dict) whose "
      "segments are the candidates, or None for those the keywords name. Keywords: as plan_check(), and "
      "plan_design_options().");
  m.def(
      "plan_design_options", [] { return DescribeKeywords(PlanDesignOptionTable()); },
      "{name: (default, description)} of plan_design()'s own keywords (the schedule's: simulate_options()).");
}

}  // namespace imufit::python
