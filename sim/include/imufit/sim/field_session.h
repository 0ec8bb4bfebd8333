// imufit — a calibration session by hand simulated from a known calibration (`imufit simulate
// --field`): no table, no plan. The unit rests in `poses` arbitrary poses and is turned by hand
// between them; the field fit (fit/field_fit.h) is tested against its exact truth.
//
// Poses. Gravity's direction in the body frame at each pose is one of the 6 faces or 8 corners of
// a cube (the faces first, so that nine poses hold each face once; or the `directions` given, in turn),
// tilted off it by a random angle in [min_tilt_deg, max_tilt_deg] about a random horizontal axis: never a
// clean face. Their order is shuffled. Each rest lasts dwell_s times a random factor in [0.8, 1.2].
//
// Turns. Between two poses the body turns as R(t) = R1(t) R2(t) (R maps the body frame at time t
// into the body frame at the start of the turn): R1 = exp(theta1(t) [n1]x) brings gravity to the
// next pose's direction, R2 = exp(theta2(t) [n2]x) twists about a random axis (or one of
// twist_axes) by a random angle (min_twist_deg to max_twist_deg, 20 to 90 degrees, either sign), so that
// every turn rotates about a changing axis (the two rotations overlap in time and do not commute: the
// integrator's coning is exercised). Each angle follows theta(tau) = Theta (tau - sin(2 pi tau) / (2 pi))
// over 75 % of the turn (R1 the first, R2 the last 75 %): zero rate and zero angular acceleration at both
// ends, as a hand moves. The turn lasts turn_s times a random factor in [0.75, 1.25]; peaks are a few rad/s.
// The truth is exact, in closed form at each sample's own time stamp:
//
//   omega_true = theta1' R2^T n1 + theta2' n2          [rad/s, body frame]
//   up(t)      = R(t)^T up(start),  a_true = g up(t)   [m/s^2]
//
// Time. Sample k is stamped start_time_s + k / rate_hz + jitter (SimulationOptions::time_jitter_s)
// and its truth is evaluated at that stamp, so irregular steps are real ones, not mislabelled
// samples; lost samples (drop_probability, drop_burst) are not written.
//
// The unit. Noise, quantisation, clipping and the temperature reading are the table simulator's
// (simulated_unit.h: the same noise processes, the same forward form of the shared model). The
// true temperature is temp_c, the first of SimulationOptions::soak_temps_c (`--temps`), or with
// warmup_c > 0 a warm-up from temp_c - warmup_c: T(t) = temp_c - warmup_c exp(-(t - t0) / warmup_tau_s).
//
// Labels. The sink gets segment = the pose index (0-based) at rest and -1 while turning: the
// truth file keeps them, the samples file is written without a segment column.
#ifndef IMUFIT_SIM_FIELD_SESSION_H_
#define IMUFIT_SIM_FIELD_SESSION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/base/option_table.h"
#include "imufit/model/constants.h"
#include "imufit/model/sensor_model.h"
#include "imufit/sim/simulator.h"

namespace imufit {

struct FieldSessionOptions {
  int poses = 12;              // static poses (at least 9: what a field fit needs)
  double turn_s = 2.0;         // mean duration of a turn between two poses, s
  double min_tilt_deg = 10.0;  // gravity's tilt off the nominal face or corner, degrees
  double max_tilt_deg = 30.0;
  double gravity_mps2 = kStandardGravityMps2;  // local gravity, m/s^2
  double warmup_c = 0.0;                       // the unit starts this much colder, degC (0: no warm-up)
  double warmup_tau_s = 300.0;                 // time constant of the warm-up, s
  // A described procedure (`imufit plan check` of a hand procedure, plan/hand_check.h); not options of
  // `imufit simulate`. The nominal directions the poses take in turn (up, body frame; each tilted):
  // empty for the 6 faces, then the 8 corners of a cube.
  std::vector<Eigen::Vector3d> directions;
  // The body axes (0 x, 1 y, 2 z) a turn's twist R2 is about, one drawn at random per turn; empty:
  // a random direction. The twist's angle is drawn from [min_twist_deg, max_twist_deg], either sign
  // (both 0: no twist, only the rotation that brings gravity to the next pose).
  std::vector<int> twist_axes;
  double min_twist_deg = 20.0;
  double max_twist_deg = 90.0;

  // An empty string when usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
};

// Every option of FieldSessionOptions, described once (base/option_table.h; field_session.cc).
const OptionTable<FieldSessionOptions>& FieldSessionOptionTable();

// The truth of one pose: when the unit rested there and gravity's direction in the body frame.
struct FieldPoseTruth {
  double start_s = 0.0;  // first and last sample time of the rest (before losses)
  double end_s = 0.0;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit vector opposite to gravity, body frame
};

// Simulates a hand session for a unit calibrated as `truth`. From `options` it takes the sample
// rate, dwell_s (a pose's rest), the first soak temperature, start time, noise, quantisation,
// clipping, time jitter, losses and the seed (the other soak temperatures, the ramp, passes and
// transition_s are not used). Calls
// `sink` for every sample kept, in time order; returns the poses' truth.
std::vector<FieldPoseTruth> SimulateFieldSession(const SimulationOptions& options,
                                                 const FieldSessionOptions& session, const SensorModel& truth,
                                                 const SimulationSink& sink);

}  // namespace imufit

#endif  // IMUFIT_SIM_FIELD_SESSION_H_
