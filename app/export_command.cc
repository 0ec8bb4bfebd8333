// imufit export — a calibration in the format of where it is used (docs/export.md).
#include <cstdio>
#include <memory>
#include <vector>

#include "commands.h"
#include "imufit/export/export.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/noise_file.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

struct ExportArguments {
  std::string calibration;
  std::string noise;  // --noise: a noise block (imufit allan --noise-yaml) used as if appended
  std::string output;
  std::vector<double> max_loss = {0.5, 10.0};  // worst case: deg/s, mg
  bool force = false;
  bool allow_uncalibrated = false;
  bool quiet = false;
  CliOptions<ExportOptions> options;  // ExportOptionTable(): --format, the envelope, the formats' own
};

// The options given, for the format given: an option that serves other formats only is refused
// (InputError naming it and the formats it serves).
ExportOptions ResolveOptions(const ExportArguments& args) {
  ExportOptions options;
  args.options.Apply(&options);
  for (const OptionEntry<ExportOptions>& entry : ExportOptionTable().entries()) {
    if (args.options.Given(entry.key) && !ExportOptionServes(entry.key, options.format)) {
      throw InputError(entry.flag,
                       "only " + ExportOptionFormats(entry.key) + " use it, not " + ToString(options.format));
    }
  }
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit export", problem);
  return options;
}

// --noise: the noise block of `noise_path` in the calibration, as if appended to its file. A
// calibration with a block of its own is refused (one or the other); a block measured through
// another calibration (its calibration_sha256) is warned about: its figures are that one's SI.
void AddNoiseBlock(const std::string& noise_path, const std::string& calibration_path,
                   Calibration* calibration) {
  if (calibration->noise) {
    throw InputError("--noise", "the calibration " + calibration_path +
                                    " has a noise: block of its own: give one or the other, not both");
  }
  calibration->noise = ReadNoiseFile(noise_path);
  const std::string& measured_through = calibration->noise->calibration_sha256;
  if (!measured_through.empty() && measured_through != Sha256OfFile(calibration_path)) {
    std::fprintf(stderr,
                 "imufit: warning: %s: the noise was measured through another calibration (SHA-256 %s...) "
                 "than %s: its figures are in that calibration's units\n",
                 noise_path.c_str(), measured_through.substr(0, 16).c_str(), calibration_path.c_str());
  }
}

int RunExport(const ExportArguments& args) {
  ExportOptions options = ResolveOptions(args);
  if (!(args.max_loss[0] >= 0.0) || !(args.max_loss[1] >= 0.0)) {
    throw InputError("--max-loss", "the bounds must be two non-negative numbers: deg/s,mg");
  }
  RefuseToOverwriteInputs(args.output, {args.calibration, args.noise});
  Calibration calibration = ReadCalibration(args.calibration);
  if (!args.noise.empty()) AddNoiseBlock(args.noise, args.calibration, &calibration);
  CheckCalibratedSensors(calibration, args.calibration, CalibrationUse::kExport, args.allow_uncalibrated);
  options.software = SoftwareVersion();
  options.calibration_file = args.calibration;
  options.calibration_sha256 = Sha256OfFile(args.calibration);
  // The output is opened (a temporary file beside it) before anything is measured or printed: a
  // folder that is missing or not writable fails first. Not committed, it leaves nothing behind.
  OutputFile output(args.output);
  const ExportResult result = ExportCalibration(calibration, options);
  for (const std::string& warning : result.warnings)
    std::fprintf(stderr, "imufit: warning: %s\n", warning.c_str());
  if (!args.quiet) std::printf("%s", DescribeLoss(result, "").c_str());
  if (const std::optional<std::string> excess =
          LossBeyondBounds(result.loss, args.max_loss[0], args.max_loss[1])) {
    if (!args.force) {
      std::fprintf(stderr,
                   "imufit: %s export refused: %s (accept it: --max-loss GYRO_DPS,ACCEL_MG or --force; "
                   "narrow the envelope: --envelope-temp-c MIN,MAX, --full-scale-dps, --max-g); nothing "
                   "written\n",
                   ToString(options.format), excess->c_str());
      return kExitNotDone;
    }
    std::fprintf(stderr, "imufit: warning: %s (written anyway: --force)\n", excess->c_str());
  }
  output.Write(result.content);
  output.Commit();
  if (!args.quiet) std::printf("wrote %s (%s)\n", args.output.c_str(), ToString(options.format));
  return kExitDone;
}

}  // namespace

CommandRunner AddExportCommand(CliCommand command) {
  auto args = std::make_shared<ExportArguments>();
  command.Option("--calibration,-c", &args->calibration, "calibration YAML (imufit fit's output)").Required();
  command.Option("--noise", &args->noise,
                 "the unit's noise figures, a file of imufit allan --noise-yaml, used as if appended to the "
                 "calibration (Kalibr needs them)");
  args->options.AddOne(command, ExportOptionTable(), "format");
  args->options.Find("format").Required().DefaultText("");
  command.Option("--output,-o", &args->output, "the file to write").Required();
  command
      .Option("--max-loss", &args->max_loss,
              "largest worst-case loss over the envelope accepted, gyro deg/s and accelerometer mg")
      .Delimiter(',')
      .Expected(2)
      .ShowDefault();
  command.Flag("--force", &args->force, "write a lossy export even beyond --max-loss");
  AddAllowUncalibratedFlag(command, &args->allow_uncalibrated);
  args->options.Add(command, ExportOptionTable(), {"format"});
  command.Flag("--quiet,-q", &args->quiet, "print nothing but warnings and errors");
  return [args] { return RunExport(*args); };
}

}  // namespace imufit
