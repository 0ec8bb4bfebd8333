// The hand session of field_session.h: poses, turns in closed form, and the unit and link of
// simulated_unit.h.
#include "imufit/sim/field_session.h"

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

// The session's own choices (poses, durations, axes) come from a generator apart from the noise's,
// so that a seed gives the same session with and without noise.
class SessionRandom {
 public:
  explicit SessionRandom(std::uint64_t seed) : engine_(seed ^ 0x3c6ef372fe94f82bULL) {}
  double Uniform(double low, double high) {  // in [low, high)
    return low + (high - low) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  Eigen::Vector3d UnitVector() {  // uniform on the sphere
    const double z = Uniform(-1.0, 1.0);
    const double phi = Uniform(0.0, 2.0 * kPi);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  }
  int Index(int count) { return std::min(count - 1, static_cast<int>(Uniform(0.0, count))); }

 private:
  std::mt19937_64 engine_;
};

Eigen::Vector3d PerpendicularTo(const Eigen::Vector3d& v) {
  const Eigen::Vector3d trial = std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(trial).normalized();
}

// The nominal directions: the 6 faces, then the 8 corners of a cube.
std::vector<Eigen::Vector3d> NominalDirections() {
  std::vector<Eigen::Vector3d> directions;
  for (int axis = 0; axis < 3; ++axis) {
    directions.push_back(Eigen::Vector3d::Unit(axis));
    directions.push_back(-Eigen::Vector3d::Unit(axis));
  }
  for (int corner = 0; corner < 8; ++corner) {
    directions.push_back(
        Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1).normalized());
  }
  return directions;
}

// Gravity's direction (up, body frame) at every pose: the nominal directions in turn (faces first),
// each tilted, then shuffled (Fisher-Yates with the session's generator).
std::vector<Eigen::Vector3d> PoseDirections(const FieldSessionOptions& session, SessionRandom* random) {
  std::vector<Eigen::Vector3d> nominal = NominalDirections();
  if (!session.directions.empty()) {
    nominal.clear();
    for (const Eigen::Vector3d& d : session.directions) nominal.push_back(d.normalized());
  }
  std::vector<Eigen::Vector3d> ups;
  for (int p = 0; p < session.poses; ++p) {
    const Eigen::Vector3d& d = nominal[static_cast<size_t>(p) % nominal.size()];
    const Eigen::Vector3d tilt_axis =
        Eigen::AngleAxisd(random->Uniform(0.0, 2.0 * kPi), d) * PerpendicularTo(d);
    const double tilt_rad = kDegToRad * random->Uniform(session.min_tilt_deg, session.max_tilt_deg);
    ups.push_back(Eigen::AngleAxisd(tilt_rad, tilt_axis) * d);
  }
  for (int i = session.poses - 1; i > 0; --i) std::swap(ups[i], ups[random->Index(i + 1)]);
  return ups;
}

// theta(tau) / Theta and its derivative d/dtau: tau - sin(2 pi tau) / (2 pi), zero rate and zero
// acceleration at both ends.
double Profile(double tau) { return tau - std::sin(2.0 * kPi * tau) / (2.0 * kPi); }
double ProfileRate(double tau) { return 1.0 - std::cos(2.0 * kPi * tau); }

// One turn, R(t) = R1(t) R2(t) (field_session.h).
struct Turn {
  Eigen::Vector3d n1 = Eigen::Vector3d::UnitX();
  double theta1 = 0.0;
  Eigen::Vector3d n2 = Eigen::Vector3d::UnitZ();
  double theta2 = 0.0;
  double duration_s = 1.0;

  static constexpr double kSpan = 0.75;  // each rotation's share of the turn
  static constexpr double kR2Start = 1.0 - kSpan;

  // The truth `t_s` seconds into the turn, from gravity's direction `up_start` at its start.
  SegmentTruth TruthAt(double t_s, const Eigen::Vector3d& up_start, double g_mps2) const {
    const double u = std::clamp(t_s / duration_s, 0.0, 1.0);
    const double tau1 = std::clamp(u / kSpan, 0.0, 1.0);
    const double tau2 = std::clamp((u - kR2Start) / kSpan, 0.0, 1.0);
    const double span_s = kSpan * duration_s;
    const Eigen::Matrix3d r1 = Eigen::AngleAxisd(theta1 * Profile(tau1), n1).toRotationMatrix();
    const Eigen::Matrix3d r2 = Eigen::AngleAxisd(theta2 * Profile(tau2), n2).toRotationMatrix();
    SegmentTruth truth;
    truth.omega_radps = theta1 * ProfileRate(tau1) / span_s * (r2.transpose() * n1) +
                        theta2 * ProfileRate(tau2) / span_s * n2;
    truth.a_mps2 = g_mps2 * ((r1 * r2).transpose() * up_start);
    return truth;
  }
  // Gravity's direction at the end of the turn.
  Eigen::Vector3d UpAtEnd(const Eigen::Vector3d& up_start) const {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(theta1, n1) * Eigen::AngleAxisd(theta2, n2).toRotationMatrix();
    return r.transpose() * up_start;
  }
};

// The turn from gravity along `up` to gravity along `up_next`: a random twist R2 first chosen, then
// R1 so that R2^T R1^T up = up_next, i.e. R1^T takes up to v = R2 up_next (about up x v).
Turn TurnBetween(const Eigen::Vector3d& up, const Eigen::Vector3d& up_next,
                 const FieldSessionOptions& session, SessionRandom* random) {
  Turn turn;
  turn.n2 = session.twist_axes.empty()
                ? random->UnitVector()
                : Eigen::Vector3d::Unit(
                      session.twist_axes[random->Index(static_cast<int>(session.twist_axes.size()))]);
  turn.theta2 = kDegToRad * random->Uniform(session.min_twist_deg, session.max_twist_deg) *
                (random->Uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0);
  const Eigen::Vector3d v = Eigen::AngleAxisd(turn.theta2, turn.n2) * up_next;
  const Eigen::Vector3d axis = up.cross(v);
  const double angle = std::atan2(axis.norm(), up.dot(v));
  // R1^T = exp(angle [m]x), m = axis / |axis|; so R1 = exp(angle [-m]x).
  turn.n1 = axis.norm() > 1e-9 ? Eigen::Vector3d(-axis.normalized()) : PerpendicularTo(up);
  turn.theta1 = angle;
  turn.duration_s = session.turn_s * random->Uniform(0.75, 1.25);
  return turn;
}

// What the unit does from one moment to the next: rest at a pose, or turn to the next.
struct Stretch {
  int pose = 0;  // the pose at rest, or the pose the turn starts from
  bool turn = false;
  double start_s = 0.0;  // relative to the session's start
  double end_s = 0.0;
  Turn motion;
};

}  // namespace

std::vector<FieldPoseTruth> SimulateFieldSession(const SimulationOptions& options,
                                                 const FieldSessionOptions& session,
                                                 const SensorModel& truth_model, const SimulationSink& sink) {
  SessionRandom random(options.seed);
  const std::vector<Eigen::Vector3d> ups = PoseDirections(session, &random);
  std::vector<Stretch> stretches;
  std::vector<FieldPoseTruth> poses;
  double t_s = 0.0;
  for (int p = 0; p < session.poses; ++p) {
    if (p > 0) {
      Stretch turn{p - 1, true, t_s, 0.0, TurnBetween(ups[p - 1], ups[p], session, &random)};
      turn.end_s = t_s + turn.motion.duration_s;
      t_s = turn.end_s;
      stretches.push_back(turn);
    }
    Stretch rest{p, false, t_s, t_s + options.dwell_s * random.Uniform(0.8, 1.2), {}};
    t_s = rest.end_s;
    stretches.push_back(rest);
  }
  // Gravity at each pose after the turns, exactly (equal to `ups` up to rounding).
  std::vector<Eigen::Vector3d> pose_up = {ups[0]};
  for (const Stretch& s : stretches) {
    if (s.turn) pose_up.push_back(s.motion.UpAtEnd(pose_up[s.pose]));
  }
  for (const Stretch& s : stretches) {
    if (!s.turn)
      poses.push_back({options.start_time_s + s.start_s, options.start_time_s + s.end_s, pose_up[s.pose]});
  }

  SimulatedUnit unit(options, truth_model);
  Link link(options);
  const double session_s = t_s;
  size_t current = 0;
  Sample raw;
  for (long long k = 0;; ++k) {
    raw.time_s = link.TimeS(k);
    const double elapsed_s = raw.time_s - options.start_time_s;
    if (elapsed_s > session_s) break;
    while (current + 1 < stretches.size() && elapsed_s >= stretches[current].end_s) ++current;
    const Stretch& s = stretches[current];
    SegmentTruth truth;
    if (s.turn) {
      truth = s.motion.TruthAt(elapsed_s - s.start_s, pose_up[s.pose], session.gravity_mps2);
      raw.segment = kTransitionSegment;
    } else {
      truth.a_mps2 = session.gravity_mps2 * pose_up[s.pose];
      raw.segment = s.pose;
    }
    const double temp_c =
        options.soak_temps_c.front() - session.warmup_c * std::exp(-elapsed_s / session.warmup_tau_s);
    unit.Sense(truth, temp_c, &raw);
    if (!link.Loses()) sink(raw, truth);
  }
  return poses;
}

}  // namespace imufit
