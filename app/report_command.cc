// imufit report — the certificate of a unit from an existing calibration and the run it was
// fitted to.
#include <cstdio>
#include <memory>

#include "commands.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/report.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

struct ReportArguments {
  std::string calibration;
  std::string plan;
  std::string samples;
  std::string limits;
  std::string output;
  WindowOptions windows;
};

int RunReport(const ReportArguments& args) {
  RefuseToOverwriteInputs(args.output, {args.calibration, args.plan, args.samples, args.limits});
  if (const std::string problem = args.windows.Validate(); !problem.empty())
    throw InputError("imufit report", problem);
  const Calibration calibration = ReadCalibration(args.calibration);
  std::optional<Verdict> verdict;
  if (!args.limits.empty()) verdict = EvaluateLimits(ReadLimits(args.limits), calibration);
  const Plan plan = ReadPlan(args.plan);
  CertificateSources sources;
  sources.calibration = calibration;
  sources.plan = plan;
  sources.run = ReadRunWindows(plan, args.samples, args.windows);
  sources.windows = args.windows;
  sources.verdict = verdict;
  sources.inputs = {{"calibration", args.calibration, ""},
                    {"plan", args.plan, ""},
                    {"samples", args.samples, ""},
                    {"limits", args.limits, ""}};
  WriteCertificate(args.output, MakeCertificate(sources));
  std::printf("imufit report: wrote %s%s\n", args.output.c_str(),
              verdict ? (verdict->pass ? " (acceptance PASS)" : " (acceptance FAIL)") : "");
  return verdict && !verdict->pass ? kExitFailedLimits : 0;
}

}  // namespace

CommandRunner AddReportCommand(CLI::App* root) {
  auto args = std::make_shared<ReportArguments>();
  CLI::App* command = root->add_subcommand(
      "report",
      "Write a unit's calibration certificate (one self-contained HTML file) from its calibration and the "
      "run it "
      "was fitted to; with --limits, the acceptance verdict too (exit 3 when it fails).");
  command->add_option("--calibration,-c", args->calibration, "calibration YAML")->required();
  command->add_option("--plan,-p", args->plan, "plan YAML of the run")->required();
  command->add_option("--samples,-s", args->samples, "raw samples CSV (or .csv.gz) of the run")->required();
  command->add_option("--limits,-l", args->limits, "acceptance limits YAML");
  command->add_option("--output,-o", args->output, "HTML file to write")->required();
  command->add_option("--trim", args->windows.trim_s, "as imufit fit --trim")->capture_default_str();
  return [args] { return RunReport(*args); };
}

}  // namespace imufit
