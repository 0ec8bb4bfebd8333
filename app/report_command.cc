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
#include "imufit/io/samples.h"
#include "imufit/io/station.h"

namespace imufit {
namespace {

struct ReportArguments {
  std::string calibration;
  std::string plan;
  std::string samples;
  std::string limits;
  std::string output;
  std::string serial;
  std::string station;  // station file: where and by whom
  bool allow_mismatch = false;
  WindowOptions windows;
  SamplesInputArguments input;  // --temp-c and the segmentation options, as imufit fit has them
};

int RunReport(const ReportArguments& args) {
  RefuseToOverwriteInputs(args.output,
                          {args.calibration, args.plan, args.samples, args.limits, args.station});
  if (const std::string problem = args.windows.Validate(); !problem.empty())
    throw InputError("imufit report", problem);
  CertificateSources sources;
  sources.calibration = ReadCalibration(args.calibration);
  if (!args.serial.empty()) sources.calibration.serial = args.serial;
  // A calibration fitted without a serial: the unit's own log may still name it.
  if (sources.calibration.serial.empty()) sources.calibration.serial = ReadSamplesSerial(args.samples);
  if (!args.limits.empty()) sources.limits = ReadLimits(args.limits);
  if (!args.station.empty()) sources.station = ReadStation(args.station);
  // A certificate of a calibration for another run's data would certify nothing.
  const std::vector<std::string> mismatches = InputMismatches(sources.calibration, args.plan, args.samples);
  if (!mismatches.empty() && !args.allow_mismatch) {
    throw InputError(args.calibration, mismatches.front() + "; give --allow-mismatch to certify it anyway");
  }
  for (const std::string& m : mismatches) {
    sources.warnings.push_back(m + " (certified with --allow-mismatch)");
    std::fprintf(stderr, "imufit: warning: %s: %s\n", args.calibration.c_str(), m.c_str());
  }
  sources.plan = ReadPlan(args.plan);
  sources.samples_input = args.input.Get();
  sources.run = ReadRunWindows(sources.plan, args.samples, args.windows, sources.samples_input);
  sources.windows = args.windows;
  sources.inputs = {{"calibration", args.calibration, ""},
                    {"plan", args.plan, ""},
                    {"samples", args.samples, ""},
                    {"limits", args.limits, ""},
                    {"station", args.station, ""}};
  const Certificate certificate = MakeCertificate(sources);
  WarnIfNoSerial(certificate, args.calibration);
  WriteCertificate(args.output, certificate);
  const std::optional<Verdict>& verdict = certificate.verdict;
  std::printf("imufit report: wrote %s%s\n", args.output.c_str(),
              verdict ? (verdict->pass ? " (acceptance PASS)" : " (acceptance FAIL)") : "");
  return verdict && !verdict->pass ? kExitFailedLimits : 0;
}

}  // namespace

void WarnIfNoSerial(const Certificate& certificate, const std::string& file) {
  if (!certificate.serial.empty()) return;
  std::fprintf(stderr,
               "imufit: warning: %s: no serial (give --serial, or a '# serial:' line in the samples header): "
               "the certificate says \"(no serial)\"\n",
               file.c_str());
}

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
  command->add_option("--serial", args->serial,
                      "the unit's serial (default: the calibration's, else the samples header's)");
  command->add_option(
      "--station", args->station,
      "station file (format imufit-station: station, operator, equipment) shown on the certificate");
  command->add_flag("--allow-mismatch", args->allow_mismatch,
                    "certify even when the calibration records other plan/samples hashes than these files' "
                    "(the certificate says so)");
  command->add_option("--trim", args->windows.trim_s, "as imufit fit --trim")->capture_default_str();
  command->add_option("--max-turn-gap", args->windows.max_turn_gap_s, "as imufit fit --max-turn-gap")
      ->capture_default_str();
  AddTempOption(command, &args->input);
  AddSegmentationOptions(command, &args->input);
  return [args] { return RunReport(*args); };
}

}  // namespace imufit
