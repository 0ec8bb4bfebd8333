// imufit export — a calibration in the format of where it is used (docs/export.md).
#include <cstdio>
#include <memory>
#include <vector>

#include "commands.h"
#include "imufit/export/export.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

struct ExportArguments {
  std::string calibration;
  std::string format;
  std::string output;
  std::vector<double> max_loss = {0.5, 10.0};  // worst case: deg/s, mg
  bool force = false;
  bool quiet = false;
  double temp_c = 0.0;
  CliOption temp_c_option;
  long long device_id = 0;
  CliOption device_id_option;
  ExportOptions options;
};

int RunExport(ExportArguments args) {
  const std::optional<ExportFormat> format = ExportFormatFromString(args.format);
  if (!format) {
    throw InputError("--format",
                     QuoteForMessage(args.format) + " is not a format (" + ExportFormatNames() + ")");
  }
  if (!(args.max_loss[0] >= 0.0) || !(args.max_loss[1] >= 0.0)) {
    throw InputError("--max-loss", "the bounds must be two non-negative numbers: deg/s,mg");
  }
  RefuseToOverwriteInputs(args.output, {args.calibration});
  const Calibration calibration = ReadCalibration(args.calibration);
  ExportOptions& options = args.options;
  options.format = *format;
  if (args.temp_c_option.Given()) options.temp_c = args.temp_c;
  if (args.device_id_option.Given()) options.device_id = args.device_id;
  options.software = SoftwareVersion();
  options.calibration_file = args.calibration;
  options.calibration_sha256 = Sha256OfFile(args.calibration);
  const ExportResult result = ExportCalibration(calibration, options);
  if (!args.quiet) std::printf("%s", DescribeLoss(result, "").c_str());
  if (const std::optional<std::string> excess =
          LossBeyondBounds(result.loss, args.max_loss[0], args.max_loss[1])) {
    if (!args.force) {
      std::fprintf(stderr, "imufit: %s export refused: %s (--max-loss, --force); nothing written\n",
                   ToString(*format), excess->c_str());
      return 1;
    }
    std::fprintf(stderr, "imufit: warning: %s (written anyway: --force)\n", excess->c_str());
  }
  WriteFileAtomically(args.output, result.content);
  if (!args.quiet) std::printf("wrote %s (%s)\n", args.output.c_str(), ToString(*format));
  return 0;
}

}  // namespace

CommandRunner AddExportCommand(CliCommand command) {
  auto args = std::make_shared<ExportArguments>();
  command.Option("--calibration,-c", &args->calibration, "calibration YAML (imufit fit's output)").Required();
  command.Option("--format,-f", &args->format, "c, bin, px4, ardupilot, kalibr, imucal or json").Required();
  command.Option("--output,-o", &args->output, "the file to write").Required();
  command
      .Option("--max-loss", &args->max_loss,
              "largest worst-case loss over the envelope accepted, gyro deg/s and accelerometer mg")
      .Delimiter(',')
      .Expected(2)
      .ShowDefault();
  command.Flag("--force", &args->force, "write a lossy export even beyond --max-loss");
  command
      .Option("--full-scale-dps", &args->options.full_scale_dps,
              "the envelope: the largest angular rate on each axis, deg/s")
      .ShowDefault();
  command.Option("--max-g", &args->options.max_g, "the envelope: the largest specific force on each axis, g")
      .ShowDefault();
  command
      .Option("--gyro-raw-per-radps", &args->options.gyro_raw_per_radps,
              "px4, ardupilot, kalibr: what the driver divides the raw gyro output by to give rad/s")
      .ShowDefault();
  command
      .Option("--accel-raw-per-mps2", &args->options.accel_raw_per_mps2,
              "px4, ardupilot, kalibr: what the driver divides the raw accelerometer output by to give m/s^2")
      .ShowDefault();
  args->temp_c_option = command.Option("--temp-c", &args->temp_c,
                                       "kalibr, imucal: the temperature the one-temperature formats are "
                                       "taken at, degC (default: the reference)");
  args->device_id_option =
      command.Option("--device-id", &args->device_id, "px4: the sensor's device ID (TC_G0_ID, CAL_ACC0_ID)");
  command.Option("--c-name", &args->options.c_name, "c: the C name of the unit (NAME_INITIALIZER)")
      .ShowDefault();
  command.Option("--rostopic", &args->options.rostopic, "kalibr: the IMU's ROS topic").ShowDefault();
  command.Flag("--quiet,-q", &args->quiet, "print nothing but warnings and errors");
  return [args] { return RunExport(*args); };
}

}  // namespace imufit
