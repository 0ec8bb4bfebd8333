// imufit — the consistency gate after the fit: a converged fit whose residuals the run's noise and
// the model cannot explain is not a calibration.
//
// Two findings make a fit inconsistent (imufit exits 1 and writes nothing, unless asked to write it
// anyway, FitRunOptions::write_inconsistent, when the calibration carries the finding):
//
//  - a sensor's reduced chi-square above ReducedChi2Limit(dof). The window residuals are
//    normalised by the noise of each window's mean, so a fit that explains the run has a reduced
//    chi-square near 1, within kChi2Sigmas * sqrt(2 / dof) (the chi-square distribution's
//    spread). What the noise figure does not hold (bias wander between windows, a temperature
//    behaviour beyond the polynomial) is allowed for by kModelErrorAllowance: residuals up to that
//    many times the noise of the means, i.e. a reduced chi-square up to its square. Beyond it the
//    fit has absorbed something the plan does not describe (a wrong position, a wrong rate, a
//    disturbed window): exchanged faces give about 1e6, a rate typo 1e5;
//  - a segment that the robust loss down-weighted at every temperature where it has windows
//    (more than half of its windows there) and whose residuals exceed kModelErrorAllowance times
//    the noise of its window means: not an outlier, but a segment whose truth is not what the plan
//    says. (A segment down-weighted by a little, e.g. a turn on a noiseless one-temperature run, is
//    model error, as for the chi-square.)
#ifndef IMUFIT_PIPELINE_CONSISTENCY_H_
#define IMUFIT_PIPELINE_CONSISTENCY_H_

#include <string>
#include <vector>

#include "imufit/fit/thermal_fit.h"
#include "imufit/run/windows.h"

namespace imufit {

// Residuals up to this many times the noise of the window means are model error, not a contradiction.
inline constexpr double kModelErrorAllowance = 10.0;
// The reduced chi-square's own spread allowed, in its standard deviations sqrt(2 / dof).
inline constexpr double kChi2Sigmas = 5.0;

// The largest reduced chi-square of a consistent fit with `dof` degrees of freedom.
double ReducedChi2Limit(int dof);

// Whether the gate judges the gyro (`gyro`) or the accelerometer: only a sensor fitted with the whole
// model (every group, the g-sensitivity, the default temperature order or more). A reduced model
// chosen by the user (a held group, a lower order) leaves in its residuals what it does not model;
// its sigmas are inflated by the reduced chi-square instead.
bool JudgedByTheGate(const FitOptions& options, bool gyro);

// Why the fit of `windows` with `options` is inconsistent, on one line ("" when it is not).
std::string Inconsistency(const FitSummary& fit, const std::vector<Window>& windows,
                          const FitOptions& options);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_CONSISTENCY_H_
