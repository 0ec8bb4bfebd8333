// imufit — the field fit's autodiff costs of a rest (field_cost.h), the accelerometer's and the
// gyro's, in a translation unit of their own: their Jet instantiations compile apart from the
// fit's stages (field_fit.cc) and from the turns' (field_cost_turns.cc), in parallel, so that no
// object of the build takes long to compile.
#include <ceres/autodiff_cost_function.h>

#include "field_cost.h"

namespace imufit {

ceres::CostFunction* FieldPoseAccelCost::Create(const FieldLayout* layout, const PoseDirection* pose,
                                                const Eigen::Vector3d& accel_mean, double x,
                                                double gravity_mps2, const Eigen::Vector3d& sigma_raw) {
  return new FieldTermsCost(
      layout,
      new ceres::AutoDiffCostFunction<FieldPoseAccelCost, 3, FieldLayout::kAccelFree, 2>(
          new FieldPoseAccelCost(layout, pose, accel_mean, gravity_mps2, sigma_raw)),
      /*gyro=*/false, /*accel=*/true, x);
}

ceres::CostFunction* FieldPoseGyroCost::Create(const FieldLayout* layout, const Eigen::Vector3d& gyro_mean,
                                               const Eigen::Vector3d& accel_mean, double x,
                                               const Eigen::Vector3d& sigma_raw) {
  return new FieldTermsCost(
      layout,
      new ceres::AutoDiffCostFunction<FieldPoseGyroCost, 3, kGyroCoefficients, FieldLayout::kAccelFree>(
          new FieldPoseGyroCost(layout, gyro_mean, accel_mean, sigma_raw)),
      /*gyro=*/true, /*accel=*/true, x);
}

}  // namespace imufit
