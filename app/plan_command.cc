// imufit plan check — what a plan will determine before the chamber time is spent
// (pipeline/plan_check.h; docs/plan.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/model/constants.h"
#include "imufit/pipeline/plan_check.h"

namespace imufit {
namespace {

struct PlanCheckArguments {
  std::string plan;
  std::string limits;
  std::vector<std::string> tolerances;  // GROUP=VALUE, display units
  std::vector<double> spec_range_c;
  double latitude_deg = 1000.0;  // not given
  std::string format = "text";
  PlanCheckOptions check;
  CliOptions<SimulationOptions> options;  // SimulationOptionTable(): the schedule and the noise
};

// The limits file's coefficient criteria as tolerances of their groups (a limit on the value or
// on its sigma: z sigma must fit inside it), in the groups' display units.
void TolerancesFromLimits(const Limits& limits, std::map<std::string, double>* tolerances) {
  struct Map {
    const char* quantity;
    const char* group;
    double factor;
  };
  static const Map kMaps[] = {{"gyro_bias_dps", "gyro.bias", 1.0},
                              {"accel_bias_mg", "accel.bias", 1.0},
                              {"gyro_scale_error_ppm", "gyro.scale", 1.0},
                              {"gyro_scale_error_pct", "gyro.scale", 1e4},
                              {"accel_scale_error_ppm", "accel.scale", 1.0},
                              {"accel_scale_error_pct", "accel.scale", 1e4},
                              {"gyro_misalignment_mrad", "gyro.misalignment", 1.0},
                              {"accel_misalignment_mrad", "accel.misalignment", 1.0},
                              {"gyro_g_sensitivity_dpsg", "gyro.g_sensitivity", 1.0}};
  for (const LimitCriterion& criterion : limits.criteria) {
    for (const Map& m : kMaps) {
      if (criterion.quantity != m.quantity) continue;
      const double tolerance = criterion.max_abs * m.factor;
      auto [it, inserted] = tolerances->emplace(m.group, tolerance);
      if (!inserted) it->second = std::min(it->second, tolerance);
    }
  }
}

std::map<std::string, double> ParseTolerances(const std::vector<std::string>& texts) {
  static const std::vector<std::string> kGroups = {"gyro.bias",          "gyro.scale", "gyro.misalignment",
                                                   "gyro.g_sensitivity", "accel.bias", "accel.scale",
                                                   "accel.misalignment"};
  std::map<std::string, double> tolerances;
  for (const std::string& text : texts) {
    const size_t equals = text.find('=');
    const std::string group = text.substr(0, equals);
    std::string allowed;
    for (const std::string& g : kGroups) allowed += (allowed.empty() ? "" : ", ") + g;
    if (equals == std::string::npos || std::find(kGroups.begin(), kGroups.end(), group) == kGroups.end()) {
      throw InputError("--tolerance", "\"" + text + "\": give GROUP=VALUE with GROUP one of " + allowed);
    }
    char* end = nullptr;
    const std::string number = text.substr(equals + 1);
    const double value = std::strtod(number.c_str(), &end);
    if (number.empty() || *end != '\0' || !(value > 0.0) || !std::isfinite(value)) {
      throw InputError("--tolerance", "\"" + text + "\": the tolerance must be a positive number in " +
                                          PlanGroupUnit(group));
    }
    tolerances[group] = value;
  }
  return tolerances;
}

int RunPlanCheck(PlanCheckArguments args) {
  SimulationOptions schedule;
  args.options.Apply(&schedule);
  if (const std::string problem = schedule.Validate(); !problem.empty()) {
    throw InputError("imufit plan check", problem);
  }
  if (!(schedule.gyro_noise_density > 0.0) || !(schedule.accel_noise_density > 0.0)) {
    throw InputError("imufit plan check",
                     "give the unit's white noise: --gyro-noise-density and --accel-noise-density (> 0)");
  }
  Plan plan = ReadPlan(args.plan);
  if (args.latitude_deg != 1000.0) plan.site.latitude_rad = args.latitude_deg * kDegToRad;
  args.check.tolerances = ParseTolerances(args.tolerances);
  if (!args.limits.empty()) TolerancesFromLimits(ReadLimits(args.limits), &args.check.tolerances);
  if (args.spec_range_c.size() == 2) args.check.spec_range_c = {{args.spec_range_c[0], args.spec_range_c[1]}};
  const PlanCheck check = CheckPlan(plan.segments, plan.site, schedule, FitOptions(), args.check);
  const std::string text = args.format == "yaml" ? PlanCheckYaml(check) : PlanCheckText(check, args.check);
  std::fputs(text.c_str(), stdout);
  if (!check.undetermined.empty()) {
    std::fprintf(stderr, "imufit: the plan does not determine the model (%zu finding%s)\n",
                 check.undetermined.size(), check.undetermined.size() == 1 ? "" : "s");
    return 1;
  }
  return check.tolerance_unmet ? 3 : 0;
}

}  // namespace

CommandRunner AddPlanCommand(CLI::App* root) {
  auto args = std::make_shared<PlanCheckArguments>();
  CLI::App* plan = root->add_subcommand("plan", "Judge a calibration plan before the run (docs/plan.md).");
  plan->require_subcommand(1);
  CLI::App* command = plan->add_subcommand(
      "check",
      "Predict the 1-sigma of every coefficient a run of PLAN will give the fit (its own Jacobians and "
      "weights, no noise simulated), against tolerances; name what limits the plan. Exit 3 when a "
      "tolerance cannot be met.");
  command->add_option("plan", args->plan, "plan YAML")->required();
  args->options.Add(
      command, SimulationOptionTable(),
      {"start_time_s", "temp_noise_c", "quantize", "time_jitter_s", "drop_probability", "drop_burst",
       "gyro_full_scale_raw", "accel_full_scale_raw", "seed", "gyro_random_walk", "accel_random_walk"});
  args->options.Find("ramp_c")->excludes(args->options.Find("soak_temps_c"));
  command->add_option(
      "--tolerance", args->tolerances,
      "GROUP=VALUE: tolerance of a coefficient group (gyro.bias deg/s, accel.bias mg, *.scale "
      "ppm, *.misalignment mrad, gyro.g_sensitivity deg/s/g); repeatable");
  command->add_option("--limits", args->limits,
                      "acceptance limits YAML: its coefficient limits as tolerances");
  command->add_option("--spec-range", args->spec_range_c, "the range the unit is specified over, degC: LO HI")
      ->expected(2);
  command->add_option("--latitude", args->latitude_deg, "the table's latitude, deg (default: the plan's)");
  command->add_option("--z", args->check.z, "coverage factor: a tolerance is met when z sigma <= it")
      ->check(CLI::PositiveNumber);
  command->add_option("--format", args->format, "text (a table) or yaml")
      ->check(CLI::IsMember({"text", "yaml"}));
  return [args, command]() -> int {
    if (!command->parsed()) return 2;
    return RunPlanCheck(*args);
  };
}

}  // namespace imufit
