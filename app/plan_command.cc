// imufit plan check — what a plan will determine before the chamber time is spent
// (pipeline/plan_check.h; docs/plan.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "imufit/base/text.h"
#include "imufit/io/error.h"
#include "imufit/io/hand_procedure.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"
#include "imufit/model/constants.h"
#include "imufit/model/local_gravity.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/plan/hand_check.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"
#include "imufit/plan/plan_prediction.h"

namespace imufit {
namespace {

// What `plan check` and `plan design` share: the schedule and the unit's noise, the limits.
struct ScheduleArguments {
  std::string limits;
  std::string noise_yaml;
  CliOptions<SimulationOptions> options;  // SimulationOptionTable(): the schedule and the noise
  CliOptions<FitRunOptions> fit;          // FitRunOptionTable(): the model the fit will estimate
};

// The options of `imufit fit` that shape the model a plan must determine (what the fit's findings
// advise: --gyro-temp-order, --fit accel, ...); the solver's own are not a plan's. plan check also
// takes the fit's --prior (the values a subset holds), so that the fit's command line checks as it
// is; held values carry no uncertainty, so the prediction does not depend on them.
const char* const kPlanFitOptions[] = {"fit",
                                       "gyro_temp_order",
                                       "accel_temp_order",
                                       "fit_g_sensitivity",
                                       "distinct_temp_c",
                                       "min_excitation_rate_radps",
                                       "rank_tolerance"};

// Window options plan check takes from `imufit fit` but the full scales (a nominal unit never clips).
const std::set<std::string> kPlanWindowExceptions = {"gyro_full_scale_raw", "accel_full_scale_raw"};

struct PlanCheckArguments {
  std::string plan;
  std::string format = "text";
  CliOptions<PlanCheckOptions> check;  // PlanCheckOptionTable()
  ScheduleArguments schedule;
  // A hand procedure's (io/hand_procedure.h): its poses overridden, and the sessions simulated.
  int poses = 0;
  int sessions = kHandCheckSessions;
  CliOption poses_option;
  CliOption sessions_option;
};

struct PlanDesignArguments {
  std::string candidates;  // a plan whose segments are the candidates ("": DesignCandidates())
  std::string output;
  CliOptions<PlanDesignOptions> design;  // PlanDesignOptionTable()
  ScheduleArguments schedule;
};

SimulationOptions ScheduleOf(const ScheduleArguments& args, const char* command) {
  SimulationOptions schedule;
  if (!args.noise_yaml.empty()) ApplyNoiseYaml(args.noise_yaml, &schedule);
  args.options.Apply(&schedule);  // what the command line gives overrides the noise YAML
  if (const std::string problem = schedule.Validate(); !problem.empty()) throw InputError(command, problem);
  if (!(schedule.gyro_noise_density > 0.0) || !(schedule.accel_noise_density > 0.0)) {
    throw InputError(command,
                     "give the unit's white noise: --noise-yaml, or --gyro-noise-density and "
                     "--accel-noise-density (> 0)");
  }
  return schedule;
}

// The options of `table` given on the command line, validated.
template <typename Options>
Options OptionsOf(const CliOptions<Options>& given, const OptionTable<Options>& table, const char* command) {
  Options options;
  given.Apply(&options);
  if (const std::string problem = ValidateOptions(table, options); !problem.empty()) {
    throw InputError(command, problem);
  }
  return options;
}

// The limits file's coefficient criteria as tolerances that a plan meets at `min_ratio`:1.
std::optional<Limits> AddLimitTolerances(const ScheduleArguments& args, PlanCheckOptions* check) {
  if (args.limits.empty()) return std::nullopt;
  Limits limits = ReadLimits(args.limits);
  TolerancesFromLimits(limits, &check->tolerances, check->min_ratio);
  return limits;
}

// The options of a table plan's check that a hand procedure's does not take (its file says them, or
// they are a table's): refused by name, so that nothing given is silently ignored.
template <typename Options>
void RefuseTableOptions(const CliOptions<Options>& given, const OptionTable<Options>& table,
                        const std::set<std::string>& allowed, const std::string& path) {
  for (const auto& entry : table.entries()) {
    if (allowed.count(entry.key) == 0 && given.Given(entry.key)) {
      throw InputError("imufit plan check",
                       entry.flag + " is an option of a table plan's check; " + path +
                           " is a hand procedure (its file describes the session: docs/plan.md)");
    }
  }
}

// `plan check HAND.yaml`: the hand procedure's predicted sigmas (plan/hand_check.h).
int RunHandCheck(const PlanCheckArguments& args) {
  RefuseTableOptions(args.schedule.options, SimulationOptionTable(),
                     {"dwell_s", "rate_hz", "gyro_noise_density", "accel_noise_density",
                      "gyro_bias_instability", "accel_bias_instability", "bias_correlation_s"},
                     args.plan);
  RefuseTableOptions(args.check, PlanCheckOptionTable(), {"tolerance", "z", "min_ratio"}, args.plan);
  RefuseTableOptions(args.schedule.fit, FitRunOptionTable(), {}, args.plan);
  HandProcedure hand = ReadHandProcedure(args.plan);
  const SimulationOptions schedule = ScheduleOf(args.schedule, "imufit plan check");
  if (args.schedule.options.Given("dwell_s")) hand.dwell_s = schedule.dwell_s;
  if (args.schedule.options.Given("rate_hz")) hand.rate_hz = schedule.rate_hz;
  if (args.poses_option.Given()) {
    if (args.poses < 9)
      throw InputError("imufit plan check", "--poses " + std::to_string(args.poses) + ": at least 9");
    hand.poses = args.poses;
  }
  if (args.sessions < 1 || args.sessions > 100) {
    throw InputError("imufit plan check", "--sessions " + std::to_string(args.sessions) + ": give 1..100");
  }
  PlanCheckOptions check_options = OptionsOf(args.check, PlanCheckOptionTable(), "imufit plan check");
  const std::optional<Limits> limits = AddLimitTolerances(args.schedule, &check_options);
  const HandSetup setup = HandSetupOf(hand, schedule);
  if (const std::string problem = setup.session.Validate(); !problem.empty()) {
    throw InputError(args.plan, problem);
  }
  const HandCheck check = CheckHandProcedure(setup, check_options, args.sessions);
  std::vector<PlanCriterion> criteria;
  if (limits && check.fitted > 0) criteria = JudgeLimits(*limits, HandPlanCheck(check, setup), check_options);
  const std::string text = args.format == "text" ? HandCheckText(check, setup, check_options) +
                                                       PlanCriteriaText(criteria, check_options)
                                                 : HandCheckYaml(check, criteria, args.format == "json");
  std::fputs(text.c_str(), stdout);
  if (!check.undetermined.empty()) {
    std::fprintf(stderr, "imufit: the hand procedure does not reliably determine the model (%zu finding%s)\n",
                 check.undetermined.size(), check.undetermined.size() == 1 ? "" : "s");
    return kExitNotDone;
  }
  const bool unmet =
      std::any_of(criteria.begin(), criteria.end(), [](const PlanCriterion& c) { return !c.met; });
  return check.tolerance_unmet || unmet ? kExitFailedLimits : kExitDone;
}

int RunPlanCheck(const PlanCheckArguments& args) {
  if (IsHandProcedureFile(args.plan)) return RunHandCheck(args);
  if (args.poses_option.Given() || args.sessions_option.Given()) {
    throw InputError("imufit plan check", std::string(args.poses_option.Given() ? "--poses" : "--sessions") +
                                              " is an option of a hand procedure's check; " + args.plan +
                                              " is a table plan");
  }
  const SimulationOptions schedule = ScheduleOf(args.schedule, "imufit plan check");
  PlanCheckOptions check_options = OptionsOf(args.check, PlanCheckOptionTable(), "imufit plan check");
  FitOptions fit = OptionsOf(args.schedule.fit, FitRunOptionTable(), "imufit plan check").fit;
  fit.held.reset();  // read (a bad file is refused), not used: held values carry no uncertainty
  const std::optional<Limits> limits = AddLimitTolerances(args.schedule, &check_options);
  const Plan plan = ReadPlan(args.plan);
  const PlanCheck check = CheckPlan(plan.segments, plan.site, schedule, fit, check_options);
  std::vector<PlanCriterion> criteria;
  if (limits && check.undetermined.empty()) criteria = JudgeLimits(*limits, check, check_options);
  const std::string text = args.format == "yaml"   ? PlanCheckYaml(check, criteria)
                           : args.format == "json" ? PlanCheckJson(check, criteria)
                                                   : PlanCheckText(check, check_options) +
                                                         PlanCriteriaText(criteria, check_options);
  std::fputs(text.c_str(), stdout);
  if (!check.undetermined.empty()) {
    std::fprintf(stderr, "imufit: the plan does not determine the model (%zu finding%s)\n",
                 check.undetermined.size(), check.undetermined.size() == 1 ? "" : "s");
    return kExitNotDone;
  }
  const bool unmet =
      std::any_of(criteria.begin(), criteria.end(), [](const PlanCriterion& c) { return !c.met; });
  return check.tolerance_unmet || unmet ? kExitFailedLimits : kExitDone;
}

// The site a designed plan is written for: the candidates' plan's, with the station's gravity
// (given; else WGS84 normal gravity at the latitude given) and latitude.
TableSite DesignSite(const Plan& candidates, bool candidates_given, const PlanDesignOptions& options,
                     std::string* gravity_note) {
  TableSite site = candidates.site;
  if (options.check.latitude_deg) site.latitude_rad = *options.check.latitude_deg * kDegToRad;
  if (options.gravity_mps2) {
    site.gravity_mps2 = *options.gravity_mps2;
    *gravity_note = "gravity_mps2: the station's, as given (--gravity-mps2).";
  } else if (candidates_given) {
    *gravity_note = "gravity_mps2: the candidates' plan's.";
  } else if (options.check.latitude_deg) {
    site.gravity_mps2 = NormalGravityMps2(*options.check.latitude_deg * kDegToRad, 0.0);  // sea level
    *gravity_note = "gravity_mps2: WGS84 normal gravity at " + FormatDouble(*options.check.latitude_deg) +
                    " deg, sea level; replace it by the station's measured gravity (--gravity-mps2).";
  } else {
    *gravity_note =
        "gravity_mps2: standard gravity, no station given: replace it by the station's (--gravity-mps2, "
        "or --latitude for WGS84 normal gravity), or the fit reads the accelerometer's scale off by their "
        "ratio.";
  }
  return site;
}

int RunPlanDesign(const PlanDesignArguments& args) {
  const SimulationOptions schedule = ScheduleOf(args.schedule, "imufit plan design");
  PlanDesignOptions options = OptionsOf(args.design, PlanDesignOptionTable(), "imufit plan design");
  options.fit = OptionsOf(args.schedule.fit, FitRunOptionTable(), "imufit plan design").fit;
  AddLimitTolerances(args.schedule, &options.check);
  Plan candidates;
  if (!args.candidates.empty()) {
    RefuseToOverwriteInputs(args.output, {args.candidates});
    candidates = ReadPlan(args.candidates);
  }
  std::string gravity_note;
  const TableSite site = DesignSite(candidates, !args.candidates.empty(), options, &gravity_note);
  PlanDesign design;
  try {
    design = DesignPlan(candidates.segments, site, schedule, options);
  } catch (const std::invalid_argument& e) {
    throw InputError("imufit plan design", e.what());
  }
  std::fputs(PlanDesignText(design, options).c_str(), stdout);
  if (!design.undetermined.empty()) {
    std::fprintf(stderr, "imufit: even every candidate cannot determine the model\n");
    return kExitNotDone;
  }
  if (!design.met) return kExitFailedLimits;
  Plan plan;
  plan.site = site;
  plan.segments = design.segments;
  std::string temps;
  for (double t : design.soaks_c) temps += (temps.empty() ? "" : ",") + FormatDouble(t);
  const std::string comment =
      "Designed by imufit plan design (docs/plan.md): " + std::to_string(design.segments.size()) +
      " segments at " + std::to_string(design.soaks_c.size()) + " soaks, " +
      NumberText("%.2f", design.hours) + " h.\nRun it with --temps=" + temps + " --dwell " +
      FormatDouble(schedule.dwell_s) + " --transition " + FormatDouble(schedule.transition_s) + ".\n" +
      gravity_note;
  WriteFileAtomically(args.output, PlanYaml(plan, comment));
  return 0;
}

}  // namespace

// The schedule's options, the noise YAML and the limits, on `command`.
void AddScheduleOptions(CliCommand command, ScheduleArguments* args) {
  args->options.Add(
      command, SimulationOptionTable(),
      {"start_time_s", "temp_noise_c", "quantize", "time_jitter_s", "drop_probability", "drop_burst",
       "gyro_full_scale_raw", "accel_full_scale_raw", "seed", "gyro_random_walk", "accel_random_walk"});
  for (const char* key : kPlanFitOptions) args->fit.AddOne(command, FitRunOptionTable(), key);
  command.Option(
      "--limits", &args->limits,
      "acceptance limits YAML: each coefficient criterion met at --min-ratio:1 (tolerance / U), each "
      "noise criterion resolved by a static dwell");
  command.Option("--noise-yaml", &args->noise_yaml,
                 "the unit's noise from `imufit allan --noise-yaml` (the worst axis of each sensor); "
                 "--*-noise-density and --*-bias-instability given as well override it");
}

CommandRunner AddPlanCommand(CliCommand command) {
  auto check_args = std::make_shared<PlanCheckArguments>();
  auto design_args = std::make_shared<PlanDesignArguments>();
  command.RequireSubcommand();
  CliCommand check = command.Subcommand(
      "check",
      "Predict the 1-sigma of every coefficient a run of PLAN will give the fit (its own Jacobians and "
      "weights, no noise simulated), against tolerances; name what limits the plan. For a hand procedure, "
      "the field fit's sigmas over simulated sessions of it, and what it cannot determine. Exit 3 when a "
      "tolerance cannot be met.");
  check
      .Option("plan", &check_args->plan,
              "plan YAML, or a hand procedure YAML (format: imufit-hand-procedure, docs/plan.md)")
      .Required();
  AddScheduleOptions(check, &check_args->schedule);
  check_args->schedule.options.Find("ramp_c").Excludes(check_args->schedule.options.Find("soak_temps_c"));
  check_args->check.Add(check, PlanCheckOptionTable(), kPlanWindowExceptions);
  check_args->schedule.fit.AddOne(check, FitRunOptionTable(),
                                  "prior");  // design's --prior is the data sheet's
  check.Option("--format", &check_args->format, "text (a table), yaml or json")
      .OneOf({"text", "yaml", "json"});
  check_args->poses_option = check.Option(
      "--poses", &check_args->poses, "a hand procedure: the number of poses (overrides its file's poses)");
  check_args->sessions_option =
      check.Option("--sessions", &check_args->sessions,
                   "a hand procedure: the simulated sessions whose field fits the prediction averages");

  CliCommand design = command.Subcommand(
      "design",
      "Choose, from candidate positions, rates and temperature set-points, the plan that meets the "
      "tolerances in the fewest hours (greedy by information per second, then exchange); write it to -o "
      "and print the predicted table before and after the exchange. Exit 3 when no plan of the "
      "candidates meets them.");
  design.Option("-o,--output", &design_args->output, "the plan YAML to write").Required();
  design.Option("--candidates", &design_args->candidates,
                "a plan whose segments are the candidates (and whose site is the run's)");
  AddScheduleOptions(design, &design_args->schedule);
  design_args->design.Add(design, PlanDesignOptionTable(), kPlanWindowExceptions);
  return [check_args, design_args, check, design]() -> int {
    if (check.Parsed()) return RunPlanCheck(*check_args);
    if (design.Parsed()) return RunPlanDesign(*design_args);
    return kExitBadInput;
  };
}

}  // namespace imufit
