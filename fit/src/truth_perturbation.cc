#include "imufit/fit/truth_perturbation.h"

#include <Eigen/Geometry>

namespace imufit {
namespace {

Eigen::Matrix3d Rotation(const Eigen::Vector3d& angle_rad) {
  const double angle = angle_rad.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, angle_rad / angle).toRotationMatrix();
}

// The fixture's map of planned directions: its shear, then the unit's rotation in it.
Eigen::Matrix3d FixtureMap(const TruthPerturbation& p) {
  Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
  shear(0, 1) = shear(1, 0) = p.orthogonality_rad[0];
  shear(0, 2) = shear(2, 0) = p.orthogonality_rad[1];
  shear(1, 2) = shear(2, 1) = p.orthogonality_rad[2];
  return Rotation(p.alignment_rad) * shear;
}

Eigen::Vector3d Direction(const Eigen::Matrix3d& map, const Eigen::Vector3d& v) {
  return (map * v).normalized();
}

}  // namespace

Eigen::Vector3d LabNorth(const TableSegment& segment) {
  if (segment.north) return *segment.north;
  int nearest = 0;
  segment.up.cwiseAbs().maxCoeff(&nearest);
  const Eigen::Vector3d next = Eigen::Vector3d::Unit((nearest + 1) % 3);
  return (next - next.dot(segment.up) * segment.up).normalized();
}

void PerturbTruth(const TruthPerturbation& p, TableSite* site, std::vector<TableSegment>* segments,
                  std::vector<Window>* windows) {
  if (site != nullptr) site->gravity_mps2 *= 1.0 + p.gravity_scale;
  if (segments != nullptr) {
    const Eigen::Matrix3d fixture = FixtureMap(p);
    for (TableSegment& s : *segments) {
      // The lab's tilt in this position's body axes (before the fixture moves the directions).
      Eigen::Matrix3d map = fixture;
      if (s.IsStatic() && !p.tilt_rad.isZero()) {
        const Eigen::Vector3d north = LabNorth(s);
        const Eigen::Vector3d east = north.cross(s.up);
        map = Rotation(p.tilt_rad[0] * north + p.tilt_rad[1] * east) * fixture;
      }
      s.up = Direction(map, s.up);
      if (s.axis) s.axis = Direction(fixture, *s.axis);
      if (s.north) s.north = Direction(map, *s.north);
      if (!s.IsStatic() && !s.IsTurn()) s.rate_radps *= 1.0 + p.rate_scale;
    }
  }
  if (windows != nullptr) {
    for (Window& w : *windows) {
      w.temp_c += p.temp_offset_c;
      w.min_temp_c += p.temp_offset_c;
      w.max_temp_c += p.temp_offset_c;
    }
  }
}

}  // namespace imufit
