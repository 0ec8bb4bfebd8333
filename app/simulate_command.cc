// imufit simulate — writes a rate-table run for a plan from a calibration used as truth.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/sim/field_session.h"
#include "imufit/sim/simulator.h"

namespace imufit {
namespace {

struct SimulateArguments {
  std::string plan;
  std::string calibration;
  std::string output;
  std::string truth_output;
  std::string serial;  // written into both files' header comments (empty: none)
  bool quiet = false;
  bool no_segment_column = false;                 // an unlabelled log (the truth file keeps the labels)
  bool no_temp_column = false;                    // a log without a thermometer
  CliOptions<SimulationOptions> options;          // SimulationOptionTable()
  bool field = false;                             // a session by hand (field_session.h): no plan
  CliOptions<FieldSessionOptions> field_options;  // FieldSessionOptionTable(), with --field
};

// The samples and the truth together, or neither: a samples file whose truth failed to write
// would pass for a complete simulation. `truth_comment` heads the truth file (with --truth).
class SimulationOutputs {
 public:
  SimulationOutputs(const SimulateArguments& args, SampleColumns columns, const std::string& comment,
                    const std::string& truth_comment)
      : samples_(args.output, columns, comment, &outputs_) {
    if (!args.truth_output.empty()) {
      truth_.emplace(args.truth_output, SampleColumns{true, true}, truth_comment, &outputs_);
    }
  }
  // Writes a raw sample and, with --truth, its true rate and specific force in the same row layout.
  void Write(const Sample& raw, const SegmentTruth& truth_of) {
    samples_.Write(raw);
    if (truth_) {
      Sample true_sample = raw;
      true_sample.gyro = truth_of.omega_radps;
      true_sample.accel = truth_of.a_mps2;
      truth_->Write(true_sample);
    }
    ++count_;
  }
  // Completes every file, then renames them together.
  void Commit() {
    samples_.Commit();
    if (truth_) truth_->Commit();
    outputs_.Commit();
  }
  long long count() const { return count_; }

 private:
  OutputTransaction outputs_;  // before the writers, which it outlives
  SamplesWriter samples_;
  std::optional<SamplesWriter> truth_;
  long long count_ = 0;
};

// simulate --field: a session by hand, written without a segment column; --truth keeps the pose
// index as its segment (-1 while turning).
int RunFieldSimulate(const SimulateArguments& args, const SimulationOptions& options) {
  FieldSessionOptions session;
  args.field_options.Apply(&session);
  if (const std::string problem = session.Validate(); !problem.empty()) {
    throw InputError("imufit simulate --field", problem);
  }
  const Calibration truth = ReadCalibration(args.calibration);
  const std::string serial_line = args.serial.empty() ? "" : "\n" + SerialComment(args.serial, "--serial");
  std::ostringstream comment;
  comment << "simulated by " << SoftwareVersion() << ": a session by hand (" << session.poses
          << " poses) from calibration " << args.calibration << ", seed " << options.seed << serial_line;
  SimulationOutputs outputs(args, SampleColumns{false, !args.no_temp_column}, comment.str(),
                            "true angular rate (rad/s) and specific force (m/s^2) of " + args.output +
                                "; segment: the pose (-1 turning)" + serial_line);
  SimulateFieldSession(options, session, truth.model, [&](const Sample& raw, const SegmentTruth& truth_of) {
    outputs.Write(raw, truth_of);
  });
  outputs.Commit();
  if (!args.quiet) {
    std::printf("simulated %lld samples (%d poses by hand) -> %s\n", outputs.count(), session.poses,
                args.output.c_str());
  }
  return 0;
}

int RunSimulate(SimulateArguments args) {
  if (!args.field && args.plan.empty())
    throw InputError("imufit simulate", "--plan is required (or --field)");
  if (args.field && !args.plan.empty()) throw InputError("--plan", "a session by hand (--field) has no plan");
  RefuseToOverwriteInputs(args.output, {args.plan, args.calibration});
  if (!args.truth_output.empty()) {
    RefuseToOverwriteInputs(args.truth_output, {args.plan, args.calibration});
    // Compare the files, not the spellings (x.csv and ./x.csv are one file).
    std::error_code truth_error;
    std::error_code output_error;
    const auto truth_file = std::filesystem::weakly_canonical(args.truth_output, truth_error);
    const auto output_file = std::filesystem::weakly_canonical(args.output, output_error);
    if (args.truth_output == args.output || (!truth_error && !output_error && truth_file == output_file)) {
      throw InputError(args.output, "--truth must differ from --output");
    }
  }
  SimulationOptions options;
  args.options.Apply(&options);
  if (const std::string problem = options.Validate(); !problem.empty()) {
    throw InputError("imufit simulate", problem);
  }
  if (args.field) return RunFieldSimulate(args, options);
  const Plan plan = ReadPlan(args.plan);
  const Calibration truth = ReadCalibration(args.calibration);

  // The serial as a unit's logger states it, so that fit, report and batch find it (samples.h).
  const std::string serial_line = args.serial.empty() ? "" : "\n" + SerialComment(args.serial, "--serial");
  std::ostringstream comment;
  comment << "simulated by " << SoftwareVersion() << " from plan " << args.plan << " and calibration "
          << args.calibration << ", seed " << options.seed << serial_line;
  SimulationOutputs outputs(
      args, SampleColumns{!args.no_segment_column, !args.no_temp_column}, comment.str(),
      "true angular rate (rad/s) and specific force (m/s^2) of " + args.output + serial_line);
  SimulateRun(options, plan.site, plan.segments, truth.model,
              [&](const Sample& raw, const SegmentTruth& truth_of) { outputs.Write(raw, truth_of); });
  outputs.Commit();
  if (!args.quiet) {
    std::printf("simulated %lld samples (%zu segments, %s) -> %s\n", outputs.count(), plan.segments.size(),
                options.ramp ? "temperature ramp" : "temperature soaks", args.output.c_str());
  }
  return 0;
}

}  // namespace

CommandRunner AddSimulateCommand(CliCommand command) {
  auto args = std::make_shared<SimulateArguments>();
  command.Option("--plan,-p", &args->plan, "plan YAML (required, but with --field)");
  command.Option("--calibration,-c", &args->calibration, "calibration YAML used as the truth").Required();
  command.Option("--output,-o", &args->output, "samples CSV to write (.gz compresses)").Required();
  command.Option("--truth", &args->truth_output,
                 "also write the true rate (rad/s) and specific force (m/s^2) of every sample, in "
                 "the corrected-samples layout");
  args->options.Add(command, SimulationOptionTable());
  args->options.Find("ramp_c").Excludes(args->options.Find("soak_temps_c"));
  args->options.Find("passes").Needs(args->options.Find("ramp_c"));
  command.Flag("--no-segment-column", &args->no_segment_column,
               "leave the segment column out (an unlabelled log; --truth keeps the true labels)");
  command.Flag("--no-temp-column", &args->no_temp_column,
               "leave the temp_c column out (a log without a thermometer; --truth keeps the temperatures)");
  command.Option("--serial", &args->serial,
                 "the unit's serial, written into the header of the samples (and --truth) as "
                 "'# serial: SERIAL', where fit, report and batch find it");
  command.Flag("--quiet,-q", &args->quiet, "print nothing but errors");
  const CliOption field = command.Flag(
      "--field", &args->field,
      "a session by hand instead of a plan: the unit rests in --poses arbitrary poses, turned by hand "
      "between them (docs/field.md); written without a segment column");
  args->field_options.Add(command, FieldSessionOptionTable());
  for (const char* key :
       {"poses", "turn_s", "min_tilt_deg", "max_tilt_deg", "gravity_mps2", "warmup_c", "warmup_tau_s"}) {
    args->field_options.Find(key).Needs(field);
  }
  return [args] { return RunSimulate(*args); };
}

}  // namespace imufit
