// The coverage checks of the thermal fit: which coefficient groups a run cannot determine, in
// words that say what data would determine them. See thermal_fit.h.
#ifndef IMUFIT_FIT_SRC_COVERAGE_H_
#define IMUFIT_FIT_SRC_COVERAGE_H_

#include <string>
#include <vector>

#include "imufit/fit/thermal_fit.h"

namespace imufit::internal {

// A window with its truth, as the fit uses it.
struct FitWindow {
  const Window* window = nullptr;
  SegmentTruth truth;
  double x = 0.0;           // temperature in the fit basis
  bool accel_known = true;  // the specific force is known (truth.a_mps2): the accelerometer is fitted here
};

// Findings (empty when the run covers the model that `options` asks for).
std::vector<std::string> CheckCoverage(const std::vector<FitWindow>& windows, double gravity_mps2,
                                       const FitOptions& options);

// "25.0, 55.0 degC"
std::string FormatTemperatures(const std::vector<double>& temps_c);

}  // namespace imufit::internal

#endif  // IMUFIT_FIT_SRC_COVERAGE_H_
