// imufit — the field fit's autodiff cost of a turn between two rests (field_cost.h), the rotation
// integrated over the turn's samples, in a translation unit of its own (see field_cost_rests.cc).
#include <ceres/autodiff_cost_function.h>

#include "field_cost.h"

namespace imufit {

ceres::CostFunction* FieldTurnCost::Create(const FieldLayout* layout, const PoseDirection* from,
                                           const PoseDirection* to, std::vector<TurnSample> samples, double x,
                                           double sigma_rad) {
  return new FieldTermsCost(
      layout,
      new ceres::AutoDiffCostFunction<FieldTurnCost, 2, kGyroCoefficients, FieldLayout::kAccelFree, 2, 2>(
          new FieldTurnCost(layout, from, to, std::move(samples), sigma_rad)),
      /*gyro=*/true, /*accel=*/true, x);
}

}  // namespace imufit
