// SimulationOptions: its option table (model/option_table.h) and its checks.
#include "imufit/sim/simulator.h"

namespace imufit {
namespace {

OptionTable<SimulationOptions> MakeSimulationOptionTable() {
  using O = SimulationOptions;
  OptionTable<O> t;
  t.Numbers(
      "soak_temps_c", "--temps",
      "soak temperatures, comma-separated on the command line: one pass through the plan at each", "degC",
      [](const O& o) { return o.soak_temps_c; },
      [](const std::vector<double>& temps, O* o) { o->soak_temps_c = temps; });
  t.Numbers(
      "ramp_c", "--ramp", "a linear temperature ramp FROM,TO across `passes` passes (none: soaks)", "degC",
      [](const O& o) {
        return o.ramp ? std::vector<double>{o.ramp_from_c, o.ramp_to_c} : std::vector<double>{};
      },
      [](const std::vector<double>& range, O* o) {
        o->ramp = !range.empty();
        if (!o->ramp) return;
        o->ramp_from_c = range[0];
        o->ramp_to_c = range[1];
      },
      /*count=*/2);
  t.Number("passes", "--passes", "passes through the plan during a ramp", "", &O::passes);
  t.Number("dwell_s", "--dwell", "time in each segment", "s", &O::dwell_s, PositiveFinite());
  t.Number("transition_s", "--transition", "time the table moves between segments (segment -1)", "s",
           &O::transition_s, NonNegativeFinite());
  t.Number("rate_hz", "--rate", "sample rate", "Hz", &O::rate_hz, PositiveFinite());
  t.Number("start_time_s", "--start-time", "time_s of the first sample", "s", &O::start_time_s);
  t.Number("gyro_noise_density", "--gyro-noise-density", "gyro white noise", "rad/s/sqrt(Hz)",
           &O::gyro_noise_density, NonNegative());
  t.Number("accel_noise_density", "--accel-noise-density", "accel white noise", "m/s^2/sqrt(Hz)",
           &O::accel_noise_density, NonNegative());
  t.Number("gyro_random_walk", "--gyro-random-walk", "gyro bias random walk", "rad/s^2/sqrt(Hz)",
           &O::gyro_random_walk, NonNegative());
  t.Number("accel_random_walk", "--accel-random-walk", "accel bias random walk", "m/s^3/sqrt(Hz)",
           &O::accel_random_walk, NonNegative());
  t.Number("gyro_bias_instability", "--gyro-bias-instability", "gyro Gauss-Markov bias, steady-state sigma",
           "rad/s", &O::gyro_bias_instability, NonNegative());
  t.Number("accel_bias_instability", "--accel-bias-instability",
           "accel Gauss-Markov bias, steady-state sigma", "m/s^2", &O::accel_bias_instability, NonNegative());
  t.Number("bias_correlation_s", "--bias-correlation", "correlation time of the Gauss-Markov bias", "s",
           &O::bias_correlation_s, Positive());
  t.Number("temp_noise_c", "--temp-noise", "white noise of the temperature reading", "degC", &O::temp_noise_c,
           NonNegative());
  t.Flag("quantize", "--quantize", "round raw outputs to integer counts", &O::quantize);
  t.Number("time_jitter_s", "--time-jitter-s",
           "time stamps off their nominal times by up to this much (uniform); below half the sample interval",
           "s", &O::time_jitter_s, NonNegative());
  t.Number(
      "drop_probability", "--drop-probability",
      "probability that a sample starts a loss of drop_burst samples (as a serial link loses frames): the "
      "lost samples are not written",
      "", &O::drop_probability, Between(0.0, 1.0, false, true));
  t.Number("drop_burst", "--drop-burst", "samples lost in a row at each loss", "", &O::drop_burst,
           AtLeast(1));
  t.Number("gyro_full_scale_raw", "--gyro-full-scale",
           "clip the raw gyro outputs to +- this, raw units, as a saturated converter does (0: no clip)", "",
           &O::gyro_full_scale_raw, NonNegative());
  t.Number("accel_full_scale_raw", "--accel-full-scale",
           "clip the raw accelerometer outputs to +- this, raw units (0: no clip)", "",
           &O::accel_full_scale_raw, NonNegative());
  t.Number("seed", "--seed", "random seed: the same seed gives the same samples", "", &O::seed);
  return t;
}

}  // namespace

const OptionTable<SimulationOptions>& SimulationOptionTable() {
  static const OptionTable<SimulationOptions> table = MakeSimulationOptionTable();
  return table;
}

std::string SimulationOptions::Validate() const {
  if (std::string problem = ValidateOptions(SimulationOptionTable(), *this); !problem.empty()) return problem;
  if (ramp && passes < 1) return "passes = " + std::to_string(passes) + ": a ramp needs at least one pass";
  if (!ramp && soak_temps_c.empty()) return "give at least one soak temperature";
  // A temperature that is not a number would make every sample NaN.
  const std::vector<double> temps = ramp ? std::vector<double>{ramp_from_c, ramp_to_c} : soak_temps_c;
  for (const double t : temps) {
    if (!(t >= -273.15 && t <= 1000.0)) {
      return std::string(ramp ? "ramp_c" : "soak_temps_c") + " = " + OptionNumberText(t) +
             ": temperatures must be numbers between -273.15 and 1000 degC";
    }
  }
  if (!(time_jitter_s < 0.5 / rate_hz)) {
    return "time_jitter_s = " + OptionNumberText(time_jitter_s) +
           ": the time jitter must lie in [0, half the sample interval)";
  }
  return "";
}

}  // namespace imufit
