// The computed sections of a certificate (certificate.h) that have a file of their own: the
// coefficients against temperature with the windows' own estimates (coefficient_curves.cc) and
// the errors of the windows before and after correction (window_errors.cc).
#ifndef IMUFIT_FACTORY_SRC_CERTIFICATE_SECTIONS_H_
#define IMUFIT_FACTORY_SRC_CERTIFICATE_SECTIONS_H_

#include <vector>

#include "imufit/factory/certificate.h"

namespace imufit::internal {

// Every coefficient group against temperature over the calibration's fit range, with the
// estimates of the windows whose errors after correction are `errors`.
std::vector<CoefficientGroup> CoefficientCurves(const Calibration& cal, const Plan& plan,
                                                const std::vector<Window>& windows,
                                                const std::vector<WindowError>& errors);

// The raw outputs divided by the unit's own 25 degC scale factors only (no bias, misalignment,
// g-sensitivity or temperature dependence): what the calibration fixes.
SensorModel ScaleOnly(const Calibration& cal);

// Per window, the errors `after` correction and `before` (through ScaleOnly()), in deg/s and mg.
WindowResiduals Residuals(const Calibration& cal, const Plan& plan, const std::vector<Window>& windows,
                          const std::vector<WindowError>& after, const std::vector<WindowError>& before);

// Per segment, then all: RMS before, RMS and largest after.
std::vector<ResidualRow> ResidualTable(const Plan& plan, const std::vector<WindowError>& after,
                                       const std::vector<WindowError>& before);

// The rows the certificate prints (Certificate::residual_table_printed); `omitted` counts the others.
std::vector<ResidualRow> PrintedResidualRows(const std::vector<ResidualRow>& table, int* omitted);

}  // namespace imufit::internal

#endif  // IMUFIT_FACTORY_SRC_CERTIFICATE_SECTIONS_H_
