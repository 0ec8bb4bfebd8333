// imufit — the field fit's starting point (field_fit.h), in closed form from the poses and turns,
// before the Ceres problem refines everything at once (imu_tk's stages, as a start only):
//
//  1. accelerometer: the axis-aligned ellipsoid through the poses' raw means (less their centroid,
//     for conditioning: an unsigned converter's counts sit near 32768), sum_i a_i A_i^2 +
//     b_i A_i = 1 by linear least squares, gives bias V_i = -b_i / (2 a_i) and scale S_i =
//     sqrt(r / a_i) / g (r = 1 + sum b_i^2 / (4 a_i)); misalignment 0;
//  2. gyro bias and g-sensitivity: B_p = V + H a_hat_p by linear least squares over the poses (V
//     the mean of B_p when H is not fitted);
//  3. gyro scale: one scale s for the three axes, misalignment 0, the s that best turns gravity's
//     direction across every turn (a scan over hand rates from 0.2 to 30 rad/s at the largest raw
//     rate of the session, 80 points, then golden-section refinement).
#ifndef IMUFIT_FIT_SRC_FIELD_START_H_
#define IMUFIT_FIT_SRC_FIELD_START_H_

#include <vector>

#include "field_cost.h"
#include "imufit/fit/field_fit.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

// The samples of `turn` as the turn cost integrates them.
std::vector<TurnSample> TurnSamples(const std::vector<Sample>& samples, const FieldTurn& turn);

// A turn's samples for the fit at no more than max_rate_hz: beyond it, the samples between the
// first and the last are averaged in blocks (the raw values are linear in the model, so the mean of
// the corrected rates is the corrected mean), each block at its mean time. The integral of the rate
// is kept; what changes is an O(h^2) coning term of the block length h (1e-5 rad per hand turn at
// 200 Hz). A 1 kHz log then costs the solver what a 200 Hz one does.
inline constexpr double kTurnFitRateHz = 200.0;
std::vector<TurnSample> DecimatedTurn(const std::vector<TurnSample>& samples, double max_rate_hz);

// sqrt(sum of the squared trapezoid weights) of a turn's samples, s: times the white noise of one
// sample (rad/s) it is the 1-sigma of the integrated angle about an axis.
double TurnNoiseWeightS(const std::vector<TurnSample>& samples);

// The starting model (temperature terms 0) from the poses and the turns' samples.
SensorModel FieldStart(const std::vector<FieldPose>& poses, const std::vector<FieldTurn>& turns,
                       const std::vector<std::vector<TurnSample>>& turn_samples,
                       const FieldFitOptions& options);

}  // namespace imufit

#endif  // IMUFIT_FIT_SRC_FIELD_START_H_
