// imufit apply — corrects raw samples with a calibration.
#include <cstdio>
#include <memory>

#include "commands.h"
#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/correct_file.h"
#include "imufit/pipeline/unit_serial.h"

namespace imufit {
namespace {

struct ApplyArguments {
  std::string calibration;
  std::string samples;
  std::string output;
  bool quiet = false;
  bool allow_mismatch = false;
  bool allow_uncalibrated = false;
  SamplesInputArguments input;
};

int RunApply(const ApplyArguments& args) {
  RefuseToOverwriteInputs(args.output, {args.calibration, args.samples});
  const Calibration calibration =
      ReadUnitCalibration(args.calibration, args.samples, args.allow_mismatch, args.allow_uncalibrated);
  // A sensor passed through uncalibrated (--allow-uncalibrated) is marked in the output's header.
  std::string comment = CorrectedByComment(calibration, Sha256OfFile(args.calibration), SoftwareVersion());
  for (const std::string& sensor : UncalibratedSensors(calibration))
    comment += "\nuncalibrated: " + sensor + " (as logged, not corrected)";
  const CorrectFileReport report =
      CorrectSamplesFile(calibration, args.samples, args.output, args.input.Get().Format(), comment);
  WarnOutsideFitTempRange(calibration, report);
  if (!args.quiet) {
    std::printf("corrected %lld samples -> %s\n", report.samples, args.output.c_str());
  }
  return 0;
}

}  // namespace

Calibration ReadUnitCalibration(const std::string& calibration_path, const std::string& samples_path,
                                bool allow_mismatch, bool allow_uncalibrated) {
  Calibration calibration = ReadCalibration(calibration_path);
  CheckCalibratedSensors(calibration, calibration_path, CalibrationUse::kCorrect, allow_uncalibrated);
  SerialSource source;
  source.kind = SerialSource::Kind::kStated;
  source.name = "the calibration " + calibration_path;
  source.serial = calibration.serial;
  for (const std::string& warning :
       ResolveSerial({source, SamplesHeaderSerial(samples_path)}, allow_mismatch).warnings) {
    std::fprintf(stderr, "imufit: warning: %s\n", warning.c_str());
  }
  return calibration;
}

void WarnOutsideFitTempRange(const Calibration& calibration, const CorrectFileReport& report) {
  if (report.outside_temp_range == 0) return;
  std::fprintf(
      stderr,
      "imufit: warning: %lld of %lld samples (%.1f %%) lie more than %g degC outside the calibration's "
      "fit temperature range [%g, %g] degC (the run spans [%g, %g] degC): their correction is "
      "an extrapolation\n",
      report.outside_temp_range, report.samples, 100.0 * report.outside_temp_range / report.samples,
      kFitRangeToleranceC, calibration.fit_temp_range_c[0], calibration.fit_temp_range_c[1],
      report.min_temp_c, report.max_temp_c);
}

void AddAllowMismatchFlag(CliCommand command, bool* allow_mismatch) {
  command.Flag("--allow-mismatch", allow_mismatch,
               "correct even when the calibration names another unit than the samples header (a "
               "warning); without it such a log is refused");
}

CommandRunner AddApplyCommand(CliCommand command) {
  auto args = std::make_shared<ApplyArguments>();
  command.Option("--calibration,-c", &args->calibration, "calibration YAML (imufit fit's output)").Required();
  command.Option("--samples,-s", &args->samples, "raw samples CSV (or .csv.gz)").Required();
  command.Option("--output,-o", &args->output, "corrected samples CSV to write (.gz compresses)").Required();
  AddTempOption(command, &args->input);
  AddAllowMismatchFlag(command, &args->allow_mismatch);
  AddAllowUncalibratedFlag(command, &args->allow_uncalibrated);
  command.Flag("--quiet,-q", &args->quiet, "print nothing but warnings and errors");
  return [args] { return RunApply(*args); };
}

}  // namespace imufit
