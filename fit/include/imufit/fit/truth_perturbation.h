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
//   tilt_rad           the table's axis tilted from the vertical in the laboratory: a rotation
//                      about true north by tilt_rad[0] and about east by tilt_rad[1], the same in
//                      the lab for every position. At rest the specific force points along
//                      R(tilt_rad[0] n + tilt_rad[1] e) up, n and e the position's north and east
//                      in body axes (e = n x up): turned over, the unit sees the same lab tilt from
//                      the other side, so part of it reads as an accelerometer bias, not only as
//                      a misalignment. A static segment without `north` is taken at the heading
//                      LabNorth() gives. About a turning axis the tilt averages out of a
//                      window's mean to second order: rate segments and turns are not moved.
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
  Eigen::Vector2d tilt_rad = Eigen::Vector2d::Zero();           // about north, about east (lab frame)
  Eigen::Vector3d orthogonality_rad = Eigen::Vector3d::Zero();  // E's xy, xz, yz
  Eigen::Vector3d alignment_rad = Eigen::Vector3d::Zero();
  double temp_offset_c = 0.0;
};

// The horizontal direction a static segment's lab tilt is taken against: its `north` when the plan
// gives one, else the body axis after the one nearest `up` (x, y, z, x: up +-z -> x, +-x -> y, +-y -> z),
// made horizontal (the heading the plan's own static positions take by convention).
Eigen::Vector3d LabNorth(const TableSegment& segment);

// Applies `perturbation` to the site, the plan's segments and the windows (any may be null).
void PerturbTruth(const TruthPerturbation& perturbation, TableSite* site, std::vector<TableSegment>* segments,
                  std::vector<Window>* windows);

}  // namespace imufit

#endif  // IMUFIT_FIT_TRUTH_PERTURBATION_H_
