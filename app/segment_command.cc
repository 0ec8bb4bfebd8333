// imufit segment — finds a plan's segments in an unlabelled log and writes it with a segment column.
#include <cstdio>
#include <memory>
#include <set>
#include <string>

#include "commands.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"

namespace imufit {
namespace {

struct SegmentArguments {
  std::string plan;
  std::string samples;
  std::string output;
  bool quiet = false;
  SamplesInputArguments input;
};

int RunSegment(const SegmentArguments& args) {
  RefuseToOverwriteInputs(args.output, {args.plan, args.samples});
  const SamplesInput input = args.input.Get();
  if (const std::string problem = input.Validate(); !problem.empty())
    throw InputError("imufit segment", problem);
  const Plan plan = ReadPlan(args.plan);
  const LabelledFile labelled = LabelSamplesFile(plan, args.samples, args.output, input);
  const Segmentation& segmentation = labelled.segmentation;
  const LabelledFileReport& report = labelled.report;
  if (args.quiet) return 0;
  std::printf(
      "imufit segment: %zu segments found in %d pass%s through the plan; %lld of %lld samples labelled -> "
      "%s\n",
      segmentation.matches.size(), segmentation.passes, segmentation.passes == 1 ? "" : "es", report.labelled,
      report.samples, args.output.c_str());
  std::printf("  raw axis signs: accel %+.0f %+.0f %+.0f, gyro %+.0f %+.0f %+.0f\n",
              segmentation.accel_signs.x(), segmentation.accel_signs.y(), segmentation.accel_signs.z(),
              segmentation.gyro_signs.x(), segmentation.gyro_signs.y(), segmentation.gyro_signs.z());
  if (report.input_had_segment) {
    std::printf(
        "  note: the input's segment column was replaced; %lld of %lld samples (%.2f %%) kept their label\n",
        report.agreeing, report.samples, 100.0 * static_cast<double>(report.agreeing) / report.samples);
  }
  std::printf("%s", SegmentationReport(segmentation).c_str());
  return 0;
}

}  // namespace

// The options that say how a file is read, as opposed to how its segments are found.
const std::set<std::string> kFileReadingKeys = {"temp_c", "time_unit", "delimiter", "decimal_comma",
                                                "column"};

void AddTempOption(CliCommand command, SamplesInputArguments* args) {
  for (const std::string& key : kFileReadingKeys)
    args->options.AddOne(command, SamplesInputOptionTable(), key);
}

void AddSegmentationOptions(CliCommand command, SamplesInputArguments* args) {
  args->options.Add(command, SamplesInputOptionTable(), kFileReadingKeys);
}

CommandRunner AddSegmentCommand(CliCommand command) {
  auto args = std::make_shared<SegmentArguments>();
  command
      .Option("--plan,-p", &args->plan, "plan YAML of the run: its segments in the order the table ran them")
      .Required();
  command.Option("--samples,-s", &args->samples, "raw samples CSV (or .csv.gz)").Required();
  command.Option("--output,-o", &args->output, "labelled samples CSV to write (.gz compresses)").Required();
  AddTempOption(command, &args->input);
  AddSegmentationOptions(command, &args->input);
  command.Flag("--quiet,-q", &args->quiet, "print nothing but errors");
  return [args] { return RunSegment(*args); };
}

}  // namespace imufit
