#include "imufit/pipeline/segment_run.h"

#include "imufit/io/path.h"
#include "imufit/io/samples.h"

namespace imufit {
namespace {

// Finding segments needs no temperature: a file without temp_c (and no fixed temperature) is read
// with NaN in its place, and written without the column.
SamplesFormat FormatToRead(const SamplesInput& input) {
  SamplesFormat format = input.Format();
  format.temp_c_optional = true;
  return format;
}

}  // namespace

Segmentation SegmentSamplesFile(const Plan& plan, const std::string& samples_path,
                                const SamplesInput& input) {
  SamplesReader reader(samples_path, /*require_segment=*/false, FormatToRead(input));
  return SegmentSamples(plan, &reader, input);
}

namespace {

template <typename Reader>
Segmentation SegmentAll(const Plan& plan, Reader* reader, const SamplesInput& input) {
  MotionDetector detector(input.segmentation);
  Sample sample;
  while (reader->Next(&sample)) detector.Add(sample);
  try {
    return MatchPlan(detector.Finish(), plan.segments, input.segmentation);
  } catch (const PlanMismatchError& e) {
    throw PlanMismatchError(reader->path() + ": the log does not match the plan " + plan.path + ": " +
                            e.what());
  }
}

}  // namespace

Segmentation SegmentSamples(const Plan& plan, SamplesReader* reader, const SamplesInput& input) {
  return SegmentAll(plan, reader, input);
}

Segmentation SegmentSamples(const Plan& plan, MemorySamplesReader* reader, const SamplesInput& input) {
  return SegmentAll(plan, reader, input);
}

namespace {

// Pass 2: `reader`'s samples, from its first, written to `writer` with the segment of
// `segmentation` (an input segment column replaced).
template <typename Reader>
LabelledFileReport WriteLabelled(const Segmentation& segmentation, Reader* reader, bool input_had_segment,
                                 SamplesWriter* writer) {
  LabelledFileReport report;
  report.input_had_segment = input_had_segment;
  Labeller labeller(segmentation);
  Sample sample;
  while (reader->Next(&sample)) {
    const int label = labeller.Label(sample.time_s);
    if (label == sample.segment) ++report.agreeing;
    sample.segment = label;
    if (label != kTransitionSegment) ++report.labelled;
    ++report.samples;
    writer->Write(sample);
  }
  writer->Commit();
  return report;
}

}  // namespace

LabelledFile LabelSamplesFile(const Plan& plan, const std::string& samples_path,
                              const std::string& output_path, const SamplesInput& input) {
  SamplesReader reader(samples_path, /*require_segment=*/false, FormatToRead(input));
  const SampleColumns columns{true, reader.has_temp() || input.temp_c.has_value()};
  const std::string serial_comment = SerialComment(reader.serial(), samples_path);
  const bool had_segment = reader.has_segment();
  LabelledFile labelled;
  if (IsRereadable(samples_path)) {
    // Two passes over the file, nothing kept in memory.
    labelled.segmentation = SegmentSamples(plan, &reader, input);
    SamplesReader second_pass(samples_path, /*require_segment=*/false, FormatToRead(input));
    SamplesWriter writer(output_path, columns, serial_comment);
    labelled.report = WriteLabelled(labelled.segmentation, &second_pass, had_segment, &writer);
    return labelled;
  }
  // A pipe (/dev/stdin, a process substitution) can be read once: its samples are kept in memory
  // (as read and checked at their lines) for both passes.
  SamplesInMemory kept;
  kept.name = samples_path;
  kept.has_temp = columns.temp;
  for (Sample sample; reader.Next(&sample);) kept.samples.push_back(sample);
  MemorySamplesReader memory(kept);
  labelled.segmentation = SegmentSamples(plan, &memory, input);
  memory.Rewind();
  SamplesWriter writer(output_path, columns, serial_comment);
  labelled.report = WriteLabelled(labelled.segmentation, &memory, had_segment, &writer);
  return labelled;
}

}  // namespace imufit
