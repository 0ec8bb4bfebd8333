// imufit — the parts of a simulated run every simulator shares (the table run of simulator.h and
// the hand session of field_session.h): normal deviates that a seed fixes on every platform, the
// sensor's noise processes, the unit that turns truth into raw outputs through the shared model's
// forward form, and the serial link's time stamps and lost samples. Internal to imufit::sim.
#ifndef IMUFIT_SIM_SRC_SIMULATED_UNIT_H_
#define IMUFIT_SIM_SRC_SIMULATED_UNIT_H_

#include <cmath>
#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "imufit/model/constants.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"
#include "imufit/model/sensor_model.h"
#include "imufit/sim/simulator.h"

namespace imufit::sim_internal {

// Standard normal deviates from mt19937_64 (whose output the C++ standard fixes) by the
// Box-Muller transform, so a seed gives the same run with every standard library.
class NormalSource {
 public:
  explicit NormalSource(std::uint64_t seed) : engine_(seed) {}
  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = Uniform();
    const double u2 = Uniform();
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * kPi * u2);
  }
  Eigen::Vector3d Next3() {
    const double x = Next();
    const double y = Next();
    const double z = Next();
    return Eigen::Vector3d(x, y, z);
  }

 private:
  double Uniform() {  // in (0, 1]
    return (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
  }
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// A sensor's bias process: random walk plus first-order Gauss-Markov, and white noise.
struct NoiseProcess {
  double white_sigma = 0.0;   // per sample
  double walk_sigma = 0.0;    // per sample step
  double markov_decay = 0.0;  // exp(-dt / tau)
  double markov_sigma = 0.0;  // per sample drive
  Eigen::Vector3d walk = Eigen::Vector3d::Zero();
  Eigen::Vector3d markov = Eigen::Vector3d::Zero();

  NoiseProcess(double density, double random_walk, double instability, double tau_s, double dt) {
    white_sigma = density / std::sqrt(dt);
    walk_sigma = random_walk * std::sqrt(dt);
    markov_decay = std::exp(-dt / tau_s);
    markov_sigma = instability * std::sqrt(1.0 - markov_decay * markov_decay);
  }
  void Start(NormalSource* normal, double instability) {
    if (instability > 0.0) markov = instability * normal->Next3();
  }
  Eigen::Vector3d Step(NormalSource* normal) {
    Eigen::Vector3d error = Eigen::Vector3d::Zero();
    if (white_sigma > 0.0) error += white_sigma * normal->Next3();
    if (walk_sigma > 0.0) {
      walk += walk_sigma * normal->Next3();
      error += walk;
    }
    if (markov_sigma > 0.0) {
      markov = markov_decay * markov + markov_sigma * normal->Next3();
      error += markov;
    }
    return error;
  }
};

// The unit under test: its true calibration and noise, from the run's generator of normal deviates.
class SimulatedUnit {
 public:
  SimulatedUnit(const SimulationOptions& options, const SensorModel& truth_model)
      : options_(options),
        truth_model_(truth_model),
        normal_(options.seed),
        gyro_noise_(options.gyro_noise_density, options.gyro_random_walk, options.gyro_bias_instability,
                    options.bias_correlation_s, 1.0 / options.rate_hz),
        accel_noise_(options.accel_noise_density, options.accel_random_walk, options.accel_bias_instability,
                     options.bias_correlation_s, 1.0 / options.rate_hz) {
    gyro_noise_.Start(&normal_, options.gyro_bias_instability);
    accel_noise_.Start(&normal_, options.accel_bias_instability);
  }

  // The raw outputs and temperature reading of the unit at `true_temp_c` under `truth`: noise in SI
  // units at the body frame, the forward model at the true temperature, then rounding and clipping
  // as the converter does. The reading is noisy; the unit behaves according to the true temperature.
  void Sense(const SegmentTruth& truth, double true_temp_c, Sample* raw) {
    const Eigen::Vector3d omega_sensed = truth.omega_radps + gyro_noise_.Step(&normal_);
    const Eigen::Vector3d a_sensed = truth.a_mps2 + accel_noise_.Step(&normal_);
    raw->temp_c = true_temp_c;
    if (options_.temp_noise_c > 0.0) raw->temp_c += options_.temp_noise_c * normal_.Next();
    const double x = truth_model_.basis.Argument(true_temp_c);
    const SensorCoefficients<double> accel = CoefficientsAt(truth_model_.accel.data(), kAccelCoefficients, x);
    const SensorCoefficients<double> gyro = CoefficientsAt(truth_model_.gyro.data(), kGyroCoefficients, x);
    Eigen::Vector3d accel_m = ForwardSensor(accel, a_sensed, Eigen::Vector3d::Zero().eval());
    Eigen::Vector3d gyro_m = ForwardSensor(gyro, omega_sensed, truth.a_mps2);
    if (options_.quantize) {
      accel_m = accel_m.array().round();
      gyro_m = gyro_m.array().round();
    }
    if (options_.gyro_full_scale_raw > 0.0) {
      gyro_m = gyro_m.cwiseMax(-options_.gyro_full_scale_raw).cwiseMin(options_.gyro_full_scale_raw);
    }
    if (options_.accel_full_scale_raw > 0.0) {
      accel_m = accel_m.cwiseMax(-options_.accel_full_scale_raw).cwiseMin(options_.accel_full_scale_raw);
    }
    raw->gyro = gyro_m;
    raw->accel = accel_m;
  }

 private:
  const SimulationOptions& options_;
  const SensorModel& truth_model_;
  NormalSource normal_;
  NoiseProcess gyro_noise_;
  NoiseProcess accel_noise_;
};

// The serial link: time stamps with their jitter, and lost samples. Each from its own generator
// (seeded from the seed), so that neither changes the samples' values.
class Link {
 public:
  explicit Link(const SimulationOptions& options)
      : options_(options),
        jitter_engine_(options.seed ^ 0x6a09e667f3bcc909ULL),
        drop_engine_(options.seed ^ 0xbb67ae8584caa73bULL) {}

  // The time stamp of sample k.
  double TimeS(long long k) {
    double time_s = options_.start_time_s + static_cast<double>(k) * (1.0 / options_.rate_hz);
    if (options_.time_jitter_s > 0.0) {
      const double u = static_cast<double>(jitter_engine_() >> 11) * 0x1.0p-53;  // [0, 1)
      time_s += options_.time_jitter_s * (2.0 * u - 1.0);
    }
    return time_s;
  }

  // Whether the next sample is lost (a loss takes drop_burst samples in a row).
  bool Loses() {
    if (losing_ == 0 && options_.drop_probability > 0.0 &&
        static_cast<double>(drop_engine_() >> 11) * 0x1.0p-53 < options_.drop_probability) {
      losing_ = options_.drop_burst;
    }
    if (losing_ == 0) return false;
    --losing_;
    return true;
  }

 private:
  const SimulationOptions& options_;
  std::mt19937_64 jitter_engine_;
  std::mt19937_64 drop_engine_;
  int losing_ = 0;  // samples still to lose in the current loss
};

}  // namespace imufit::sim_internal

#endif  // IMUFIT_SIM_SRC_SIMULATED_UNIT_H_
