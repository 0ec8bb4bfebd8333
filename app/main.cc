// imufit — the command. Thin: parse the command line, call the libraries, print, and return
// the exit status of docs/spec.md section 4.
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "imufit/factory/git_revision.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/run/segmentation.h"

namespace imufit {

std::string SoftwareVersion() { return std::string("imufit ") + IMUFIT_VERSION; }

}  // namespace imufit

int main(int argc, char** argv) {
  CLI::App app{
      "imufit: thermal calibration of inertial measurement units.\n"
      "Fits gyro and accelerometer biases, scale factors, misalignments, gyro g-sensitivity and\n"
      "their cubic temperature dependence from rate-table runs, applies calibrations, simulates\n"
      "runs and characterises noise; runs factory batches with acceptance limits. Exit status: 0 done,\n"
      "1 the job could not be done, 2 bad invocation or bad input, 3 done but acceptance limits failed.",
      "imufit"};
  app.set_version_flag("--version",
                       std::string(imufit::SoftwareVersion()) + " (git " + imufit::GitRevision() + ")");
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, imufit::CommandRunner>> commands;
  // The subcommand an Add*Command just registered is the last one defined. (get_subcommands()
  // without a filter lists only the *parsed* subcommands, which is empty before parse().)
  const auto add = [&](imufit::CommandRunner runner) {
    commands.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(runner));
  };
  add(imufit::AddFitCommand(&app));
  add(imufit::AddApplyCommand(&app));
  add(imufit::AddSimulateCommand(&app));
  add(imufit::AddAllanCommand(&app));
  add(imufit::AddBatchCommand(&app));
  add(imufit::AddHistoryCommand(&app));
  add(imufit::AddLotCommand(&app));
  add(imufit::AddStoreCommand(&app));
  add(imufit::AddReportCommand(&app));
  add(imufit::AddSegmentCommand(&app));
  add(imufit::AddExportCommand(&app));
  add(imufit::AddPlanCommand(&app));

  // Outputs are written to temporary files and renamed when complete; a stopped run removes them.
  imufit::InstallOutputCleanupOnSignals();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : 2;
  }
  try {
    for (auto& [command, run] : commands) {
      if (command->parsed()) return run();
    }
    return 2;
  } catch (const imufit::InputError& e) {
    std::fprintf(stderr, "imufit: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "imufit: error: out of memory\n");
    return 1;
  } catch (const imufit::PlanMismatchError& e) {  // well-formed files that disagree: exit 1
    std::fprintf(stderr, "imufit: %s; nothing written\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "imufit: error: %s\n", e.what());
    return 1;
  }
}
