#include "imufit/pipeline/static_stretch.h"

#include <utility>

#include "imufit/io/samples.h"

namespace imufit {

LongestStaticStretch::LongestStaticStretch(const Plan& plan) {
  // A segment id names the plan's first segment with that id (Plan::Find).
  std::set<int> seen;
  for (const TableSegment& segment : plan.segments) {
    if (seen.insert(segment.id).second && segment.IsStatic()) static_segments_.insert(segment.id);
  }
}

void LongestStaticStretch::Add(const Sample& sample) {
  const bool is_static = static_segments_.count(sample.segment) > 0;
  if (!is_static || (current_.size() > 0 && current_.segment != sample.segment)) Close();
  if (!is_static) return;
  if (current_.size() == 0) {
    current_.segment = sample.segment;
    current_.start_time_s = sample.time_s;
  }
  current_.end_time_s = sample.time_s;
  current_.temp_sum_c += sample.temp_c;
  for (int axis = 0; axis < 3; ++axis) current_.gyro[axis].push_back(sample.gyro(axis));
}

void LongestStaticStretch::Close() {
  if (current_.size() > best_.size()) std::swap(best_, current_);
  current_.segment = kTransitionSegment;
  current_.start_time_s = current_.end_time_s = current_.temp_sum_c = 0.0;
  for (std::vector<double>& axis : current_.gyro) axis.clear();  // keeps the memory for the next
}

StaticStretch LongestStaticStretch::Finish() {
  Close();
  current_ = StaticStretch();
  return std::move(best_);
}

StaticStretch ReadStaticStretch(const Plan& plan, const std::string& samples_path, const SamplesInput& input,
                                const std::optional<Segmentation>& segmentation) {
  SamplesReader reader(samples_path, /*require_segment=*/false, input.Format());
  std::optional<Labeller> labeller;
  if (!reader.has_segment()) {
    labeller.emplace(segmentation ? *segmentation : SegmentSamplesFile(plan, samples_path, input));
  }
  LongestStaticStretch stretch(plan);
  Sample sample;
  while (reader.Next(&sample)) {
    if (labeller) sample.segment = labeller->Label(sample.time_s);
    stretch.Add(sample);
  }
  return stretch.Finish();
}

}  // namespace imufit
