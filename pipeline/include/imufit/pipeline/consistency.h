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

// A corrected output further than this fraction from the truth, as a gain, is a gross error: no
// held scale of the right unit (a prior of the same model, a lower temperature order) is off by
// 10 %, while a unit of measure mistaken is off by a factor (deg/s for counts: 16; mg for m/s^2: 100).
inline constexpr double kGrossScaleError = 0.1;
// How near (relative) the log's raw units per SI unit must lie to a unit loggers write to be named.
inline constexpr double kLoggedUnitTolerance = 0.05;

// The unit-of-measure finding of every fit, subsets included ("" when none): a sensor whose
// corrected output over the run's windows is not the truth within kGrossScaleError, as a gain
// (rate windows for the gyro, windows of known specific force for the accelerometer). This is
// what a held scale in another unit than the log's does (a --prior in counts, a gyro logged in
// deg/s): the fitted bias cannot absorb a scale. The log's raw units per SI unit (the gain times
// the calibration's scale) are named when they are a unit loggers write (deg/s, mg, g, ...). A
// sensor held whole without a prior is not judged (it is not calibrated: fit_run.cc records so).
std::string UnitOfMeasureFinding(const FitSummary& fit, const std::vector<Window>& windows,
                                 const TableSite& site, const std::vector<TableSegment>& segments,
                                 const FitOptions& options);

// Why the fit of `windows` (of the plan's `site` and `segments`) with `options` is inconsistent, on
// one line ("" when it is not): the unit-of-measure finding of every fit, then the gate's findings.
std::string Inconsistency(const FitSummary& fit, const std::vector<Window>& windows, const TableSite& site,
                          const std::vector<TableSegment>& segments, const FitOptions& options);

// How far a unit's thermometer may read from the chamber's soak set-points at the ends of a run,
// degC: it reads its own die, warmer than the chamber by its self-heating (a few degC, some 10 in a
// powered tactical unit), and lags a ramp.
inline constexpr double kSoakToleranceC = 15.0;
// Above this no IMU is rated (automotive grade ends at 125 degC): a log beyond it is suspect.
inline constexpr double kMaxRatedTempC = 125.0;

// The run's temperatures (its windows') against the plan's soak set-points (Plan::soak_temps_c).
struct TemperatureFinding {
  std::string refusal;  // the coldest and warmest windows are not the coldest and warmest set-points
                        // within kSoakToleranceC (with a "Fahrenheit?" hint when 9/5 T + 32 explains it)
  std::string warning;  // without set-points: windows above kMaxRatedTempC
};
TemperatureFinding CheckRunTemperatures(const std::vector<Window>& windows,
                                        const std::vector<double>& soak_temps_c);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_CONSISTENCY_H_
