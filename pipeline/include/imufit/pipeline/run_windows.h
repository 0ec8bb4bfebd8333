// imufit — where files meet the fit: a run's samples file read into the fit's windows.
//
// imufit::pipeline links io (files) and fit (windows, the fit); the command, the benchmarks and
// any batch tooling build on it instead of re-writing the read loop.
#ifndef IMUFIT_PIPELINE_RUN_WINDOWS_H_
#define IMUFIT_PIPELINE_RUN_WINDOWS_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/io/plan.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/run/segmentation.h"
#include "imufit/run/windows.h"

namespace imufit {

struct RunWindows {
  std::vector<Window> windows;
  WindowStats stats;
  // Set when the file had no segment column and the segments were found in the data.
  std::optional<Segmentation> segmentation;
};

// Streams `samples_path` (CSV or .csv.gz) through a WindowBuilder. Throws InputError for bad
// input, including a sample whose segment id the plan does not have (located at its line). A file
// without a segment column is labelled first (segment_run.h: one more pass over the file); then
// PlanMismatchError says where the log and the plan disagree.
RunWindows ReadRunWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options,
                          const SamplesInput& input = SamplesInput());

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_RUN_WINDOWS_H_
