#include "imufit/pipeline/run_windows.h"

#include <set>
#include <utility>

#include "imufit/io/error.h"
#include "imufit/io/parallel_samples.h"
#include "imufit/io/path.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

// The samples of `reader` (a SamplesReader or a ParallelSamplesReader), labelled by `labeller`
// when not null, into windows, each checked against the plan, and into the static stretch when
// not null.
template <typename Reader>
void ReadSamples(const Plan& plan, Reader* reader, Labeller* labeller, WindowBuilder* builder,
                 NoiseStretchFinder* stretch) {
  std::set<int> ids;
  for (const TableSegment& segment : plan.segments) ids.insert(segment.id);
  Sample sample;
  int last_checked = kTransitionSegment;
  while (reader->Next(&sample)) {
    if (labeller != nullptr) sample.segment = labeller->Label(sample.time_s);
    if (sample.segment != kTransitionSegment && sample.segment != last_checked) {
      if (ids.count(sample.segment) == 0) {
        reader->Fail("segment",
                     "segment " + std::to_string(sample.segment) + " is not in the plan " + plan.path);
      }
      last_checked = sample.segment;
    }
    builder->Add(sample);
    if (stretch != nullptr) stretch->Add(sample);
  }
}

}  // namespace

RunReader::RunReader(const Plan& plan, std::string samples_path, const SamplesInput& input)
    : plan_(plan),
      input_(input),
      first_pass_(std::in_place, std::move(samples_path), /*require_segment=*/false, input.Format(),
                  &digest_) {}

RunReader::RunReader(const Plan& plan, const SamplesInMemory& samples, const SamplesInput& input)
    : plan_(plan),
      input_(input),
      memory_(std::in_place, samples, input.seconds_per_time_unit),
      in_memory_(&samples) {}

RunWindows RunReader::ReadMemory(WindowBuilder* builder, NoiseStretchFinder* stretch) {
  RunWindows run;
  std::optional<Labeller> labeller;
  if (!memory_->has_segment()) {
    run.segmentation = SegmentSamples(plan_, &*memory_, input_);
    labeller.emplace(*run.segmentation);
    memory_->Rewind();
  }
  ReadSamples(plan_, &*memory_, labeller ? &*labeller : nullptr, builder, stretch);
  run.samples_sha256 = in_memory_->Sha256();
  return run;
}

RunWindows RunReader::Read(const WindowOptions& options,
                           const std::optional<NoiseStretchOptions>& noise_stretch) {
  IMUFIT_CHECK(!read_, "RunReader::Read() reads the file once");
  read_ = true;
  WindowBuilder builder(options, plan_.segments);
  std::optional<NoiseStretchFinder> stretch;
  if (noise_stretch) stretch.emplace(plan_, *noise_stretch);
  const RunHeader header = run_header();
  RunWindows run;
  try {
    if (memory_) {
      run = ReadMemory(&builder, stretch ? &*stretch : nullptr);
    } else {
      run = ReadFile(&builder, stretch ? &*stretch : nullptr);
    }
  } catch (const PlanMismatchError&) {
    // A log that is not the plan's, or one in another time unit than the one read.
    CheckSpan(options, memory_ ? memory_->time_span_s() : first_pass_->time_span_s(),
              (memory_ ? memory_->rows() : first_pass_->rows()) - 1);
    throw;
  }
  run.windows = builder.Finish();
  run.header = header;
  run.stats = builder.stats();
  if (run.windows.empty()) {
    CheckSpan(options, run.stats.last_time_s - run.stats.first_time_s, run.stats.samples - 1);
  }
  if (stretch) run.static_stretch = stretch->Finish();
  return run;
}

void RunReader::CheckSpan(const WindowOptions& options, double span_s, long long intervals) const {
  // Every segment of the plan outlasts the trim after a move in a run that can calibrate.
  const double needed_s = static_cast<double>(plan_.segments.size()) * options.trim_s;
  const std::string problem = SpanProblem(span_s, intervals, needed_s, input_.seconds_per_time_unit);
  if (!problem.empty()) throw InputError(name(), "time_s: " + problem);
}

RunWindows RunReader::ReadFile(WindowBuilder* builder, NoiseStretchFinder* stretch) {
  RunWindows run;
  if (!first_pass_->has_segment() && !IsRereadable(first_pass_->path())) {
    // A pipe (/dev/stdin, a process substitution) can be read once: its samples are kept in memory
    // (as read and checked at their lines) for the two passes.
    SamplesInMemory kept;
    kept.name = first_pass_->path();
    for (Sample sample; first_pass_->Next(&sample);) kept.samples.push_back(sample);
    MemorySamplesReader samples(kept);
    run.segmentation = SegmentSamples(plan_, &samples, input_);
    Labeller labeller(*run.segmentation);
    samples.Rewind();
    ReadSamples(plan_, &samples, &labeller, builder, stretch);
    run.samples_sha256 = digest_.HexDigest();
    return run;
  }
  // Without a segment column the first pass finds the segments and the second labels the samples.
  std::optional<SamplesReader> second_pass;
  std::optional<Labeller> labeller;
  if (!first_pass_->has_segment()) {
    run.segmentation = SegmentSamples(plan_, &*first_pass_, input_);
    labeller.emplace(*run.segmentation);
    second_pass.emplace(first_pass_->path(), /*require_segment=*/false, input_.Format());
  }
  // Parsed on every core.
  ParallelSamplesReader samples(second_pass ? &*second_pass : &*first_pass_);
  ReadSamples(plan_, &samples, labeller ? &*labeller : nullptr, builder, stretch);
  run.samples_sha256 = digest_.HexDigest();  // the first pass has read the whole file
  return run;
}

RunWindows ReadRunWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options,
                          const SamplesInput& input) {
  return RunReader(plan, samples_path, input).Read(options);
}

}  // namespace imufit
