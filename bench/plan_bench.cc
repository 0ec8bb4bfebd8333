// imufit — benchmark of `plan check` and `plan design` (pipeline/plan_check.h, plan_design.h):
//
//   plan check:  the 24-position plan (fixtures/plan_24pos.yaml) at 7 soak temperatures;
//                target < 1 s.
//   hand check:  the hand procedure fixtures/hand_12poses.yaml (12 rests of 10 s, 100 Hz), its
//                default 3 simulated sessions fitted; target < 1 s.
//   plan design: the 26 candidate positions (faces, edges, corners) with +-100 and +-300 deg/s
//                about each face's axis, at 6 temperature set-points; target < 10 s.
//
// Beside each, the yardstick of the same run: a fit of the 24-position plan simulated at the same
// 7 soaks (what the check saves: it predicts that fit's sigmas without one). Best of 3; measured and
// printed, never asserted (this is not a test).
//
// Usage: plan_bench
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "imufit/fit/thermal_fit.h"
#include "imufit/io/hand_procedure.h"
#include "imufit/io/plan.h"
#include "imufit/plan/hand_check.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"

namespace imufit {
namespace {

double BestOf3(const std::function<void()>& run) {
  double best = 1e300;
  for (int i = 0; i < 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    run();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

SimulationOptions Schedule() {
  SimulationOptions schedule;
  schedule.soak_temps_c = {-40.0, -20.0, 0.0, 25.0, 45.0, 65.0, 85.0};
  schedule.dwell_s = 20.0;
  schedule.transition_s = 10.0;
  schedule.rate_hz = 100.0;
  schedule.gyro_noise_density = 1e-4;
  schedule.accel_noise_density = 1e-3;
  schedule.gyro_bias_instability = 2e-5;
  schedule.accel_bias_instability = 1e-4;
  return schedule;
}

int Main() {
  const Plan plan = ReadPlan(IMUFIT_FIXTURES_DIR "/plan_24pos.yaml");
  const SimulationOptions schedule = Schedule();
  PlanCheckOptions check_options;
  check_options.tolerances = {{"gyro.bias", 0.005}, {"accel.bias", 0.5}, {"gyro.scale", 300.0}};
  PlanCheck check;
  const double check_s =
      BestOf3([&] { check = CheckPlan(plan.segments, plan.site, schedule, FitOptions(), check_options); });

  const HandSetup hand = HandSetupOf(ReadHandProcedure(IMUFIT_FIXTURES_DIR "/hand_12poses.yaml"), schedule);
  HandCheck hand_check;
  const std::clock_t hand_cpu_start = std::clock();
  const double hand_s =
      BestOf3([&] { hand_check = CheckHandProcedure(hand, check_options, kHandCheckSessions); });
  // Processor time per check (the mean of the three): a shared machine stretches the wall clock.
  const double hand_cpu_s = static_cast<double>(std::clock() - hand_cpu_start) / CLOCKS_PER_SEC / 3.0;

  std::vector<Window> windows;
  {
    SimulationOptions run = schedule;
    run.rate_hz = 20.0;  // the fit sees window means: the yardstick is the solve, not the simulation
    WindowBuilder builder(WindowOptions(), plan.segments);
    SimulateRun(run, plan.site, plan.segments, SensorModel::Identity(),
                [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
    windows = builder.Finish();
  }
  const double fit_s = BestOf3([&] { FitThermalModel(windows, plan.site, plan.segments, FitOptions()); });

  PlanDesignOptions design_options;
  design_options.check = check_options;
  design_options.check.latitude_deg = 52.27;
  design_options.positions = "faces,edges,corners";
  design_options.set_points_c = {-40.0, -15.0, 10.0, 35.0, 60.0, 85.0};
  PlanDesign design;
  const double design_s = BestOf3([&] { design = DesignPlan({}, TableSite(), schedule, design_options); });

  std::printf(
      "plan check, 24 positions x 7 soaks:   %7.3f s (target < 1 s)   %.2f x one fit of the run (%.3f s)\n",
      check_s, check_s / fit_s, fit_s);
  std::printf(
      "hand check, 12 poses x %d sessions:  %7.3f s (target < 1 s; processor %.3f s)   %.3f s a session "
      "(simulated, fitted)%s\n",
      kHandCheckSessions, hand_s, hand_cpu_s, hand_s / kHandCheckSessions,
      hand_check.tolerance_unmet ? "; advice computed too" : "");
  std::printf(
      "plan design, %d candidates x %d set-points: %7.3f s (target < 10 s): %zu segments x %zu soaks, "
      "%.2f h (greedy %.2f h), %s\n",
      design.candidate_segments, design.candidate_set_points, design_s, design.segments.size(),
      design.soaks_c.size(), design.hours, design.greedy_hours, design.met ? "meets" : "does not meet");
  std::printf("limiting coefficient of the check: %s\n",
              check.rows.empty() ? "-" : check.rows.front().name.c_str());
  return 0;
}

}  // namespace
}  // namespace imufit

int main() { return imufit::Main(); }
