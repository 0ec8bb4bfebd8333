// The gyro's autodiff window cost (window_cost_create.h): WindowCost<kGyroParameters> instantiated with
// ceres::Jet here alone.
#include "window_cost.h"
#include "window_cost_create.h"

namespace imufit {

ceres::CostFunction* CreateGyroWindowCost(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth,
                                          const Eigen::Vector3d& a_true, double x,
                                          const Eigen::Vector3d& sigma_raw, const double* p0,
                                          const double* step) {
  return WindowCost<kGyroParameters>::Create(raw_mean, truth, a_true, x, sigma_raw, p0, step);
}

}  // namespace imufit
