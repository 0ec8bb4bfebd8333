// imufit plan check — what a plan will determine before the chamber time is spent
// (pipeline/plan_check.h; docs/plan.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/pipeline/plan_check.h"

namespace imufit {
namespace {

struct PlanCheckArguments {
  std::string plan;
  std::string limits;
  std::string noise_yaml;
  std::string format = "text";
  CliOptions<PlanCheckOptions> check;     // PlanCheckOptionTable()
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

int RunPlanCheck(const PlanCheckArguments& args) {
  SimulationOptions schedule;
  if (!args.noise_yaml.empty()) ApplyNoiseYaml(args.noise_yaml, &schedule);
  args.options.Apply(&schedule);  // what the command line gives overrides the noise YAML
  if (const std::string problem = schedule.Validate(); !problem.empty()) {
    throw InputError("imufit plan check", problem);
  }
  if (!(schedule.gyro_noise_density > 0.0) || !(schedule.accel_noise_density > 0.0)) {
    throw InputError("imufit plan check",
                     "give the unit's white noise: --noise-yaml, or --gyro-noise-density and "
                     "--accel-noise-density (> 0)");
  }
  PlanCheckOptions check_options;
  args.check.Apply(&check_options);
  if (const std::string problem = ValidateOptions(PlanCheckOptionTable(), check_options); !problem.empty()) {
    throw InputError("imufit plan check", problem);
  }
  const Plan plan = ReadPlan(args.plan);
  if (!args.limits.empty()) TolerancesFromLimits(ReadLimits(args.limits), &check_options.tolerances);
  const PlanCheck check = CheckPlan(plan.segments, plan.site, schedule, FitOptions(), check_options);
  const std::string text = args.format == "yaml"   ? PlanCheckYaml(check)
                           : args.format == "json" ? PlanCheckJson(check)
                                                   : PlanCheckText(check, check_options);
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
  args->check.Add(command, PlanCheckOptionTable());
  command->add_option("--limits", args->limits,
                      "acceptance limits YAML: its coefficient limits as tolerances");
  command->add_option("--noise-yaml", args->noise_yaml,
                      "the unit's noise from `imufit allan --noise-yaml` (the worst axis of each sensor); "
                      "--*-noise-density and --*-bias-instability given as well override it");
  command->add_option("--format", args->format, "text (a table), yaml or json")
      ->check(CLI::IsMember({"text", "yaml", "json"}));
  return [args, command]() -> int {
    if (!command->parsed()) return 2;
    return RunPlanCheck(*args);
  };
}

}  // namespace imufit
