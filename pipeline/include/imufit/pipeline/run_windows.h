// imufit — where files meet the fit: a run's samples file read into the fit's windows.
//
// imufit::pipeline links io (files) and fit (windows, the fit); the command, the benchmarks and
// any batch tooling build on it instead of re-writing the read loop.
#ifndef IMUFIT_PIPELINE_RUN_WINDOWS_H_
#define IMUFIT_PIPELINE_RUN_WINDOWS_H_

#include <string>
#include <vector>

#include "imufit/fit/windows.h"
#include "imufit/io/plan.h"

namespace imufit {

struct RunWindows {
  std::vector<Window> windows;
  WindowStats stats;
};

// Streams `samples_path` (CSV or .csv.gz) through a WindowBuilder. Throws InputError for bad
// input, including a sample whose segment id the plan does not have (located at its line).
RunWindows ReadRunWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_RUN_WINDOWS_H_
