#include "imufit/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "imufit/model/constants.h"
#include "simulated_unit.h"

namespace imufit {
namespace {

using sim_internal::Link;
using sim_internal::SimulatedUnit;

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
