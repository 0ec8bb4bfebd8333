// imufit — the command. Thin: parse the command line, call the libraries, print, and return
// the exit status of exit_status.h (docs/spec.md section 4).
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "exit_status.h"
#include "imufit/factory/git_revision.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/run/segmentation.h"

namespace imufit {

std::string SoftwareVersion() { return std::string("imufit ") + IMUFIT_VERSION; }

namespace {

// The commands, once: `imufit --help` lists them from here, in this order, and cli_test checks that
// docs/spec.md section 4 lists the same. (ninja's kTools[].)
struct CommandEntry {
  const char* name;
  const char* description;  // the command's help, first line of `imufit COMMAND --help`
  CommandRunner (*add)(CliCommand command);
};
const CommandEntry kCommands[] = {
    {"fit",
     "Fit biases, scale factors, misalignments, gyro g-sensitivity and their cubic temperature dependence to "
     "a rate-table run; write the calibration YAML with 1-sigma uncertainties. Exit 1 when the run does not "
     "determine the model (the message says what is missing) or the fit does not converge.",
     AddFitCommand},
    {"apply",
     "Correct raw samples with a calibration: writes time_s, temp_c, segment (if present), gyro in rad/s and "
     "accel in m/s^2, body frame.",
     AddApplyCommand},
    {"simulate",
     "Write a rate-table run for a plan from a known calibration (the truth), with noise, a temperature "
     "schedule and a seed. Noise densities are in Kalibr's units.",
     AddSimulateCommand},
    {"allan",
     "Allan deviation of columns of a samples file, with confidence intervals, the IEEE 952 noise terms "
     "(quantization, random walk, bias instability, rate random walk, ramp) and Kalibr noise densities. "
     "Columns are rates in SI units (a corrected file: gyro rad/s, accel m/s^2), or raw counts corrected on "
     "the way in with --calibration. Writes column,estimator,tau_s,terms,dev,dev_lo,dev_hi.",
     AddAllanCommand},
    {"batch",
     "Fit every unit of a lot: each folder of UNITS_DIR is a unit (plan.yaml and samples.csv[.gz], or "
     "samples only with --plan). Writes OUT_DIR/<unit>/calibration.yaml, report.html and manifest.yaml, and "
     "OUT_DIR/lot_summary.csv; every unit is fitted with the fit options below, as imufit fit would fit it; "
     "a re-run skips units whose inputs, fit options and software are unchanged. Exit 0 every unit passed, 3 "
     "some unit failed its limits or could not be fitted, 1 stopped early, 2 bad invocation.",
     AddBatchCommand},
    {"history",
     "Query the results store across stations: every calibration of a serial (--serial), the yield of lots "
     "(--lot [NAME]) or by station or month (--by), a key figure over time (--trend gyro.bias.x, or a figure "
     "name such as gyro_bias_dps.x; with --serial, one unit's; with --station, that station's drift).",
     AddHistoryCommand},
    {"lot",
     "Write a lot's page and summary from the results store, each unit by its latest fit in the lot: for a "
     "lot fitted in shards (imufit batch --shard), whose shards leave the lot page to the store.",
     AddLotCommand},
    {"store", "Manage results stores: merge station stores into one.", AddStoreCommand},
    {"report",
     "Write a unit's calibration certificate (one self-contained HTML file) from its calibration and the run "
     "it was fitted to; with --limits, the acceptance verdict too (exit 3 when it fails).",
     AddReportCommand},
    {"segment",
     "Find the plan's segments (rests, constant rates, turns) in a log without a segment column, print the "
     "match with times, and write the samples with a segment column (-1 while moving). Exit 1 when the log "
     "and the plan disagree (missing, extra or reordered segments; the message gives the time).",
     AddSegmentCommand},
    {"export",
     "Write a calibration for where it is used: the C runtime (c, bin), PX4, ArduPilot, Kalibr, imucal or "
     "JSON. A format that cannot hold the whole model measures its loss over the envelope first and refuses "
     "(exit 1) beyond --max-loss.",
     AddExportCommand},
    {"plan", "Judge or design a calibration plan before the run (docs/plan.md).", AddPlanCommand},
};

std::string ProgramDescription() {
  return "imufit: thermal calibration of inertial measurement units.\n"
         "Fits gyro and accelerometer biases, scale factors, misalignments, gyro g-sensitivity and\n"
         "their cubic temperature dependence from rate-table runs, applies calibrations, simulates\n"
         "runs and characterises noise; runs factory batches with acceptance limits. Exit status: " +
         ExitStatusText() + ".";
}

}  // namespace
}  // namespace imufit

int main(int argc, char** argv) {
  using imufit::kExitBadInput;
  using imufit::kExitNotDone;
  imufit::CliProgram program(imufit::ProgramDescription(),
                             imufit::SoftwareVersion() + " (git " + imufit::GitRevision() + ")");
  std::vector<std::pair<imufit::CliCommand, imufit::CommandRunner>> commands;
  for (const imufit::CommandEntry& entry : imufit::kCommands) {
    const imufit::CliCommand command = program.Add(entry.name, entry.description);
    commands.emplace_back(command, entry.add(command));
  }

  // Outputs are written to temporary files and renamed when complete; a stopped run removes them.
  imufit::InstallOutputCleanupOnSignals();
  if (const std::optional<int> status = program.Parse(argc, argv)) return *status;
  try {
    for (auto& [command, run] : commands) {
      if (command.Parsed()) return run();
    }
    return kExitBadInput;
  } catch (const imufit::InputError& e) {
    std::fprintf(stderr, "imufit: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "imufit: error: out of memory\n");
    return kExitNotDone;
  } catch (const imufit::PlanMismatchError& e) {  // well-formed files that disagree: exit 1
    std::fprintf(stderr, "imufit: %s; nothing written\n", e.what());
    return kExitNotDone;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "imufit: error: %s\n", e.what());
    return kExitNotDone;
  }
}
