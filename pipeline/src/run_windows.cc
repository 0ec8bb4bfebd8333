#include "imufit/pipeline/run_windows.h"

#include <set>

#include "imufit/io/samples.h"

namespace imufit {

RunWindows ReadRunWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options,
                          const SamplesInput& input) {
  std::set<int> ids;
  for (const TableSegment& segment : plan.segments) ids.insert(segment.id);
  RunWindows run;
  SamplesReader reader(samples_path, /*require_segment=*/false, input.temp_c);
  std::optional<Labeller> labeller;
  if (!reader.has_segment()) {
    run.segmentation = SegmentSamplesFile(plan, samples_path, input);
    labeller.emplace(*run.segmentation);
  }
  WindowBuilder builder(options, plan.segments);
  Sample sample;
  int last_checked = kTransitionSegment;
  while (reader.Next(&sample)) {
    if (labeller) sample.segment = labeller->Label(sample.time_s);
    if (sample.segment != kTransitionSegment && sample.segment != last_checked) {
      if (ids.count(sample.segment) == 0) {
        reader.Fail("segment", "segment " + std::to_string(sample.segment) + " is not in the plan " + plan.path);
      }
      last_checked = sample.segment;
    }
    builder.Add(sample);
  }
  run.windows = builder.Finish();
  run.stats = builder.stats();
  return run;
}

}  // namespace imufit
