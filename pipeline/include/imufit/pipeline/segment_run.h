// imufit — an unlabelled samples file labelled with its plan's segments: the two passes of
// fit/segmentation.h over a file (pass 1 finds the segments, pass 2 labels the samples by time).
// A file is read twice, never held in memory; a pipe, which can be read once, is kept in memory.
#ifndef IMUFIT_PIPELINE_SEGMENT_RUN_H_
#define IMUFIT_PIPELINE_SEGMENT_RUN_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/io/memory_samples.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/run/segmentation.h"

namespace imufit {

// How a samples file is read when it lacks optional columns.
struct SamplesInput {
  // The temperature of every sample, degC, for a file without a temp_c column (a file with one is
  // then refused).
  std::optional<double> temp_c;
  // Seconds per unit of the time_s column (--time-unit: kTimeUnitNames).
  double seconds_per_time_unit = 1.0;
  // Its delimiter and decimal mark (--delimiter, --decimal-comma).
  CsvDialect dialect;
  // Columns under the file's own names (--column time_s=Time).
  std::vector<ColumnName> column_names;
  // A PX4 ULog's sensor instance, its multi_id (--instance; io/ulog_samples.h); none: the only one.
  std::optional<int> ulog_instance;
  // How the segments are found in a file without a segment column.
  SegmentationOptions segmentation;

  // An empty string when usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
  // How SamplesReader reads the file.
  SamplesFormat Format() const { return {temp_c, seconds_per_time_unit, dialect, column_names}; }
};

// Every option of SamplesInput, described once (model/option_table.h; run_options.cc).
const OptionTable<SamplesInput>& SamplesInputOptionTable();

// Pass 1 over `samples_path` and the match with `plan` (its segment column, if any, is ignored).
// Throws InputError for bad input and PlanMismatchError when the log and the plan disagree.
Segmentation SegmentSamplesFile(const Plan& plan, const std::string& samples_path, const SamplesInput& input);
// The same over a reader that has read nothing but the header yet; reads it to its end.
Segmentation SegmentSamples(const Plan& plan, SamplesReader* reader, const SamplesInput& input);
// The same over samples in memory.
Segmentation SegmentSamples(const Plan& plan, MemorySamplesReader* reader, const SamplesInput& input);

struct LabelledFileReport {
  long long samples = 0;
  long long labelled = 0;  // samples given a segment id (the rest are -1)
  bool input_had_segment = false;
  long long agreeing = 0;  // with input_had_segment: samples whose old and new labels agree
};

struct LabelledFile {
  Segmentation segmentation;
  LabelledFileReport report;
};

// Both passes: finds the segments of `samples_path` (SegmentSamplesFile) and writes its samples
// with their segment column to `output_path` (atomically; an input segment column is replaced),
// keeping temp_c when the input has it or `input.temp_c` gives it. A path that cannot be read
// twice (a pipe: io/path.h IsRereadable) is read once and its samples kept in memory.
LabelledFile LabelSamplesFile(const Plan& plan, const std::string& samples_path,
                              const std::string& output_path, const SamplesInput& input);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_SEGMENT_RUN_H_
