#include "imufit/pipeline/segment_run.h"

#include <cmath>

#include "imufit/io/csv_reader.h"
#include "imufit/io/samples.h"

namespace imufit {
namespace {

// Finding segments needs no temperature: a file without temp_c (and no fixed temperature) is read
// with NaN in its place, and written without the column.
SamplesFormat FormatToRead(const std::string& samples_path, const SamplesInput& input) {
  SamplesFormat format = input.Format();
  if (input.temp_c) return format;
  if (CsvReader(samples_path, nullptr, format.dialect).FindColumn(format.InFile("temp_c"))) return format;
  format.temp_c = std::nan("");
  return format;
}

}  // namespace

Segmentation SegmentSamplesFile(const Plan& plan, const std::string& samples_path,
                                const SamplesInput& input) {
  SamplesReader reader(samples_path, /*require_segment=*/false, FormatToRead(samples_path, input));
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

LabelledFileReport WriteLabelledSamples(const Segmentation& segmentation, const std::string& samples_path,
                                        const std::string& output_path, const SamplesInput& input) {
  SamplesReader reader(samples_path, /*require_segment=*/false, FormatToRead(samples_path, input));
  SamplesWriter writer(output_path, SampleColumns{true, reader.has_temp() || input.temp_c.has_value()},
                       SerialComment(reader.serial(), samples_path));
  LabelledFileReport report;
  report.input_had_segment = reader.has_segment();
  Labeller labeller(segmentation);
  Sample sample;
  while (reader.Next(&sample)) {
    const int label = labeller.Label(sample.time_s);
    if (label == sample.segment) ++report.agreeing;
    sample.segment = label;
    if (label != kTransitionSegment) ++report.labelled;
    ++report.samples;
    writer.Write(sample);
  }
  writer.Commit();
  return report;
}

}  // namespace imufit
