// imufit report — the certificate of a unit from an existing calibration and the run it was
// fitted to.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>

#include "commands.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/certify.h"
#include "imufit/factory/report.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "imufit/io/station.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/pipeline/unit_serial.h"

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
  PdfArguments pdf;
  CustomerArguments customer;
  RunReadingArguments run;  // the run is read as imufit fit read it
};

int RunReport(const ReportArguments& args) {
  RefuseToOverwriteInputs(args.output,
                          {args.calibration, args.plan, args.samples, args.limits, args.station});
  const Paper paper = args.pdf.Resolve();
  args.customer.Check();
  const std::string pdf = args.pdf.pdf ? PdfPathFor(args.output) : "";
  if (!pdf.empty())
    RefuseToOverwriteInputs(pdf, {args.calibration, args.plan, args.samples, args.limits, args.station});
  const WindowOptions windows = args.run.Windows();
  const SamplesInput input = args.run.input.Get();
  if (std::string problem = windows.Validate(); !problem.empty()) throw InputError("imufit report", problem);
  if (std::string problem = input.Validate(); !problem.empty()) throw InputError("imufit report", problem);
  // Certified as `imufit fit` and `imufit batch` certify (CertifyUnit), the calibration an input.
  CertifySettings settings;
  settings.software = SoftwareVersion();
  settings.windows = windows;
  settings.samples_input = input;
  settings.customer = args.customer.customer;
  settings.order = args.customer.order;
  settings.noise_stretch = args.run.NoiseStretch();
  UnitOutcome unit;
  FitRunResult& fit = unit.fit.emplace();
  Calibration calibration = ReadCalibration(args.calibration);
  // fit --field: certified from its own record and its session, without a plan or a table run
  // (docs/factory.md, "A calibration by hand").
  const bool by_hand = calibration.body_frame.has_value();
  if (by_hand && !args.plan.empty()) {
    throw InputError("--plan", "a calibration by hand (body_frame: " + *calibration.body_frame +
                                   ", imufit fit --field) has no plan: give only its samples file");
  }
  if (!by_hand && args.plan.empty()) {
    throw InputError("imufit report",
                     "--plan is required: the certificate of a table calibration states its "
                     "errors on the plan's known truths");
  }
  // A sensor the calibration does not calibrate is marked on the certificate, never certified as fitted.
  for (std::string& note : CheckCalibratedSensors(calibration, args.calibration, CalibrationUse::kCertify,
                                                  /*allow_uncalibrated=*/true))
    unit.warnings.push_back(std::move(note));
  if (!by_hand) fit.plan = ReadPlan(args.plan);
  // The calibration's serial, unless --serial corrects it; a calibration fitted without one takes
  // the unit's own log's, then the plan's. Sources that disagree are warned about (unit_serial.h).
  SerialSource stated, stated_by_calibration, plan;
  stated.kind = SerialSource::Kind::kStated;
  stated.name = "--serial";
  stated.serial = args.serial;
  stated_by_calibration.name = "the calibration " + args.calibration;
  stated_by_calibration.serial = calibration.serial;
  plan.name = "the plan " + args.plan;
  plan.serial = fit.plan.serial;
  std::vector<SerialSource> sources = {stated, stated_by_calibration, SamplesHeaderSerial(args.samples)};
  if (!by_hand) sources.push_back(plan);
  UnitSerial serial = ResolveSerial(sources, args.allow_mismatch);
  calibration.serial = serial.serial;
  for (const std::string& w : serial.warnings) {
    unit.warnings.push_back(w);
    std::fprintf(stderr, "imufit: warning: %s\n", w.c_str());
  }
  ReadLimitsAndStation(args.limits, args.station, &settings);
  // A certificate of a calibration for another run's data would certify nothing.
  const std::vector<std::string> mismatches = InputMismatches(calibration, args.plan, args.samples);
  if (!mismatches.empty() && !args.allow_mismatch) {
    throw InputError(args.calibration, mismatches.front() + "; give --allow-mismatch to certify it anyway");
  }
  for (const std::string& m : mismatches) {
    unit.warnings.push_back(m + " (certified with --allow-mismatch)");
    std::fprintf(stderr, "imufit: warning: %s: %s\n", args.calibration.c_str(), m.c_str());
  }
  // Read once for the windows, the hash and the noise section's static stretch; a session by hand
  // is certified from its calibration's record (its samples file only hashed).
  if (!by_hand) {
    RunReader reader(fit.plan, args.samples, input);
    fit.run = reader.Read(windows, settings.noise_stretch);
  }
  fit.calibration = std::move(calibration);
  unit.serial = fit.calibration->serial;
  unit.plan_path = args.plan;
  unit.samples_path = args.samples;
  unit.samples_sha256 = fit.run.samples_sha256;
  WarnIfNoSerial(unit.serial, args.calibration);
  UnitFiles files{args.calibration, args.output, pdf, paper, {}, /*calibration_is_input=*/true};
  CertifyUnit(settings, files, &unit);  // the page and its PDF, both or neither
  const std::optional<Verdict>& verdict = unit.verdict;
  std::printf("imufit report: wrote %s%s%s\n", args.output.c_str(),
              pdf.empty() ? "" : (" and " + pdf).c_str(),
              verdict ? (verdict->pass ? " (acceptance PASS)" : " (acceptance FAIL)") : "");
  return verdict && !verdict->pass ? kExitFailedLimits : 0;
}

}  // namespace

Paper PdfArguments::Resolve() const {
  Paper value = Paper::kA4;
  if (!ValueOf(kPaperNames, paper, &value))
    throw InputError("--paper", "is \"" + paper + "\"; one of " + AllNames(kPaperNames));
  if (pdf) {
    if (const std::string problem = PdfProblem(); !problem.empty())
      throw std::runtime_error("--pdf: " + problem);
  }
  return value;
}

void CustomerArguments::Check() const {
  for (const auto& [name, value] : {std::pair<const char*, const std::string&>{"--customer", customer},
                                    std::pair<const char*, const std::string&>{"--order", order}}) {
    if (std::any_of(value.begin(), value.end(),
                    [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
      throw InputError(name, "must be one line of text without control characters");
    }
    if (value.size() > kMaxStationTextBytes) {
      throw InputError(name, "is " + std::to_string(value.size()) + " bytes long; at most " +
                                 std::to_string(kMaxStationTextBytes) + " fit on a certificate");
    }
  }
}

void AddCustomerOptions(CliCommand command, CustomerArguments* args) {
  command.Option("--customer", &args->customer, "the customer the certificate is issued to (printed on it)");
  command.Option("--order", &args->order, "the customer's order or job number (printed on the certificate)");
}

void AddPdfOptions(CliCommand command, PdfArguments* args) {
  command.Flag("--pdf", &args->pdf,
               "also print the certificate to PDF beside its HTML (report.html -> report.pdf; a batch's "
               "lot.pdf too), with headless Chromium");
  command.Option("--paper", &args->paper, "paper of --pdf: " + AllNames(kPaperNames) + " (default A4)");
}

void WarnIfNoSerial(const std::string& serial, const std::string& file) {
  if (!serial.empty()) return;
  std::fprintf(stderr,
               "imufit: warning: %s: no serial (give --serial, or a '# serial:' line in the samples header): "
               "the certificate says \"(no serial)\"\n",
               file.c_str());
}

CommandRunner AddReportCommand(CliCommand command) {
  auto args = std::make_shared<ReportArguments>();
  command.Option("--calibration,-c", &args->calibration, "calibration YAML").Required();
  command.Option("--plan,-p", &args->plan,
                 "plan YAML of the run (required, except for a calibration by hand: imufit fit --field)");
  command.Option("--samples,-s", &args->samples, "raw samples CSV (or .csv.gz) of the run").Required();
  command.Option("--limits,-l", &args->limits, "acceptance limits YAML");
  command.Option("--output,-o", &args->output, "HTML file to write").Required();
  command.Option("--serial", &args->serial,
                 "the unit's serial (default: the calibration's, else the samples header's, else the "
                 "plan's); one that contradicts the samples header is refused unless --allow-mismatch");
  command.Option(
      "--station", &args->station,
      "station file (format imufit-station: station, operator, equipment) shown on the certificate");
  AddPdfOptions(command, &args->pdf);
  AddCustomerOptions(command, &args->customer);
  command.Flag("--allow-mismatch", &args->allow_mismatch,
               "certify even when the calibration records other plan/samples hashes than these files', "
               "or --serial names another unit than the samples header (the certificate says so)");
  // The run must be cut into windows as the fit cut it: give the options the fit was given.
  AddRunReadingOptions(command, &args->run);
  return [args] { return RunReport(*args); };
}

}  // namespace imufit
