// imufit — the subcommands of the `imufit` program. Each Add*Command registers its options on
// `root` and returns the function that runs it once the command line has been parsed; that
// function returns the exit status of docs/spec.md section 4 (0 done, 1 could not be done, 2 bad
// input; 3 done but failed acceptance limits) and lets InputError escape to main(), which prints it and returns 2.
#ifndef IMUFIT_APP_COMMANDS_H_
#define IMUFIT_APP_COMMANDS_H_

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/segment_run.h"

namespace imufit {

using CommandRunner = std::function<int()>;

CommandRunner AddApplyCommand(CLI::App* root);
CommandRunner AddFitCommand(CLI::App* root);
CommandRunner AddSimulateCommand(CLI::App* root);
CommandRunner AddAllanCommand(CLI::App* root);
CommandRunner AddBatchCommand(CLI::App* root);
CommandRunner AddHistoryCommand(CLI::App* root);
CommandRunner AddReportCommand(CLI::App* root);
CommandRunner AddSegmentCommand(CLI::App* root);
CommandRunner AddExportCommand(CLI::App* root);

// How a command reads samples files without a temp_c or segment column (segment_command.cc).
struct SamplesInputArguments {
  double temp_c = 25.0;
  CLI::Option* temp_c_option = nullptr;
  SamplesInput input;
  bool HasTemp() const { return temp_c_option != nullptr && temp_c_option->count() > 0; }
  SamplesInput Get() const {
    SamplesInput result = input;
    if (HasTemp()) result.temp_c = temp_c;
    return result;
  }
};
// --temp-c.
void AddTempOption(CLI::App* command, SamplesInputArguments* args);
// --segment-window, --min-steady, --direction-tolerance, --rate-tolerance.
void AddSegmentationOptions(CLI::App* command, SamplesInputArguments* args);

// How a run is read into windows: what a certificate must read as the fit read it.
struct RunReadingArguments {
  WindowOptions windows;
  SamplesInputArguments input;
};
// --trim, --window-temp-span, --window-max-duration, --window-min-samples, --max-turn-gap, --temp-c
// and the segmentation options (fit, batch and report: run_options.cc).
void AddRunReadingOptions(CLI::App* command, RunReadingArguments* args);

// The options of a unit's fit, defined once for `imufit fit` and `imufit batch` so that the two
// cannot drift apart (run_options.cc).
struct FitRunArguments {
  RunReadingArguments run;
  FitOptions fit;  // the options CLI11 fills directly
  std::string loss = "huber";
  bool no_g_sensitivity = false;
  std::string groups = "all";  // --fit
  std::string prior;           // --prior: the held groups' values
  double gyro_bias_stability_dph = 0.0;
  double accel_bias_stability_ug = 0.0;
  CLI::Option* gyro_order_option = nullptr;
  CLI::Option* accel_order_option = nullptr;

  // The FitRunOptions these options give (fit, windows, input): parses --loss and --fit, reads
  // --prior, converts to SI, and with --temp-c makes the temperature orders 0. Throws InputError.
  FitRunOptions Resolve() const;
};
// The fit options, and AddRunReadingOptions: --fit, --prior, --loss, --loss-scale,
// --gyro-temp-order, --accel-temp-order, --no-g-sensitivity, the bias stabilities,
// --bias-correlation, --max-iterations.
void AddFitRunOptions(CLI::App* command, FitRunArguments* args);

struct Calibration;
struct CorrectFileReport;
// Warns once, with a count, when corrected samples lay outside the calibration's fit temperature
// range (an extrapolation): apply_command.cc; apply and allan --calibration share it.
void WarnOutsideFitTempRange(const Calibration& calibration, const CorrectFileReport& report);

// A certificate that names no unit (its `serial` empty) says "(no serial)" (under a warning on the
// page); this says so on stderr too, naming `file` (report_command.cc; fit --report and report
// share it).
void WarnIfNoSerial(const std::string& serial, const std::string& file);

// Exit status 3 (an addition to docs/spec.md section 4, docs/factory.md): the job was done, but a unit
// failed its acceptance limits (or, in a batch, could not be fitted).
inline constexpr int kExitFailedLimits = 3;

// "imufit 0.1.0 (git abc123)" — the software string written into calibration files.
std::string SoftwareVersion();

}  // namespace imufit

#endif  // IMUFIT_APP_COMMANDS_H_
