// imufit — a labelled run checked against its plan before the fit.
//
// A log with a `segment` column carries the table controller's labels; the plan says what each
// segment is. When the two disagree (two faces' `up` exchanged, a rate typed 200 for 300, a lost
// sign) the fit would go on and its robust loss would quietly down-weight the windows that show it.
// CheckLabels() finds such segments first, the way MatchPlan() (segmentation.h) finds them in an
// unlabelled run, but against the fit's own forward model instead of raw directions:
//
//  - per sensor, the windows whose truth the plan states (the gyro: every window, a turn's as its
//    mean rate; the accelerometer: static segments and rates about a vertical axis) are fitted by
//    linear least squares to raw = K(T) truth + V(T), K and V polynomials in temperature of the
//    fit's order (the closed-form start of the fit, thermal_fit_start.cc);
//  - a window disagrees when its raw mean is further from the model's prediction than
//        kLabelNoiseSigmas * (noise of its mean) + kLabelSignalFraction * |K truth|
//          + kLabelRangeFraction * |K| / sqrt(3) * max|truth|,
//    the run's own noise, the model error a good unit can show relative to the signal (scale
//    nonlinearity, a temperature behaviour beyond the polynomial, centripetal terms) and a floor
//    relative to the sensor's largest planned truth (bias drift within a soak);
//  - the segment with the worst disagreement is set aside and the model refitted without it, as
//    long as the rest still determine the model (the planned truths span the three axes), until
//    every segment left agrees; then every segment is judged against that model.
//
// A disagreeing segment is described by what it measured (the raw means through the model, in the
// plan's terms: gravity direction, a rate in deg/s about an axis, a turn's angle), at which
// temperatures, against what was planned, and by its likely cause: two segments whose measurements
// are each other's plans (ids exchanged), a measurement opposite to the plan (a lost sign), one
// along the planned axis of another size (a typo in the rate or angle).
#ifndef IMUFIT_RUN_LABEL_CHECK_H_
#define IMUFIT_RUN_LABEL_CHECK_H_

#include <string>
#include <vector>

#include "imufit/model/rate_table.h"
#include "imufit/run/windows.h"

namespace imufit {

// Window noise sigmas a disagreement must exceed.
inline constexpr double kLabelNoiseSigmas = 6.0;
// Model error allowed relative to a window's own signal |K truth| (5 %: far above a MEMS unit's
// scale nonlinearity, far below a wrong position (141 % of g), a typo (tens of %) or a sign (200 %)).
inline constexpr double kLabelSignalFraction = 0.05;
// Floor relative to the sensor's largest planned truth (1 %: 0.1 m/s^2 at 1 g, 3 deg/s at 300 deg/s).
inline constexpr double kLabelRangeFraction = 0.01;

// The segments of `windows` (raw units, labelled) that disagree with `segments`, described on one
// line ("" when every checkable segment agrees). `gyro_temp_order` and `accel_temp_order` are the
// fit's temperature polynomial orders.
std::string CheckLabels(const std::vector<Window>& windows, const TableSite& site,
                        const std::vector<TableSegment>& segments, int gyro_temp_order, int accel_temp_order);

}  // namespace imufit

#endif  // IMUFIT_RUN_LABEL_CHECK_H_
