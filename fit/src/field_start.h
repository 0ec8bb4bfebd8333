// imufit — the field fit's starting point (field_fit.h), in closed form from the poses and turns,
// before the Ceres problem refines everything at once (imu_tk's stages, as a start only):
//
//  1. accelerometer: the axis-aligned ellipsoid through the poses' raw means, sum_i a_i A_i^2 +
//     b_i A_i = 1 by linear least squares, gives bias V_i = -b_i / (2 a_i) and scale S_i =
//     sqrt(r / a_i) / g (r = 1 + sum b_i^2 / (4 a_i)); misalignment 0;
//  2. gyro bias and g-sensitivity: B_p = V + H a_hat_p by linear least squares over the poses (V
//     the mean of B_p when H is not fitted);
//  3. gyro scale: one scale s for the three axes, misalignment 0, the s that best turns gravity's
//     direction across every turn (a scan over hand rates from 0.2 to 30 rad/s at the largest raw
//     rate of the session, then golden-section refinement).
#ifndef IMUFIT_FIT_SRC_FIELD_START_H_
#define IMUFIT_FIT_SRC_FIELD_START_H_

#include <vector>

#include "field_cost.h"
#include "imufit/fit/field_fit.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

// The samples of `turn` as the turn cost integrates them.
std::vector<TurnSample> TurnSamples(const std::vector<Sample>& samples, const FieldTurn& turn);

// The starting model (temperature terms 0) from the poses and the turns' samples.
SensorModel FieldStart(const std::vector<FieldPose>& poses, const std::vector<FieldTurn>& turns,
                       const std::vector<std::vector<TurnSample>>& turn_samples,
                       const FieldFitOptions& options);

}  // namespace imufit

#endif  // IMUFIT_FIT_SRC_FIELD_START_H_
