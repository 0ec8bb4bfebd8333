// imufit — the plan's truth as the station got it wrong: a small perturbation of the table's rate,
// the local gravity, the directions of the fixture and the thermometer, applied to what the fit is
// given (the site, the segments and the windows' temperatures).
//
// The uncertainty budget (factory/uncertainty_budget.h) re-solves the fit with the truth perturbed
// by one standard uncertainty of each Type B source: the change of every coefficient is that
// source's contribution (a sensitivity coefficient times its u, GUM 5.1.3), without linearising
// anything by hand. Each perturbation keeps the structure of the problem: a rotation axis that is
// `up` stays `up`, so the same windows fit the same sensors.
//
//   rate_scale         the table turns at (1 + rate_scale) x the planned rate (rate segments;
//                      a turn's angle comes from the table's encoder and is kept)
//   gravity_scale      local gravity is (1 + gravity_scale) x the plan's
//   tilt_rad           the table's axis tilted from the vertical: at rest the specific force
//                      points along R(tilt) up (static segments; about a turning axis the tilt
//                      averages out of a window's mean to second order)
//   orthogonality_rad  the fixture's faces not square: every planned direction (up, axis, north)
//                      mapped by I + E, E symmetric with zero diagonal (xy, xz, yz), renormalised
//   alignment_rad      the unit seated rotated in its fixture: every planned direction rotated by
//                      R(alignment)
//   temp_offset_c      the thermometer reads low by this: the true temperature of every window is
//                      its reading + temp_offset_c
#ifndef IMUFIT_FIT_TRUTH_PERTURBATION_H_
#define IMUFIT_FIT_TRUTH_PERTURBATION_H_

#include <vector>

#include <Eigen/Core>

#include "imufit/model/rate_table.h"
#include "imufit/run/windows.h"

namespace imufit {

struct TruthPerturbation {
  double rate_scale = 0.0;
  double gravity_scale = 0.0;
  Eigen::Vector3d tilt_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d orthogonality_rad = Eigen::Vector3d::Zero();  // E's xy, xz, yz
  Eigen::Vector3d alignment_rad = Eigen::Vector3d::Zero();
  double temp_offset_c = 0.0;
};

// Applies `perturbation` to the site, the plan's segments and the windows (any may be null).
void PerturbTruth(const TruthPerturbation& perturbation, TableSite* site, std::vector<TableSegment>* segments,
                  std::vector<Window>* windows);

}  // namespace imufit

#endif  // IMUFIT_FIT_TRUTH_PERTURBATION_H_
