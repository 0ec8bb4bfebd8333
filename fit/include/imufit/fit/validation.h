// imufit — how well a calibration predicts data it was not fitted on.
//
// PredictWindows() corrects each window's mean raw output with a calibration (through the shared
// model, exactly as `imufit apply` corrects a sample: accelerometer first, the gyro's
// g-sensitivity from the corrected specific force) and compares it with the window's truth.
// Because the model is affine in the raw outputs at a fixed temperature, the correction of a
// window's mean is the mean of its samples' corrections.
//
// LeaveOneTemperatureOut() refits without each interior temperature group in turn and predicts
// the windows left out. The lowest and highest groups are not left out: that would test
// extrapolation, not calibration. When the temperatures left in a fold cannot determine the
// chosen order (a cubic needs four), the fold is fitted at the highest order they determine, and
// says so (HeldOutGroup::gyro_temp_order / accel_temp_order), instead of not being fitted at all.
#ifndef IMUFIT_FIT_VALIDATION_H_
#define IMUFIT_FIT_VALIDATION_H_

#include <string>
#include <vector>

#include "imufit/fit/thermal_fit.h"
#include "imufit/run/windows.h"

namespace imufit {

// The prediction error of one window, SI, body frame: corrected minus true.
struct WindowError {
  int window = 0;
  int segment = 0;
  double temp_c = 0.0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  // The truth the errors are taken against (a turn's: its mean rate over the whole occurrence).
  Eigen::Vector3d omega_true_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_true_mps2 = Eigen::Vector3d::Zero();
  // False where gravity turns in the body frame (a turn, a rate about a non-vertical axis): the
  // specific force is then not constant, and accel_mps2 is against its value at the start.
  bool specific_force_known = true;
};

// Errors aggregated over the windows of one segment (or of one held-out group).
// The accelerometer's figures leave out windows whose specific force is not known (a turn or a rate
// about a non-vertical axis: WindowError::specific_force_known).
struct ErrorStats {
  int segment = -1;  // -1 for "all"
  int windows = 0;
  int accel_windows = 0;  // of `windows`, those with a known specific force
  double gyro_rms_radps = 0.0;
  double gyro_max_radps = 0.0;
  double accel_rms_mps2 = 0.0;
  double accel_max_mps2 = 0.0;
};

std::vector<WindowError> PredictWindows(const SensorModel& model, const std::vector<Window>& windows,
                                        const TableSite& site, const std::vector<TableSegment>& segments);

// All windows together.
ErrorStats SummariseErrors(const std::vector<WindowError>& errors);
// One entry per segment id, in id order.
std::vector<ErrorStats> ErrorsBySegment(const std::vector<WindowError>& errors);

struct HeldOutGroup {
  double temp_c = 0.0;  // centre of the held-out group
  bool fitted = false;  // false: the rest of the run did not determine the model
  // The temperature orders the held-out fit used: the options' orders, or lower when the
  // temperatures left in the fold determine no more (distinct temperatures - 1).
  int gyro_temp_order = 0;
  int accel_temp_order = 0;
  bool order_lowered = false;
  std::string why_not;  // when !fitted
  ErrorStats errors;    // of the held-out windows
};

// Temperature groups: the distinct temperatures of the run, or at most `max_groups` bands of
// equal width when there are more (a ramp).
std::vector<HeldOutGroup> LeaveOneTemperatureOut(const std::vector<Window>& windows, const TableSite& site,
                                                 const std::vector<TableSegment>& segments,
                                                 const FitOptions& options, int max_groups = 6);

}  // namespace imufit

#endif  // IMUFIT_FIT_VALIDATION_H_
