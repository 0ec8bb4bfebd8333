// imufit — the fit's autodiff cost of one window (window_cost.h), one function per sensor, each
// defined in a translation unit of its own (window_cost_gyro.cc, window_cost_accel.cc): the Jet
// instantiations of the model (84 and 48 parameters) compile apart from the solving stages and
// from each other, in parallel, so that no object of the build takes long to compile.
#ifndef IMUFIT_FIT_SRC_WINDOW_COST_CREATE_H_
#define IMUFIT_FIT_SRC_WINDOW_COST_CREATE_H_

#include <Eigen/Core>

namespace ceres {
class CostFunction;
}  // namespace ceres

namespace imufit {

// WindowCost<kGyroParameters>::Create and WindowCost<kAccelParameters>::Create: the window's 3
// normalised residuals over the sensor's scaled parameters q; the caller (the ceres::Problem) owns
// the result. The arguments are WindowCost's.
ceres::CostFunction* CreateGyroWindowCost(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth,
                                          const Eigen::Vector3d& a_true, double x,
                                          const Eigen::Vector3d& sigma_raw, const double* p0,
                                          const double* step);
ceres::CostFunction* CreateAccelWindowCost(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& truth,
                                           const Eigen::Vector3d& a_true, double x,
                                           const Eigen::Vector3d& sigma_raw, const double* p0,
                                           const double* step);

}  // namespace imufit

#endif  // IMUFIT_FIT_SRC_WINDOW_COST_CREATE_H_
