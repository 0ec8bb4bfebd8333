// imufit fit — fits the thermal model of SPEC.md section 1 to a rate-table run.
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include "commands.h"
#include "imufit/fit/thermal_fit.h"
#include "imufit/fit/validation.h"
#include "imufit/fit/windows.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"

namespace imufit {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kStandardGravity = 9.80665;  // m/s^2 per g, for mg and deg/s/g

struct FitArguments {
  std::string plan;
  std::string samples;
  std::string output;
  std::string check_plan;
  std::string check_samples;
  std::string loss = "huber";
  bool no_g_sensitivity = false;
  bool validate = false;
  bool quiet = false;
  FitOptions fit;
  WindowOptions windows;
};

// Reads a run into windows, refusing samples whose segment the plan does not have.
std::vector<Window> ReadWindows(const Plan& plan, const std::string& samples_path, const WindowOptions& options,
                                WindowStats* stats) {
  std::set<int> ids;
  for (const TableSegment& segment : plan.segments) ids.insert(segment.id);
  SamplesReader reader(samples_path, /*require_segment=*/true);
  WindowBuilder builder(options);
  Sample sample;
  int last_checked = kTransitionSegment;
  while (reader.Next(&sample)) {
    if (sample.segment != kTransitionSegment && sample.segment != last_checked) {
      if (ids.count(sample.segment) == 0) {
        reader.Fail("segment", "segment " + std::to_string(sample.segment) + " is not in the plan " + plan.path);
      }
      last_checked = sample.segment;
    }
    builder.Add(sample);
  }
  std::vector<Window> windows = builder.Finish();
  *stats = builder.stats();
  return windows;
}

std::string Format(const char* format, double a, double b) {
  char text[96];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

// The 25 degC values a test engineer reads first, in familiar units, with 1-sigma.
void PrintCoefficients(const FitSummary& fit) {
  const auto c0 = [](const std::array<double, kGyroParameters>& p, int coefficient) { return p[coefficient * kPolynomialTerms]; };
  const auto a0 = [](const std::array<double, kAccelParameters>& p, int coefficient) { return p[coefficient * kPolynomialTerms]; };
  const char* axes = "xyz";
  std::printf("  at 25 degC (+- 1 sigma):\n");
  for (int i = 0; i < 3; ++i) {
    const double scale = c0(fit.model.gyro, kScaleCoefficient + i);  // raw per rad/s
    const double to_dps = kRadToDeg / scale;
    std::printf("    gyro %c   bias %s deg/s   scale %s raw/(deg/s)\n", axes[i],
                Format("%+.5f +- %.5f", c0(fit.model.gyro, kBiasCoefficient + i) * to_dps,
                       c0(fit.sigma.gyro, kBiasCoefficient + i) * to_dps).c_str(),
                Format("%.5f +- %.5f", scale / kRadToDeg, c0(fit.sigma.gyro, kScaleCoefficient + i) / kRadToDeg).c_str());
  }
  for (int i = 0; i < 3; ++i) {
    const double scale = a0(fit.model.accel, kScaleCoefficient + i);  // raw per m/s^2
    const double to_mg = 1e3 / (scale * kStandardGravity);
    std::printf("    accel %c  bias %s mg      scale %s raw/g\n", axes[i],
                Format("%+.4f +- %.4f", a0(fit.model.accel, kBiasCoefficient + i) * to_mg,
                       a0(fit.sigma.accel, kBiasCoefficient + i) * to_mg).c_str(),
                Format("%.4f +- %.4f", scale * kStandardGravity, a0(fit.sigma.accel, kScaleCoefficient + i) * kStandardGravity).c_str());
  }
  std::printf("    misalignment, mrad:          gyro                      accel\n");
  for (int m = 0; m < 6; ++m) {
    const int c = kMisalignmentCoefficient + m;
    std::printf("      %-2s  %s   %s\n", kCoefficientNames[c].axis,
                Format("%+9.4f +- %.4f", c0(fit.model.gyro, c) * 1e3, c0(fit.sigma.gyro, c) * 1e3).c_str(),
                Format("%+9.4f +- %.4f", a0(fit.model.accel, c) * 1e3, a0(fit.sigma.accel, c) * 1e3).c_str());
  }
  std::printf("    gyro g-sensitivity, deg/s/g:\n");
  for (int h = 0; h < 9; ++h) {
    const int c = kGSensitivityCoefficient + h;
    const double to_dps_per_g = kRadToDeg * kStandardGravity / c0(fit.model.gyro, kScaleCoefficient + h / 3);
    std::printf("      %-2s  %s%s", kCoefficientNames[c].axis,
                Format("%+.5f +- %.5f", c0(fit.model.gyro, c) * to_dps_per_g, c0(fit.sigma.gyro, c) * to_dps_per_g).c_str(),
                h % 3 == 2 ? "\n" : "   ");
  }
}

void PrintErrors(const char* title, const std::vector<ErrorStats>& stats) {
  std::printf("  %s\n    segment  windows   gyro RMS / max, deg/s      accel RMS / max, mg\n", title);
  for (const ErrorStats& s : stats) {
    std::printf("    %7s  %7d   %10.5f / %-10.5f   %8.4f / %-8.4f\n",
                s.segment < 0 ? "all" : std::to_string(s.segment).c_str(), s.windows, s.gyro_rms_radps * kRadToDeg,
                s.gyro_max_radps * kRadToDeg, s.accel_rms_mps2 / kStandardGravity * 1e3,
                s.accel_max_mps2 / kStandardGravity * 1e3);
  }
}

YAML::Node Diagnostics(const FitSummary& fit, const WindowStats& stats, const FitArguments& args) {
  YAML::Node node;
  node["plan"] = args.plan;
  node["samples"] = args.samples;
  node["samples_read"] = stats.samples;
  node["windows_used"] = fit.windows_used;
  node["windows_downweighted"] = fit.windows_downweighted;
  node["distinct_temperatures_c"] = fit.distinct_temps_c;
  node["iterations"] = fit.iterations;
  node["termination"] = fit.termination;
  node["gyro_residual_rms_radps"] = fit.gyro_rms_radps;
  node["accel_residual_rms_mps2"] = fit.accel_rms_mps2;
  node["gyro_reduced_chi2"] = fit.gyro_reduced_chi2;
  node["accel_reduced_chi2"] = fit.accel_reduced_chi2;
  node["gyro_temp_order"] = args.fit.gyro_temp_order;
  node["accel_temp_order"] = args.fit.accel_temp_order;
  node["g_sensitivity_fitted"] = args.fit.fit_g_sensitivity;
  node["loss"] = RobustLossName(args.fit.loss);
  return node;
}

int RunFit(FitArguments args) {
  RefuseToOverwriteInputs(args.output, {args.plan, args.samples, args.check_plan, args.check_samples});
  std::string error;
  if (!ParseRobustLoss(args.loss, &args.fit.loss, &error)) throw InputError("--loss", error);
  args.fit.fit_g_sensitivity = !args.no_g_sensitivity;
  if (const std::string problem = args.fit.Validate(); !problem.empty()) throw InputError("imufit fit", problem);
  if (const std::string problem = args.windows.Validate(); !problem.empty()) throw InputError("imufit fit", problem);
  if (args.check_samples.empty() != args.check_plan.empty() && args.check_samples.empty()) {
    throw InputError("imufit fit", "--check-plan needs --check-samples");
  }

  const Plan plan = ReadPlan(args.plan);
  WindowStats stats;
  const std::vector<Window> windows = ReadWindows(plan, args.samples, args.windows, &stats);
  // A held-out run is read before fitting, so that a bad file is reported before any work.
  std::vector<Window> check_windows;
  Plan check_plan;
  if (!args.check_samples.empty()) {
    check_plan = ReadPlan(args.check_plan.empty() ? args.plan : args.check_plan);
    WindowStats check_stats;
    check_windows = ReadWindows(check_plan, args.check_samples, args.windows, &check_stats);
  }

  const FitSummary fit = FitThermalModel(windows, plan.site, plan.segments, args.fit);
  if (fit.status == FitStatus::kUndetermined) {
    std::fprintf(stderr, "imufit: %s: the run does not determine the model; nothing written:\n", args.samples.c_str());
    for (const std::string& finding : fit.undetermined) std::fprintf(stderr, "  - %s\n", finding.c_str());
    std::fprintf(stderr,
                 "  (the run: %lld samples, %lld in transitions, %lld trimmed after moves, %d windows used, %lld windows "
                 "shorter than %d samples dropped)\n",
                 stats.samples, stats.transition_samples, stats.trimmed_samples, fit.windows_used, stats.short_windows,
                 args.windows.min_samples);
    return 1;
  }
  if (!fit.IsSolutionUsable()) {
    std::fprintf(stderr, "imufit: %s: %s; nothing written\n", args.samples.c_str(), fit.BriefReport().c_str());
    return 1;
  }

  Calibration calibration;
  calibration.serial = plan.serial;
  calibration.created_utc = UtcNow();
  calibration.software = SoftwareVersion();
  calibration.fit_temp_range_c = fit.temp_range_c;
  calibration.model = fit.model;
  calibration.sigma = fit.sigma;
  calibration.extra = YAML::Node(YAML::NodeType::Map);
  calibration.extra["fit"] = Diagnostics(fit, stats, args);

  std::vector<HeldOutGroup> folds;
  if (args.validate) folds = LeaveOneTemperatureOut(windows, plan.site, plan.segments, args.fit);
  std::vector<ErrorStats> check_errors;
  if (!check_windows.empty()) {
    const std::vector<WindowError> errors = PredictWindows(fit.model, check_windows, check_plan.site, check_plan.segments);
    check_errors = ErrorsBySegment(errors);
    check_errors.push_back(SummariseErrors(errors));
    calibration.extra["check"]["samples"] = args.check_samples;
    calibration.extra["check"]["gyro_error_rms_radps"] = check_errors.back().gyro_rms_radps;
    calibration.extra["check"]["accel_error_rms_mps2"] = check_errors.back().accel_rms_mps2;
  }
  WriteCalibration(args.output, calibration);

  if (args.quiet) return 0;
  std::printf("imufit fit: %s\n", fit.BriefReport().c_str());
  std::printf("  run: %lld samples, %d windows, %.1f .. %.1f degC; %lld samples in transitions, %lld trimmed\n",
              stats.samples, fit.windows_used, fit.temp_range_c[0], fit.temp_range_c[1], stats.transition_samples,
              stats.trimmed_samples);
  std::printf("  residual RMS: gyro %.5f deg/s, accel %.4f mg (reduced chi-square %.3g / %.3g)\n",
              fit.gyro_rms_radps * kRadToDeg, fit.accel_rms_mps2 / kStandardGravity * 1e3, fit.gyro_reduced_chi2,
              fit.accel_reduced_chi2);
  if (fit.windows_downweighted > 0) {
    std::printf("  down-weighted by the %s loss:", RobustLossName(args.fit.loss).c_str());
    int shown = 0;
    for (const WindowResidual& r : fit.residuals) {
      if (!r.downweighted || shown++ >= 10) continue;
      const Window& w = windows[r.window];
      std::printf(" [segment %d, %.1f degC, t=%.1f s]", w.segment, w.temp_c, w.start_s);
    }
    std::printf("%s\n", fit.windows_downweighted > 10 ? " ..." : "");
  }
  PrintCoefficients(fit);
  if (args.validate) {
    std::printf("  leave-one-temperature-out validation:\n");
    if (folds.empty()) std::printf("    not enough temperatures (needs at least 3 groups)\n");
    for (const HeldOutGroup& g : folds) {
      if (!g.fitted) {
        std::printf("    without %.1f degC: not fitted (%s)\n", g.temp_c, g.why_not.c_str());
        continue;
      }
      std::printf("    without %6.1f degC: %3d held-out windows, gyro RMS %.5f deg/s (max %.5f), accel RMS %.4f mg (max %.4f)\n",
                  g.temp_c, g.errors.windows, g.errors.gyro_rms_radps * kRadToDeg, g.errors.gyro_max_radps * kRadToDeg,
                  g.errors.accel_rms_mps2 / kStandardGravity * 1e3, g.errors.accel_max_mps2 / kStandardGravity * 1e3);
    }
  }
  if (!check_errors.empty()) PrintErrors(("held-out run " + args.check_samples + ":").c_str(), check_errors);
  std::printf("  wrote %s\n", args.output.c_str());
  return 0;
}

}  // namespace

CommandRunner AddFitCommand(CLI::App* root) {
  auto args = std::make_shared<FitArguments>();
  FitOptions& f = args->fit;
  WindowOptions& w = args->windows;
  CLI::App* command = root->add_subcommand(
      "fit",
      "Fit biases, scale factors, misalignments, gyro g-sensitivity and their cubic temperature "
      "dependence to a rate-table run; write the calibration YAML with 1-sigma uncertainties. Exit 1 when "
      "the run does not determine the model (the message says what is missing) or the fit does not converge.");
  command->add_option("--plan,-p", args->plan, "plan YAML of the run")->required();
  command->add_option("--samples,-s", args->samples, "raw samples CSV (or .csv.gz)")->required();
  command->add_option("--output,-o", args->output, "calibration YAML to write")->required();
  command->add_option("--gyro-temp-order", f.gyro_temp_order, "order of the gyro temperature polynomials, 0..3")
      ->capture_default_str()
      ->check(CLI::Range(0, 3));
  command->add_option("--accel-temp-order", f.accel_temp_order, "order of the accel temperature polynomials, 0..3")
      ->capture_default_str()
      ->check(CLI::Range(0, 3));
  command->add_flag("--no-g-sensitivity", args->no_g_sensitivity, "hold the gyro g-sensitivity at zero");
  command->add_option("--loss", args->loss, "robust loss: none, huber, cauchy")->capture_default_str();
  command->add_option("--loss-scale", f.loss_scale,
                      "where the robust loss acts, in robust spreads of the windows' normalised residuals")
      ->capture_default_str();
  command->add_option("--trim", w.trim_s, "seconds dropped at the start of each segment occurrence")->capture_default_str();
  command->add_option("--window-temp-span", w.max_temp_span_c,
                      "a window closes when its temperature has moved this far, degC")
      ->capture_default_str();
  command->add_option("--window-max-duration", w.max_duration_s, "a window closes after this many seconds (0: never)")
      ->capture_default_str();
  command->add_option("--window-min-samples", w.min_samples, "windows with fewer samples are dropped")
      ->capture_default_str();
  command->add_option("--max-iterations", f.max_iterations, "solver iterations at most, per pass")->capture_default_str();
  command->add_option("--threads", f.num_threads, "solver threads")->capture_default_str();
  command->add_flag("--validate", args->validate,
                    "leave each interior temperature out in turn, refit, and report the errors on it");
  command->add_option("--check-samples", args->check_samples, "a held-out run to report the calibration's errors on");
  command->add_option("--check-plan", args->check_plan, "the plan of --check-samples (default: --plan)");
  command->add_flag("--quiet,-q", args->quiet, "print nothing but errors");
  return [args] { return RunFit(*args); };
}

}  // namespace imufit
