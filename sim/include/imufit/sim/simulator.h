// imufit — a rate-table run simulated from a known calibration (`imufit simulate`).
//
// For each sample the simulator knows the truth (omega_true in rad/s, a_true in m/s^2, body
// frame, docs/spec.md section 2), adds the sensor's noise in SI units at the body frame, and turns
// the result into raw outputs with the forward form of the shared model:
//
//   B = diag(S_g) inv(M_g) (omega_true + n_g + b_g) + V_g + H a_true
//   A = diag(S_a) inv(M_a) (a_true + n_a + b_a) + V_a
//
// n is white noise of the given density (sigma = density * sqrt(rate)), b a bias that follows
// a random walk and a first-order Gauss-Markov process (bias instability). Raw outputs may be
// rounded to integer counts. The temperature follows a soak schedule (every pass through the
// plan at one temperature) or a linear ramp across several passes.
//
// Between two segments the table moves for `transition_s` (segment -1): `up` turns from the old
// to the new direction with a smooth (cubic) profile about the axis old x new, while the table
// rate changes linearly; omega_true = rate(t) up(t) + angle'(t) axis (+ Earth rate along up),
// a_true = g up(t). The same seed gives the same samples, bit for bit, on every platform.
//
// A turn through a known angle (angle_deg) rests for the first and last 20 % of its dwell and
// turns in between with a raised-cosine rate profile (zero rate and zero angular acceleration at
// both ends, as a hand or a position-mode table moves); a rate segment about an axis that is not
// vertical spins at its rate from the start of the dwell. In both, world-fixed directions turn in
// the body frame exactly (up_b(t) = R(n, -angle(t)) up): gravity, the vertical Earth rate and
// the g-sensitivity term follow the orientation sample by sample.
#ifndef IMUFIT_SIM_SIMULATOR_H_
#define IMUFIT_SIM_SIMULATOR_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

struct SimulationOptions {
  // Soak temperatures, degC: one pass through the plan at each (used when ramp is off).
  std::vector<double> soak_temps_c = {25.0};
  // A linear temperature ramp from ramp_from_c to ramp_to_c across `passes` passes.
  bool ramp = false;
  double ramp_from_c = -40.0;
  double ramp_to_c = 85.0;
  int passes = 4;
  double dwell_s = 10.0;      // time in each segment
  double transition_s = 2.0;  // time the table moves between segments (segment -1)
  double rate_hz = 100.0;     // sample rate
  double start_time_s = 0.0;  // time_s of the first sample
  // White noise densities (Kalibr's units): rad/s/sqrt(Hz) and m/s^2/sqrt(Hz).
  double gyro_noise_density = 0.0;
  double accel_noise_density = 0.0;
  // Bias random walk: rad/s^2/sqrt(Hz) and m/s^3/sqrt(Hz).
  double gyro_random_walk = 0.0;
  double accel_random_walk = 0.0;
  // Bias instability as a Gauss-Markov process: steady-state sigma (rad/s, m/s^2) and
  // correlation time.
  double gyro_bias_instability = 0.0;
  double accel_bias_instability = 0.0;
  double bias_correlation_s = 100.0;
  double temp_noise_c = 0.0;  // white noise of the temperature reading, degC
  bool quantize = false;      // round raw outputs to integer counts
  // Time stamps jitter: each time_s is off its nominal k / rate_hz by a uniform deviate in
  // [-time_jitter_s, +time_jitter_s] (less than half the sample interval, so times still increase).
  // The deviates come from their own generator: the samples' values are those of the run without jitter.
  double time_jitter_s = 0.0;
  // Lost samples, as a serial link loses frames: each sample starts a loss of `drop_burst` samples
  // in a row with probability drop_probability. Lost samples are not written (neither the raw
  // sample nor its truth); the others keep their values and time stamps, from their own generator.
  double drop_probability = 0.0;
  int drop_burst = 1;
  // The raw outputs' full scale, raw units (0: none): outputs are clipped to +-full scale, as a
  // converter saturates.
  double gyro_full_scale_raw = 0.0;
  double accel_full_scale_raw = 0.0;
  std::uint64_t seed = 1;

  // An empty string when the options are usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
  // Number of samples the run will have (without losses; with drop_probability, at most this many).
  long long SampleCount(size_t segment_count) const;
};

// Every option of SimulationOptions, described once (model/option_table.h; simulation_options.cc).
const OptionTable<SimulationOptions>& SimulationOptionTable();

// Called for every sample, in time order: the raw sample and its truth.
using SimulationSink = std::function<void(const Sample& raw, const SegmentTruth& truth)>;

// Simulates the run of `segments` (in plan order) on `site` for a unit calibrated as `truth`.
void SimulateRun(const SimulationOptions& options, const TableSite& site,
                 const std::vector<TableSegment>& segments, const SensorModel& truth,
                 const SimulationSink& sink);

}  // namespace imufit

#endif  // IMUFIT_SIM_SIMULATOR_H_
