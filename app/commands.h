// imufit — the subcommands of the `imufit` program. Each Add*Command registers its options on
// `command` (the table of main.cc names and describes it) and returns the function that runs it
// once the command line has been parsed; that function returns an exit status of exit_status.h
// and lets InputError escape to main(), which prints it and returns kExitBadInput.
#ifndef IMUFIT_APP_COMMANDS_H_
#define IMUFIT_APP_COMMANDS_H_

#include <set>
#include <string>

#include "cli.h"
#include "cli_options.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/report/pdf.h"

namespace imufit {

CommandRunner AddApplyCommand(CliCommand command);
CommandRunner AddFitCommand(CliCommand command);
CommandRunner AddSimulateCommand(CliCommand command);
CommandRunner AddAllanCommand(CliCommand command);
CommandRunner AddBatchCommand(CliCommand command);
CommandRunner AddHistoryCommand(CliCommand command);
CommandRunner AddLotCommand(CliCommand command);
CommandRunner AddStoreCommand(CliCommand command);
CommandRunner AddReportCommand(CliCommand command);
CommandRunner AddSegmentCommand(CliCommand command);
CommandRunner AddPlanCommand(CliCommand command);
CommandRunner AddExportCommand(CliCommand command);

// How a command reads samples files without a temp_c or segment column: the options of
// SamplesInputOptionTable() (segment_command.cc).
struct SamplesInputArguments {
  CliOptions<SamplesInput> options;
  bool HasTemp() const { return options.Given("temp_c"); }
  CliOption TempOption() const { return options.Find("temp_c"); }  // after AddTempOption
  SamplesInput Get() const {
    SamplesInput input;
    options.Apply(&input);
    return input;
  }
};
// --temp-c, --time-unit, --delimiter, --decimal-comma and --column: how a file is read.
void AddTempOption(CliCommand command, SamplesInputArguments* args);
// The segmentation options: --segment-window, --min-steady, --direction-tolerance, ...
void AddSegmentationOptions(CliCommand command, SamplesInputArguments* args);

// How a run is read into windows: what a certificate must read as the fit read it.
struct RunReadingArguments {
  CliOptions<WindowOptions> windows;
  SamplesInputArguments input;
  CliOptions<NoiseStretchOptions> noise_stretch;  // the certificate's noise stretch (--noise-segment)
  NoiseStretchOptions NoiseStretch() const {
    NoiseStretchOptions options;
    noise_stretch.Apply(&options);
    return options;
  }
  WindowOptions Windows() const {
    WindowOptions options;
    windows.Apply(&options);
    return options;
  }
};
// The options of WindowOptionTable() (--trim, --window-temp-span, ...), --temp-c, the
// segmentation options and --noise-segment (report: run_options.cc).
void AddRunReadingOptions(CliCommand command, RunReadingArguments* args);

// The options of a unit's fit, FitRunOptionTable(), defined once for `imufit fit` and `imufit
// batch` so that the two cannot drift apart (run_options.cc).
struct FitRunArguments {
  CliOptions<FitRunOptions> options;

  // The FitRunOptions these options give: converted to SI, --prior read, and with --temp-c the
  // temperature orders 0. Throws InputError.
  FitRunOptions Resolve() const;
};
// Every option of FitRunOptionTable() but those whose keys are in `except`.
void AddFitRunOptions(CliCommand command, FitRunArguments* args, const std::set<std::string>& except = {});

struct Calibration;
struct CorrectFileReport;
// The calibration at `calibration_path` for correcting the samples at `samples_path`: refused
// (InputError at the samples header's serial) when its serial names another unit than that header,
// unless `allow_mismatch` (then a warning); as fit, report and batch refuse (unit_serial.h).
// apply_command.cc; apply and allan --calibration share it, and --allow-mismatch
// (AddAllowMismatchFlag).
// A sensor the calibration does not calibrate (UncalibratedSensors) is refused too, unless
// `allow_uncalibrated` (CheckCalibratedSensors).
Calibration ReadUnitCalibration(const std::string& calibration_path, const std::string& samples_path,
                                bool allow_mismatch, bool allow_uncalibrated);

// How a command uses a calibration's sensors (CheckCalibratedSensors).
enum class CalibrationUse {
  kCorrect,  // apply, allan --calibration: the samples corrected
  kExport,   // export: the coefficients handed on
  kCertify,  // report: the coefficients certified
};
// One sentence per sensor that `calibration` (read from `path`) does not calibrate
// (UncalibratedSensors: held whole at nominal values by a fit of the other sensor alone).
std::vector<std::string> UncalibratedNotes(const Calibration& calibration, const std::string& path);
// The one check of every consumer of a calibration (calibration_use.cc): correcting or exporting a
// sensor it does not calibrate is refused (PlanMismatchError: exit 1, naming the sensor) unless
// `allow_uncalibrated`; otherwise, and when certifying, each such sensor is warned about on stderr
// and its note returned, for the certificate to carry.
std::vector<std::string> CheckCalibratedSensors(const Calibration& calibration, const std::string& path,
                                                CalibrationUse use, bool allow_uncalibrated);
void AddAllowUncalibratedFlag(CliCommand command, bool* allow_uncalibrated);
void AddAllowMismatchFlag(CliCommand command, bool* allow_mismatch);
// Warns once, with a count, when corrected samples lay outside the calibration's fit temperature
// range (an extrapolation): apply_command.cc; apply and allan --calibration share it.
void WarnOutsideFitTempRange(const Calibration& calibration, const CorrectFileReport& report);

// A certificate that names no unit (its `serial` empty) says "(no serial)" (under a warning on the
// page); this says so on stderr too, naming `file` (report_command.cc; fit --report and report
// share it).
void WarnIfNoSerial(const std::string& serial, const std::string& file);

// --pdf and --paper: the certificate (and a batch's lot page) printed to PDF beside its HTML
// (report_command.cc; fit --report, report and batch share them).
struct PdfArguments {
  bool pdf = false;
  std::string paper = NameOf(kPaperNames, Paper::kA4);
  // The paper (InputError naming --paper for another name); with --pdf, throws std::runtime_error
  // (exit 1) before any work when Chromium cannot be found.
  Paper Resolve() const;
};
void AddPdfOptions(CliCommand command, PdfArguments* args);

// --customer and --order: whom a certificate is issued to (report_command.cc; fit --report, report
// and batch share them).
struct CustomerArguments {
  std::string customer, order;
  // Throws InputError naming the option for a value that is not one line of printable text.
  void Check() const;
};
void AddCustomerOptions(CliCommand command, CustomerArguments* args);

// "imufit 0.1.0 (git abc123)" — the software string written into calibration files.
std::string SoftwareVersion();

}  // namespace imufit

#endif  // IMUFIT_APP_COMMANDS_H_
