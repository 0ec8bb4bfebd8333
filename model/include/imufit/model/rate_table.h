// imufit — the truth of a rate-table segment (docs/spec.md section 2), in the body frame, SI units.
//
//   omega_true = rate * up + Omega_E sin(phi) up            (+ Omega_E cos(phi) north, static)
//   a_true     = g up - rate^2 (r - up (r . up))            (centripetal, rate segments with r)
//
// up: unit vector opposite to gravity, body axes. north: unit horizontal vector to true north
// (static segments only: in a rate segment the horizontal Earth rate turns with the table and
// averages out, so it is left out of the truth). r: the sensor's position relative to the table
// axis, metres, body axes. The Earth-rate terms are present only when the latitude is known.
#ifndef IMUFIT_MODEL_RATE_TABLE_H_
#define IMUFIT_MODEL_RATE_TABLE_H_

#include <cmath>
#include <optional>

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

inline SegmentTruth TruthOf(const TableSite& site, const TableSegment& segment) {
  SegmentTruth truth;
  truth.omega_radps = segment.rate_radps * segment.up;
  if (site.latitude_rad) {
    truth.omega_radps += kEarthRateRadps * std::sin(*site.latitude_rad) * segment.up;
    if (segment.IsStatic() && segment.north) {
      truth.omega_radps += kEarthRateRadps * std::cos(*site.latitude_rad) * *segment.north;
    }
  }
  truth.a_mps2 = site.gravity_mps2 * segment.up;
  if (!segment.IsStatic() && segment.lever_arm_m) {
    const Eigen::Vector3d& r = *segment.lever_arm_m;
    const Eigen::Vector3d radial = r - segment.up * r.dot(segment.up);
    truth.a_mps2 -= segment.rate_radps * segment.rate_radps * radial;
  }
  return truth;
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_RATE_TABLE_H_
