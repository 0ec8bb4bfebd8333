// Simulated runs shared by fit_test and run_test (header-only): the site, the MEMS noise and the
// windows of a simulated run, and the saturation of SixPositionPlan's fast rates.
#ifndef IMUFIT_TESTS_SIM_RUNS_H_
#define IMUFIT_TESTS_SIM_RUNS_H_

#include <cmath>
#include <cstdint>
#include <vector>

#include "imufit/model/constants.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sensor_model.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"

namespace imufit::testing {

inline TableSite Site() {
  TableSite site;
  site.gravity_mps2 = 9.79285;
  site.latitude_rad = 30.27 * kDegToRad;
  return site;
}

inline SimulationOptions MemsNoise(std::uint64_t seed) {
  SimulationOptions o;
  o.soak_temps_c = {-40.0, -10.0, 25.0, 55.0, 85.0};
  o.dwell_s = 6.0;
  o.transition_s = 1.0;
  o.rate_hz = 100.0;
  o.gyro_noise_density = 1e-4;   // rad/s/sqrt(Hz), about 0.35 deg/sqrt(h)
  o.accel_noise_density = 5e-4;  // m/s^2/sqrt(Hz), about 50 micro-g/sqrt(Hz)
  o.quantize = true;
  o.seed = seed;
  return o;
}

inline std::vector<Window> Simulate(const SimulationOptions& options,
                                    const std::vector<TableSegment>& segments, const SensorModel& truth,
                                    const WindowOptions& window_options = WindowOptions(),
                                    const TableSite& site = Site()) {
  WindowBuilder builder(window_options, segments);
  SimulateRun(options, site, segments, truth,
              [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
  return builder.Finish();
}

// The 300 deg/s rates of SixPositionPlan reach about 5000 counts on a RandomMemsModel unit (16.5
// counts per deg/s), the 100 deg/s ones about 1700: a full scale of 3000 pins the first.
inline constexpr double kGyroFullScaleCounts = 3000.0;
inline int FastRateWindows(const std::vector<Window>& windows, const std::vector<TableSegment>& plan) {
  int fast = 0;
  for (const Window& w : windows) fast += std::abs(plan[w.segment].rate_radps) > 200.0 * kDegToRad;
  return fast;
}

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_SIM_RUNS_H_
