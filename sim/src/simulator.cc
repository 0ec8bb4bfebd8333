#include "imufit/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

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

// What the table does over one stretch of the run.
struct Phase {
  int from = 0;  // segment index (dwell: from == to)
  int to = 0;
  bool transition = false;
  long long samples = 0;
  double soak_temp_c = 0.0;
};

Eigen::Vector3d PerpendicularTo(const Eigen::Vector3d& v) {
  const Eigen::Vector3d trial = std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(trial).normalized();
}

// Truth while the table moves from segment `a` to segment `b`, at fraction u of the move.
SegmentTruth TransitionTruth(const TableSite& site, const TableSegment& a, const TableSegment& b, double u,
                             double duration_s) {
  const double cos_angle = std::clamp(a.up.dot(b.up), -1.0, 1.0);
  const double angle = std::acos(cos_angle);
  Eigen::Vector3d axis = a.up.cross(b.up);
  axis = axis.norm() > 1e-9 ? axis.normalized() : PerpendicularTo(a.up);
  const double s = u * u * (3.0 - 2.0 * u);
  const double s_dot = 6.0 * u * (1.0 - u) / duration_s;
  const Eigen::Vector3d up = Eigen::AngleAxisd(angle * s, axis) * a.up;
  const double rate = a.rate_radps + (b.rate_radps - a.rate_radps) * u;
  SegmentTruth truth;
  // A world-fixed direction seen from the body turns as d(up)/dt = -omega x up, so turning up
  // by +angle about `axis` needs omega = -angle' axis.
  truth.omega_radps = rate * up - angle * s_dot * axis;
  if (site.latitude_rad) truth.omega_radps += kEarthRateRadps * std::sin(*site.latitude_rad) * up;
  truth.a_mps2 = site.gravity_mps2 * up;
  return truth;
}

// A turn's motion occupies this middle fraction of its dwell; the table rests before and after,
// so the stretch labelled with the segment holds the whole motion.
constexpr double kTurnRestFraction = 0.2;

// Truth during a dwell, `t_s` seconds after it began, for the kinds whose truth changes with
// time: a turn through angle_rad with a smooth (raised-cosine) rate profile, as a hand or a
// position-mode table moves, and a constant rate about an axis that is not vertical. The body
// turns by angle(t) about the body axis n, so world-fixed directions seen from the body turn by
// -angle(t): up_b(t) = R(n, -angle(t)) up, exactly (no numerical integration). Earth's vertical
// rate turns with up_b; its horizontal part is left out as everywhere in a rate segment.
SegmentTruth MovingTruth(const TableSite& site, const TableSegment& segment, double t_s, double dwell_s) {
  const Eigen::Vector3d& n = segment.RotationAxis();
  double angle = 0.0;
  double rate = segment.rate_radps;
  if (segment.IsTurn()) {
    const double motion_s = (1.0 - 2.0 * kTurnRestFraction) * dwell_s;
    const double tau = std::clamp((t_s - kTurnRestFraction * dwell_s) / motion_s, 0.0, 1.0);
    // s(tau) = tau - sin(2 pi tau) / (2 pi): rate 1 - cos(2 pi tau), zero with zero slope at both ends.
    angle = *segment.angle_rad * (tau - std::sin(2.0 * kPi * tau) / (2.0 * kPi));
    rate = *segment.angle_rad * (1.0 - std::cos(2.0 * kPi * tau)) / motion_s;
  } else {
    angle = segment.rate_radps * t_s;
  }
  const Eigen::Vector3d up = Eigen::AngleAxisd(-angle, n) * segment.up;
  SegmentTruth truth;
  truth.omega_radps = rate * n;
  if (site.latitude_rad) truth.omega_radps += kEarthRateRadps * std::sin(*site.latitude_rad) * up;
  truth.a_mps2 = site.gravity_mps2 * up;
  if (!segment.IsTurn() && segment.lever_arm_m) {
    const Eigen::Vector3d& r = *segment.lever_arm_m;
    truth.a_mps2 -= rate * rate * (r - n * r.dot(n));
  }
  return truth;
}

// The stretches of the run in order: every pass through the plan, a move between two dwells.
std::vector<Phase> PhasesOf(const SimulationOptions& options, size_t segment_count) {
  const long long dwell_samples = std::llround(options.dwell_s * options.rate_hz);
  const long long move_samples = std::llround(options.transition_s * options.rate_hz);
  const int passes = options.ramp ? options.passes : static_cast<int>(options.soak_temps_c.size());
  std::vector<Phase> phases;
  for (int pass = 0; pass < passes; ++pass) {
    const double soak_c = options.ramp ? 0.0 : options.soak_temps_c[pass];
    for (int i = 0; i < static_cast<int>(segment_count); ++i) {
      if (!phases.empty() && move_samples > 0) {
        phases.push_back(Phase{phases.back().to, i, true, move_samples, soak_c});
      }
      phases.push_back(Phase{i, i, false, dwell_samples, soak_c});
    }
  }
  return phases;
}

// What the table does to the unit: the truth of sample j of a phase, and its segment label.
class TableMotion {
 public:
  TableMotion(const SimulationOptions& options, const TableSite& site,
              const std::vector<TableSegment>& segments)
      : options_(options), site_(site), segments_(segments) {
    for (const TableSegment& segment : segments) dwell_truth_.push_back(TruthOf(site, segment));
  }

  SegmentTruth TruthAt(const Phase& phase, long long j, int* segment_id) const {
    const double dt = 1.0 / options_.rate_hz;
    if (phase.transition) {
      *segment_id = kTransitionSegment;
      const double u = (static_cast<double>(j) + 0.5) / static_cast<double>(phase.samples);
      return TransitionTruth(site_, segments_[phase.from], segments_[phase.to], u, options_.transition_s);
    }
    const TableSegment& segment = segments_[phase.from];
    *segment_id = segment.id;
    return segment.SpecificForceIsKnown() && !segment.IsTurn()
               ? dwell_truth_[phase.from]
               : MovingTruth(site_, segment, static_cast<double>(j) * dt, options_.dwell_s);
  }

 private:
  const SimulationOptions& options_;
  const TableSite& site_;
  const std::vector<TableSegment>& segments_;
  std::vector<SegmentTruth> dwell_truth_;  // of the segments whose truth is constant
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

// The true temperature of sample k of `total`: the soak's, or along the ramp.
double TrueTempC(const SimulationOptions& options, const Phase& phase, long long k, long long total) {
  if (!options.ramp) return phase.soak_temp_c;
  const double progress = total > 1 ? static_cast<double>(k) / static_cast<double>(total - 1) : 0.0;
  return options.ramp_from_c + (options.ramp_to_c - options.ramp_from_c) * progress;
}

}  // namespace

long long SimulationOptions::SampleCount(size_t segment_count) const {
  const long long dwell = std::llround(dwell_s * rate_hz);
  const long long move = std::llround(transition_s * rate_hz);
  const long long passes_run = ramp ? passes : static_cast<long long>(soak_temps_c.size());
  const long long segments = passes_run * static_cast<long long>(segment_count);
  return segments * dwell + (segments - 1) * move;
}

void SimulateRun(const SimulationOptions& options, const TableSite& site,
                 const std::vector<TableSegment>& segments, const SensorModel& truth_model,
                 const SimulationSink& sink) {
  const long long total = options.SampleCount(segments.size());
  const TableMotion table(options, site, segments);
  SimulatedUnit unit(options, truth_model);
  Link link(options);
  long long k = 0;
  Sample raw;
  for (const Phase& phase : PhasesOf(options, segments.size())) {
    for (long long j = 0; j < phase.samples; ++j, ++k) {
      raw.time_s = link.TimeS(k);
      const SegmentTruth truth = table.TruthAt(phase, j, &raw.segment);
      unit.Sense(truth, TrueTempC(options, phase, k, total), &raw);
      if (!link.Loses()) sink(raw, truth);
    }
  }
}

}  // namespace imufit
