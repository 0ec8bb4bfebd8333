// imufit — the subcommands of the `imufit` program. Each Add*Command registers its options on
// `root` and returns the function that runs it once the command line has been parsed; that
// function returns the exit status of docs/spec.md section 4 (0 done, 1 could not be done, 2 bad
// input; 3 done but failed acceptance limits) and lets InputError escape to main(), which prints it and
// returns 2.
#ifndef IMUFIT_APP_COMMANDS_H_
#define IMUFIT_APP_COMMANDS_H_

#include <functional>
#include <set>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_options.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/report/pdf.h"

namespace imufit {

using CommandRunner = std::function<int()>;

CommandRunner AddApplyCommand(CLI::App* root);
CommandRunner AddFitCommand(CLI::App* root);
CommandRunner AddSimulateCommand(CLI::App* root);
CommandRunner AddAllanCommand(CLI::App* root);
CommandRunner AddBatchCommand(CLI::App* root);
CommandRunner AddHistoryCommand(CLI::App* root);
CommandRunner AddLotCommand(CLI::App* root);
CommandRunner AddStoreCommand(CLI::App* root);
CommandRunner AddReportCommand(CLI::App* root);
CommandRunner AddSegmentCommand(CLI::App* root);
CommandRunner AddPlanCommand(CLI::App* root);
CommandRunner AddExportCommand(CLI::App* root);

// How a command reads samples files without a temp_c or segment column: the options of
// SamplesInputOptionTable() (segment_command.cc).
struct SamplesInputArguments {
  CliOptions<SamplesInput> options;
  bool HasTemp() const { return options.Given("temp_c"); }
  CLI::Option* TempOption() const { return options.Find("temp_c"); }  // after AddTempOption
  SamplesInput Get() const {
    SamplesInput input;
    options.Apply(&input);
    return input;
  }
};
// --temp-c, --time-unit, --delimiter, --decimal-comma and --column: how a file is read.
void AddTempOption(CLI::App* command, SamplesInputArguments* args);
// The segmentation options: --segment-window, --min-steady, --direction-tolerance, ...
void AddSegmentationOptions(CLI::App* command, SamplesInputArguments* args);

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
void AddRunReadingOptions(CLI::App* command, RunReadingArguments* args);

// The options of a unit's fit, FitRunOptionTable(), defined once for `imufit fit` and `imufit
// batch` so that the two cannot drift apart (run_options.cc).
struct FitRunArguments {
  CliOptions<FitRunOptions> options;

  // The FitRunOptions these options give: converted to SI, --prior read, and with --temp-c the
  // temperature orders 0. Throws InputError.
  FitRunOptions Resolve() const;
};
// Every option of FitRunOptionTable() but those whose keys are in `except`.
void AddFitRunOptions(CLI::App* command, FitRunArguments* args, const std::set<std::string>& except = {});

struct Calibration;
struct CorrectFileReport;
// The calibration at `calibration_path` for correcting the samples at `samples_path`: refused
// (InputError at the samples header's serial) when its serial names another unit than that header,
// unless `allow_mismatch` (then a warning); as fit, report and batch refuse (unit_serial.h).
// apply_command.cc; apply and allan --calibration share it, and --allow-mismatch
// (AddAllowMismatchFlag).
Calibration ReadUnitCalibration(const std::string& calibration_path, const std::string& samples_path,
                                bool allow_mismatch);
void AddAllowMismatchFlag(CLI::App* command, bool* allow_mismatch);
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
void AddPdfOptions(CLI::App* command, PdfArguments* args);

// --customer and --order: whom a certificate is issued to (report_command.cc; fit --report, report
// and batch share them).
struct CustomerArguments {
  std::string customer, order;
  // Throws InputError naming the option for a value that is not one line of printable text.
  void Check() const;
};
void AddCustomerOptions(CLI::App* command, CustomerArguments* args);

// Exit status 3 (an addition to docs/spec.md section 4, docs/factory.md): the job was done, but a unit
// failed its acceptance limits (or, in a batch, could not be fitted).
inline constexpr int kExitFailedLimits = 3;

// "imufit 0.1.0 (git abc123)" — the software string written into calibration files.
std::string SoftwareVersion();

}  // namespace imufit

#endif  // IMUFIT_APP_COMMANDS_H_
