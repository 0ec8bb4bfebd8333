// imufit fit — fits the thermal model of docs/spec.md section 1 to a rate-table run.
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "field_fit_command.h"
#include "imufit/base/text.h"
#include "imufit/factory/certify.h"
#include "imufit/fit/thermal_fit.h"
#include "imufit/io/error.h"
#include "imufit/io/units.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/report/engineering_units.h"
#include "imufit/store/store.h"

namespace imufit {
namespace {

struct FitArguments {
  std::string plan;
  std::string samples;                     // the first --samples (a table run: the only one)
  std::vector<std::string> samples_given;  // every --samples (--field: several sessions of one unit)
  std::string output;
  bool quiet = false;
  std::string limits;          // acceptance limits: verdict table, exit 3 when they fail
  std::string report;          // certificate HTML to write
  std::string store;           // results store to record the fit in
  std::string serial;          // the unit's serial; empty: the samples header's, else the plan's
  std::string station;         // station file shown on the certificate (with --report)
  PdfArguments pdf;            // the certificate printed too (with --report)
  CustomerArguments customer;  // printed on the certificate (with --report)
  FitRunArguments run;         // the fit options, shared with imufit batch
  FieldFitArguments field;     // --field: a session by hand, no plan (field_fit_command.h)
};

// A value and its 1-sigma: the sigma goes through the same unit conversion as the value, whose
// factor may be negative (a scale in the denominator), but a sigma is a magnitude.
std::string Format(const char* format, double value, double sigma) {
  char text[96];
  std::snprintf(text, sizeof text, format, value, std::abs(sigma));
  return text;
}

// The 25 degC values a test engineer reads first, in familiar units (engineering_units.h), with
// 1-sigma.
// Held groups (--fit) show their value and "held" instead of a sigma.
void PrintCoefficients(const FitSummary& fit, const FitOptions& options) {
  struct Figure {
    EngineeringValue value;
    bool held;
  };
  const auto at25 = [&](Sensor sensor, int coefficient) {
    return Figure{EngineeringCoefficient(fit.model, &fit.sigma, sensor, coefficient, kFigureTempC),
                  !options.Fits(sensor == Sensor::kGyro, coefficient)};
  };
  const auto text = [](const char* format, const Figure& f) {
    std::string out = Format(format, f.value.value, f.value.sigma);
    if (f.held) out = out.substr(0, out.find(" +- ")) + " (held)";
    return out;
  };
  const char* axes = "xyz";
  // A run that did not reach 25 degC (a hot-only run): the cubics extrapolated, as the certificate
  // and the limits say too (acceptance.h Figure::extrapolated).
  const double low = fit.temp_range_c[0], high = fit.temp_range_c[1];
  char range[96] = "";
  if (high > low && (kFigureTempC < low || kFigureTempC > high))
    std::snprintf(range, sizeof range, " (extrapolated: fitted %.4g..%.4g degC)", low, high);
  std::printf("  at 25 degC (+- 1 sigma)%s:\n", range);
  for (int i = 0; i < 3; ++i) {
    std::printf("    gyro %c   bias %s deg/s   scale %s raw/(deg/s)\n", axes[i],
                text("%+.5f +- %.5f", at25(Sensor::kGyro, kBiasCoefficient + i)).c_str(),
                text("%.5f +- %.5f", at25(Sensor::kGyro, kScaleCoefficient + i)).c_str());
  }
  for (int i = 0; i < 3; ++i) {
    std::printf("    accel %c  bias %s mg      scale %s raw/g\n", axes[i],
                text("%+.4f +- %.4f", at25(Sensor::kAccel, kBiasCoefficient + i)).c_str(),
                text("%.4f +- %.4f", at25(Sensor::kAccel, kScaleCoefficient + i)).c_str());
  }
  std::printf("    misalignment, mrad:          gyro                      accel\n");
  for (int m = 0; m < 6; ++m) {
    const int c = kMisalignmentCoefficient + m;
    std::printf("      %-2s  %s   %s\n", kCoefficientNames[c].axis,
                text("%+9.4f +- %.4f", at25(Sensor::kGyro, c)).c_str(),
                text("%+9.4f +- %.4f", at25(Sensor::kAccel, c)).c_str());
  }
  std::printf("    gyro g-sensitivity, deg/s/g:\n");
  for (int h = 0; h < 9; ++h) {
    const int c = kGSensitivityCoefficient + h;
    std::printf("      %-2s  %s%s", kCoefficientNames[c].axis,
                text("%+.5f +- %.5f", at25(Sensor::kGyro, c)).c_str(), h % 3 == 2 ? "\n" : "   ");
  }
}

void PrintErrors(const char* title, const std::vector<ErrorStats>& stats) {
  std::printf("  %s\n    segment  windows   gyro RMS / max, deg/s      accel RMS / max, mg\n", title);
  for (const ErrorStats& s : stats) {
    std::printf("    %7s  %7d   %10.5f / %-10.5f   %8.4f / %-8.4f\n",
                s.segment < 0 ? "all" : std::to_string(s.segment).c_str(), s.windows,
                DpsFromRadps(s.gyro_rms_radps), DpsFromRadps(s.gyro_max_radps), MgFromMps2(s.accel_rms_mps2),
                MgFromMps2(s.accel_max_mps2));
  }
}

// The fit's options from the command line.
FitRunOptions ResolveOptions(const FitArguments& args) {
  FitRunOptions options = args.run.Resolve();
  options.software = SoftwareVersion();
  options.serial = args.serial;
  // The certificate's noise section: measured whenever the unit is judged (CertifyUnit judges
  // through the certificate with a report, limits or a store, whether its page is written or not).
  options.keep_static_stretch = !args.report.empty() || !args.limits.empty() || !args.store.empty();
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit fit", problem);
  return options;
}

// What the unit is certified with: the fit's reading of the run, the program, --limits and
// --station (read: a bad file is reported before any work) and --store (opened into `store`).
CertifySettings ReadFactoryInputs(const FitArguments& args, const FitRunOptions& options,
                                  std::unique_ptr<ResultsStore>* store) {
  CertifySettings settings;
  settings.software = options.software;
  settings.windows = options.windows;
  settings.samples_input = options.input;
  ReadLimitsAndStation(args.limits, args.station, &settings);
  settings.fit_options = options.Describe();
  settings.customer = args.customer.customer;
  settings.order = args.customer.order;
  if (!args.store.empty()) {
    *store = std::make_unique<ResultsStore>(args.store);
    settings.store = store->get();
  }
  return settings;
}

// What is said before the fit's outcome: a run at one temperature, the segments found in the data.
void PrintRunNotes(const FitRunOptions& options, const FitRunResult& result) {
  if (options.input.temp_c) {
    std::printf(
        "imufit fit: note: no temp_c column, every sample at %g degC (--temp-c): temperature orders 0\n",
        *options.input.temp_c);
  }
  if (result.run.segmentation) {
    const Segmentation& segmentation = *result.run.segmentation;
    std::printf("imufit fit: no segment column: %zu segments found in %d pass%s through the plan:\n%s",
                segmentation.matches.size(), segmentation.passes, segmentation.passes == 1 ? "" : "es",
                SegmentationReport(segmentation).c_str());
  }
}

// A run that does not determine the model: one line saying what is missing and what the run held.
// Returns 1.
int ReportUndetermined(const FitArguments& args, const FitRunOptions& options, const FitRunResult& result) {
  std::fprintf(stderr, "imufit: %s, nothing written\n",
               UndeterminedMessage(args.samples, options, result).c_str());
  return kExitNotDone;
}

// The fit: the run, the residuals, the windows the robust loss down-weighted, the coefficients.
void PrintFit(const FitRunOptions& options, const FitRunResult& result) {
  const FitSummary& fit = result.fit;
  const WindowStats& stats = result.run.stats;
  std::printf("imufit fit: %s%s\n", fit.BriefReport().c_str(),
              result.inconsistency.empty() ? "" : " INCONSISTENT (written with --write-inconsistent)");
  std::printf(
      "  run: %lld samples, %d windows, %.1f .. %.1f degC; %lld samples in transitions, %lld trimmed\n",
      stats.samples, fit.windows_used, fit.temp_range_c[0], fit.temp_range_c[1], stats.transition_samples,
      stats.trimmed_samples);
  if (stats.short_samples + stats.saturated_samples + stats.gap_turn_samples > 0) {
    // Besides the transitions and the trim: every sample the windows left out, with its reason.
    std::printf("  left out of the windows: %s\n", LeftOutNote(stats, options.windows).c_str());
  }
  if (const std::string note = TimeStampNote(stats); !note.empty()) {
    std::printf("  time stamps: %s\n", note.c_str());
  }
  if (const std::string note = SaturationNote(stats); !note.empty()) {
    std::printf("  saturation: %s\n", note.c_str());
  }
  std::printf("  residual RMS: gyro %.5f deg/s, accel %.4f mg (reduced chi-square %.3g / %.3g)\n",
              DpsFromRadps(fit.gyro_rms_radps), MgFromMps2(fit.accel_rms_mps2), fit.gyro_reduced_chi2,
              fit.accel_reduced_chi2);
  if (fit.windows_downweighted > 0) {
    std::printf("  down-weighted by the %s loss:", RobustLossName(options.fit.loss).c_str());
    int shown = 0;
    for (const WindowResidual& r : fit.residuals) {
      if (!r.downweighted || shown++ >= 10) continue;
      const Window& w = result.run.windows[r.window];
      std::printf(" [segment %d, %.1f degC, t=%.1f s]", w.segment, w.temp_c, w.start_s);
    }
    std::printf("%s\n", fit.windows_downweighted > 10 ? " ..." : "");
  }
  PrintCoefficients(fit, options.fit);
  if (options.fit.gyro_bias_stability_radps == 0.0 || options.fit.accel_bias_stability_mps2 == 0.0) {
    std::printf(
        "  note: the sigmas reflect white noise only%s; give the unit's in-run bias stability\n"
        "        (--gyro-bias-stability-dph, --accel-bias-stability-ug) if its bias wanders\n",
        options.fit.gyro_bias_stability_radps == 0.0 && options.fit.accel_bias_stability_mps2 == 0.0 ? ""
        : options.fit.gyro_bias_stability_radps == 0.0 ? " for the gyro"
                                                       : " for the accelerometer");
  }
}

// --validate: the errors on each temperature left out in turn.
void PrintValidation(const std::vector<HeldOutGroup>& folds) {
  std::printf("  leave-one-temperature-out validation:\n");
  if (folds.empty()) std::printf("    not enough temperatures (needs at least 3 groups)\n");
  for (const HeldOutGroup& g : folds) {
    if (!g.fitted) {
      std::printf("    without %.1f degC: not fitted (%s)\n", g.temp_c, g.why_not.c_str());
      continue;
    }
    std::printf(
        "    without %6.1f degC: %3d held-out windows, gyro RMS %.5f deg/s (max %.5f), accel RMS %.4f mg "
        "(max %.4f)\n",
        g.temp_c, g.errors.windows, DpsFromRadps(g.errors.gyro_rms_radps),
        DpsFromRadps(g.errors.gyro_max_radps), MgFromMps2(g.errors.accel_rms_mps2),
        MgFromMps2(g.errors.accel_max_mps2));
    if (g.order_lowered) {
      std::printf(
          "      (held out at temperature order %d gyro / %d accel: the other temperatures determine no "
          "more)\n",
          g.gyro_temp_order, g.accel_temp_order);
    }
  }
}

// After CertifyUnit: the verdict, the files written, the store. Returns the exit status: 0,
// kExitFailedLimits, or kExitBadInput when the store refused the fit (then nothing was written).
int ReportCertified(const FitArguments& args, const UnitOutcome& unit, bool recorded) {
  if (!recorded) {
    std::fprintf(stderr, "imufit: %s; nothing written\n", unit.message.c_str());
    return kExitBadInput;
  }
  if (!args.report.empty()) WarnIfNoSerial(unit.fit->calibration->serial, args.samples);
  const bool judged = unit.verdict.has_value();
  if (judged && (!args.quiet || !unit.verdict->pass)) std::printf("%s", unit.verdict->Table().c_str());
  if (!args.quiet) std::printf("  wrote %s\n", args.output.c_str());
  if (!args.report.empty() && !args.quiet) std::printf("  wrote %s\n", args.report.c_str());
  if (!args.store.empty() && !args.quiet) std::printf("  recorded in %s\n", args.store.c_str());
  return judged && !unit.verdict->pass ? kExitFailedLimits : 0;
}

// The checks of --report, --pdf, --customer and --order every fit makes; returns the PDF's path ("": none).
std::string CheckCertificateOutputs(const FitArguments& args, const std::vector<std::string>& inputs) {
  if (!args.report.empty()) RefuseToOverwriteInputs(args.report, inputs);
  if (args.pdf.pdf && args.report.empty())
    throw InputError("--pdf", "prints the certificate: give --report too");
  if ((!args.customer.customer.empty() || !args.customer.order.empty()) && args.report.empty())
    throw InputError(args.customer.customer.empty() ? "--order" : "--customer",
                     "is shown on the certificate: give --report too");
  args.customer.Check();
  const std::string pdf = args.pdf.pdf ? PdfPathFor(args.report) : "";
  if (!pdf.empty()) RefuseToOverwriteInputs(pdf, inputs);
  return pdf;
}

// fit --field: written as it is, or with --limits, --report or --store certified, judged and
// recorded as a table fit is (CertifyUnit; the certificate of a calibration by hand, certificate.h).
int RunCertifiedFieldFit(const FitArguments& args) {
  if (!args.plan.empty()) throw InputError("--plan", "a session by hand (--field) has no plan");
  RefuseTableOptions(args.run);
  const FitRunOptions options = ResolveOptions(args);
  std::vector<std::string> inputs = args.samples_given;
  inputs.insert(inputs.end(), {args.limits, args.output, args.station});
  const std::string pdf = CheckCertificateOutputs(args, inputs);
  if (args.limits.empty() && args.report.empty() && args.store.empty()) {
    if (!args.station.empty())
      throw InputError("--station", "is shown on the certificate: give --report too");
    return RunFieldFit(args.field, args.samples_given, args.output, args.serial, args.quiet, options);
  }
  const Paper paper = args.pdf.Resolve();
  std::unique_ptr<ResultsStore> store;
  CertifySettings settings = ReadFactoryInputs(args, options, &store);
  settings.fit_options = "field";
  const auto certify = [&](const FieldRunResult& result) {
    UnitOutcome unit;
    unit.samples_path = args.samples;
    unit.samples_sha256 = result.samples_sha256;
    unit.serial = result.serial;
    unit.warnings = result.serial_warnings;
    FitRunResult& fit = unit.fit.emplace();
    fit.calibration = result.calibration;
    fit.serial = result.serial;
    // What the samples header said, as the record keeps it (the store's acquisition time and model).
    const FitRecord& record = *result.calibration->fit;
    fit.run.header.acquired_utc = record.acquired_utc.value_or("");
    fit.run.header.model = record.unit_model.value_or("");
    fit.run.header.firmware = record.unit_firmware.value_or("");
    fit.run.header.ambient = record.ambient.value_or("");
    const bool recorded = CertifyUnit(settings, {args.output, args.report, pdf, paper, {}}, &unit);
    if (!pdf.empty() && !args.quiet && recorded) std::printf("  wrote %s\n", pdf.c_str());
    return ReportCertified(args, unit, recorded);
  };
  return RunFieldFit(args.field, args.samples_given, args.output, args.serial, args.quiet, options, certify);
}

int RunFit(const FitArguments& args) {
  if (args.field.field) return RunCertifiedFieldFit(args);
  if (args.samples_given.size() > 1) {
    throw InputError("--samples",
                     "given " + std::to_string(args.samples_given.size()) +
                         " times: a table fit takes one run (several sessions by hand of one unit "
                         "are fitted jointly with --field)");
  }
  if (args.plan.empty()) throw InputError("imufit fit", "--plan is required (or --field)");
  const std::string check_plan = args.run.options.GivenText("check_plan");
  const std::string check_samples = args.run.options.GivenText("check_samples");
  RefuseToOverwriteInputs(args.output, {args.plan, args.samples, check_plan, check_samples, args.limits,
                                        args.run.options.GivenText("prior")});
  const std::string pdf = CheckCertificateOutputs(
      args, {args.plan, args.samples, check_plan, check_samples, args.limits, args.output, args.station});
  const Paper paper = args.pdf.Resolve();
  const FitRunOptions options = ResolveOptions(args);
  std::unique_ptr<ResultsStore> store;
  const CertifySettings settings = ReadFactoryInputs(args, options, &store);

  UnitOutcome unit;
  unit.plan_path = args.plan;
  unit.samples_path = args.samples;
  unit.fit = FitRun(args.plan, args.samples, options);
  const FitRunResult& result = *unit.fit;
  for (const auto* warnings : {&result.serial_warnings, &result.run_warnings}) {
    for (const std::string& warning : *warnings)
      std::fprintf(stderr, "imufit: warning: %s\n", warning.c_str());
  }
  if (!result.inconsistency.empty()) {
    std::fprintf(stderr,
                 "imufit: warning: the fit is inconsistent with the run's noise: %s; written anyway\n",
                 result.inconsistency.c_str());
  }
  if (!args.quiet) PrintRunNotes(options, result);
  if (result.fit.status == FitStatus::kUndetermined) return ReportUndetermined(args, options, result);
  if (!result.calibration) {
    std::fprintf(stderr, "imufit: %s: %s; nothing written\n", args.samples.c_str(),
                 result.fit.BriefReport().c_str());
    return kExitNotDone;
  }
  if (!args.quiet) {
    PrintFit(options, result);
    if (options.validate) PrintValidation(result.folds);
    if (!result.check_errors.empty()) {
      PrintErrors(("held-out run " + options.check_samples + ":").c_str(), result.check_errors);
    }
  }
  unit.serial = result.serial;
  unit.warnings = result.serial_warnings;
  unit.warnings.insert(unit.warnings.end(), result.run_warnings.begin(), result.run_warnings.end());
  unit.plan_sha256 = result.plan_sha256;
  unit.samples_sha256 = result.run.samples_sha256;
  const bool recorded = CertifyUnit(settings, {args.output, args.report, pdf, paper, {}}, &unit);
  if (!pdf.empty() && !args.quiet) std::printf("  wrote %s\n", pdf.c_str());
  return ReportCertified(args, unit, recorded);
}

}  // namespace

CommandRunner AddFitCommand(CliCommand command) {
  auto args = std::make_shared<FitArguments>();
  command.Option("--plan,-p", &args->plan, "plan YAML of the run (required, but with --field)");
  command
      .Option(
          "--samples,-s", &args->samples_given,
          "raw samples CSV (or .csv.gz); with --field, given once per session of one unit: fitted jointly")
      .Required();
  command.Option("--output,-o", &args->output, "calibration YAML to write").Required();
  AddFitRunOptions(command, &args->run);
  command.Flag("--quiet,-q", &args->quiet, "print nothing but errors");
  command.Option(
      "--limits,-l", &args->limits,
      "acceptance limits YAML: print the verdict criterion by criterion; exit 3 when the unit fails");
  command.Option(
      "--serial", &args->serial,
      "the unit's serial (default: the samples header's '# serial:' line, else the plan's serial); one "
      "that contradicts the samples header is refused (exit 2) unless --allow-mismatch");
  command.Option("--report", &args->report, "write the unit's calibration certificate (self-contained HTML)");
  AddPdfOptions(command, &args->pdf);
  AddCustomerOptions(command, &args->customer);
  command.Option("--station", &args->station,
                 "station file (format imufit-station: station, operator, equipment, the Type B sources of "
                 "U) shown on the "
                 "certificate; its sources are in every U and verdict, with or without --report");
  command.Option(
      "--store", &args->store,
      "record the fit in this results store (an SQLite file, created when missing, or a PostgreSQL URL)");
  AddFieldFitOptions(command, &args->field);
  return [args] {
    args->samples = args->samples_given.front();
    return RunFit(*args);
  };
}

}  // namespace imufit
