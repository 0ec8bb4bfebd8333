// imufit — the truth of a rate-table segment (docs/spec.md section 2, docs/conventions.md), in
// the body frame, SI units. With n the rotation axis (`axis`, else `up`):
//
//   static: omega_true = Omega_E sin(phi) up (+ Omega_E cos(phi) north)
//           a_true     = g up
//   rate:   omega_true = rate n + Omega_E sin(phi) (up . n) n
//           a_true     = g up - rate^2 (r - n (r . n))
//   turn:   mean(omega_true) = angle n / duration + Omega_E sin(phi) (up . n) n
//           a_true     = g up
//
// up: unit vector opposite to gravity, body axes (for a turn: at its start). north: unit
// horizontal vector to true north (static segments only: in a rate segment the horizontal Earth
// rate turns with the table and averages out, so it is left out of the truth; only the Earth rate
// along the axis is constant). r: the sensor's position relative to the table axis, metres, body
// axes. The Earth-rate terms are present only when the latitude is known.
//
// The specific force is constant only when the axis is vertical (n parallel to up). About any
// other axis gravity turns in the body frame: a_true above is then its value at the start of the
// segment, and `SpecificForceIsKnown()` is false: the fit does not use the accelerometer there.
// A turn's rate profile is unknown; only its mean over the whole turn is (TurnTruth()).
#ifndef IMUFIT_MODEL_RATE_TABLE_H_
#define IMUFIT_MODEL_RATE_TABLE_H_

#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace imufit {

// Earth's rotation rate (WGS-84), rad/s.
inline constexpr double kEarthRateRadps = 7.292115e-5;

// One segment of a rate-table plan, in SI units (io/ converts the plan file's deg/s).
//
// Three kinds of segment: static (rate 0, no angle); a constant rate about the rotation axis
// (rate_radps != 0); a turn through a known angle about the rotation axis (angle_rad set: hand
// rotations, position-mode tables, indexing heads; the rate during the turn is not known, only
// its integral). The rotation axis is `axis` when given (two- and three-axis tables, turns about
// a horizontal axis), else `up` (a single-axis table turns about the vertical).
struct TableSegment {
  int id = 0;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit vector, body axes (at the start of a turn)
  double rate_radps = 0.0;                        // rate about RotationAxis(), right-hand rule
  std::optional<double> angle_rad;                // turn through this angle about RotationAxis()
  std::optional<Eigen::Vector3d> axis;            // unit, body axes; absent: the axis is `up`
  std::optional<Eigen::Vector3d> north;           // unit, horizontal, body axes; static only
  std::optional<Eigen::Vector3d> lever_arm_m;     // sensor position from the table axis
  bool IsStatic() const { return rate_radps == 0.0 && !angle_rad; }
  bool IsTurn() const { return angle_rad.has_value(); }
  const Eigen::Vector3d& RotationAxis() const { return axis ? *axis : up; }
  // The rotation axis is vertical (parallel or antiparallel to up, to 1e-6 rad).
  bool AxisIsVertical() const { return std::abs(RotationAxis().dot(up)) >= kVerticalAxisCosine; }
  // The specific force is constant and known from the plan (static, or about a vertical axis).
  bool SpecificForceIsKnown() const { return IsStatic() || AxisIsVertical(); }

  static constexpr double kVerticalAxisCosine = 1.0 - 5e-13;  // cos(1e-6 rad)
};

// The site of the run: local gravity and, optionally, latitude.
struct TableSite {
  double gravity_mps2 = 9.80665;
  std::optional<double> latitude_rad;  // when present, Earth rotation is part of the truth
};

// The true angular rate (rad/s) and specific force (m/s^2) of a segment, body frame.
struct SegmentTruth {
  Eigen::Vector3d omega_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_mps2 = Eigen::Vector3d::Zero();
};

// The truth of a static or rate segment (for a rate about a non-vertical axis, a_true at the
// segment's starting orientation); for a turn, omega_true is its Earth rate only (see TurnTruth).
inline SegmentTruth TruthOf(const TableSite& site, const TableSegment& segment) {
  SegmentTruth truth;
  const Eigen::Vector3d& n = segment.RotationAxis();
  truth.omega_radps = segment.rate_radps * n;
  if (site.latitude_rad) {
    const double vertical_earth_rate = kEarthRateRadps * std::sin(*site.latitude_rad);
    if (segment.IsStatic()) {
      truth.omega_radps += vertical_earth_rate * segment.up;
      if (segment.north) truth.omega_radps += kEarthRateRadps * std::cos(*site.latitude_rad) * *segment.north;
    } else {
      // Only the part along the axis is constant in the body frame (with no `axis`, n is up).
      truth.omega_radps += segment.axis ? Eigen::Vector3d(vertical_earth_rate * segment.up.dot(n) * n)
                                        : Eigen::Vector3d(vertical_earth_rate * segment.up);
    }
  }
  truth.a_mps2 = site.gravity_mps2 * segment.up;
  if (!segment.IsStatic() && !segment.IsTurn() && segment.lever_arm_m) {
    const Eigen::Vector3d& r = *segment.lever_arm_m;
    const Eigen::Vector3d radial = r - n * r.dot(n);
    truth.a_mps2 -= segment.rate_radps * segment.rate_radps * radial;
  }
  return truth;
}

// The truth of a window covering one whole occurrence of a turn of `duration_s` (its samples
// times their mean interval): the mean rate angle n / duration plus the Earth rate along n, and
// g up (meaningful when the axis is vertical).
inline SegmentTruth TurnTruth(const TableSite& site, const TableSegment& segment, double duration_s) {
  SegmentTruth truth = TruthOf(site, segment);
  truth.omega_radps += segment.angle_rad.value_or(0.0) / duration_s * segment.RotationAxis();
  return truth;
}

// What to check when a fitted or read scale factor is negative or changes sign: the unit's axis
// or rotation sign convention against the body frame's and the plan's (right-handed rates and
// turns, specific force along up at rest). For the messages of `imufit fit` and of the readers.
inline std::string ScaleSignAdvice(bool gyro, int axis) {
  const std::string name = std::string(gyro ? "gyro " : "accel ") + "xyz"[axis];
  if (gyro) {
    return "a scale factor is positive by convention: check the sign of the unit's " + name +
           " axis against the body frame, and that the plan's rate_dps and angle_deg follow the right-hand "
           "rule "
           "about their axis (positive = counter-clockwise seen from the axis tip)";
  }
  return "a scale factor is positive by convention: check the sign of the unit's " + name +
         " axis against the body frame: at rest an accelerometer reads +g along up (specific force, not "
         "gravity)";
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_RATE_TABLE_H_
