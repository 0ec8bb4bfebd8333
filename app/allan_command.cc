// imufit allan — Allan deviation (and relatives) of columns of a samples file, their confidence
// intervals, the IEEE 952 noise terms, a noise YAML file and a plot (docs/spec.md section 4,
// docs/allan.md). Thin: the per-column analysis is noise/column_analysis.h, the files are
// io/noise_file.h (filled from the analysis here; engineer units: io/units.h), the plot is
// factory/allan_plot.h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "imufit/base/enum_names.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/noise_file.h"
#include "imufit/io/output_file.h"
#include "imufit/io/path.h"
#include "imufit/io/sha256.h"
#include "imufit/io/units.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/column_analysis.h"
#include "imufit/pipeline/correct_file.h"
#include "imufit/pipeline/series_reader.h"
#include "imufit/report/allan_plot.h"

namespace imufit {
namespace {

struct AllanArguments {
  std::string samples;
  std::vector<std::string> columns;
  std::string output;
  CliOptions<AllanOptions> allan;           // AllanOptionTable(): --estimator, --confidence, ...
  CliOptions<NoiseFitOptions> noise_fit;    // NoiseFitOptionTable(): --min-clusters
  CliOptions<UniformSeriesOptions> series;  // UniformSeriesOptionTable(): --time-tolerance, --gaps
  std::string taus = "octave";
  std::string kind = "auto";
  std::string noise_yaml;
  std::string plot;
  std::string plot_units = "native";
  double scale = 1.0;
  std::string calibration;      // correct the raw samples through it first (as imufit apply does)
  SamplesInputArguments input;  // --temp-c, for a raw log without temp_c; --time-unit
  bool quiet = false;
  bool allow_mismatch = false;  // with --calibration
  bool allow_uncalibrated = false;
};

[[noreturn]] void BadInvocation(const std::string& message) { throw InputError("imufit allan", message); }

std::string Number(double value, int digits = 4) {
  if (!std::isfinite(value)) return "n/a";
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

// A static gyro reads Earth rate and its bias: far below 1 rad/s (57 deg/s) in rad/s. A larger
// mean means the column is not in rad/s (raw counts, or deg/s).
constexpr double kImplausibleGyroMeanRadps = 1.0;
// An accelerometer at rest reads about 1 g; a mean beyond 4 g is not m/s^2.
constexpr double kImplausibleAccelMeanMps2 = 4.0 * kStandardGravityMps2;

void PlausibilityWarnings(const AllanArguments& args, const UniformSeries& series,
                          const std::vector<ColumnAnalysis>& results) {
  // A static log may be long and slow: a warning here, where a run against a plan is refused
  // (SamplesReader).
  if (!args.input.options.Given("time_unit") && series.sample_interval_s >= kMaxSampleIntervalS) {
    std::fprintf(stderr,
                 "imufit: warning: %s: time_s steps by %s s (%s Hz), slow for an IMU: if the timestamps are "
                 "milliseconds or microseconds, say so with --time-unit ms or --time-unit us\n",
                 args.samples.c_str(), Number(series.sample_interval_s).c_str(),
                 Number(1.0 / series.sample_interval_s).c_str());
  }
  for (const ColumnAnalysis& r : results) {
    const double mean = std::abs(r.curve.mean);
    const bool gyro = r.kind == ColumnKind::kGyro && mean > kImplausibleGyroMeanRadps;
    const bool accel = r.kind == ColumnKind::kAccel && mean > kImplausibleAccelMeanMps2;
    if (!gyro && !accel) continue;
    if (!args.calibration.empty()) {
      // Corrected and still implausible: the calibration is not this unit's (or not for raw counts).
      std::fprintf(
          stderr,
          "imufit: warning: %s: %s has a mean of %s %s after correction with %s, implausible for a %s "
          "at rest: is it this unit's calibration, and are the columns what it was fitted to?\n",
          args.samples.c_str(), r.name.c_str(), Number(r.curve.mean).c_str(), SiUnit(r.kind),
          args.calibration.c_str(), gyro ? "gyro" : "accelerometer");
      continue;
    }
    std::fprintf(stderr,
                 "imufit: warning: %s: %s has a mean of %s %s, implausible for a %s at rest in SI units: are "
                 "these raw counts (or deg/s, g)? Give the unit's calibration (--calibration CAL.yaml), or "
                 "--scale (raw per %s)\n",
                 args.samples.c_str(), r.name.c_str(), Number(r.curve.mean).c_str(), SiUnit(r.kind),
                 gyro ? "gyro" : "accelerometer", SiUnit(r.kind));
  }
}

// The analysis and what it needs, parsed and checked before anything is read.
struct AllanSettings {
  AllanOptions options;
  NoiseFitOptions fit_options;
  UniformSeriesOptions series_options;
  TauSpec tau_spec;
  double seconds_per_unit = 1.0;  // of the time column
  AllanPlotUnits plot_units = AllanPlotUnits::kNative;
};

// What was analysed, for the summary and the plot's title: the samples, and the calibration they
// were corrected through (the figures are the corrected unit's).
std::string Analysed(const AllanArguments& args) {
  return args.calibration.empty() ? args.samples : args.samples + " corrected by " + args.calibration;
}

void PrintSummary(const AllanArguments& args, const AllanSettings& settings, const UniformSeries& series,
                  int64_t sample_count, const std::vector<ColumnAnalysis>& results) {
  std::printf("%s: %lld samples at %s s (%s s), %s, %zu taus, %.3g %% confidence\n", Analysed(args).c_str(),
              static_cast<long long>(sample_count), Number(series.sample_interval_s, 6).c_str(),
              Number(series.end_time_s - series.start_time_s - series.bridged_time_s, 6).c_str(),
              ToString(results.front().curve.estimator), results.front().curve.points.size(),
              100.0 * settings.options.confidence);
  if (series.gaps_bridged > 0) {
    std::printf("  bridged %lld gap(s) totalling %s s\n", static_cast<long long>(series.gaps_bridged),
                Number(series.bridged_time_s).c_str());
  }
  for (const ColumnAnalysis& r : results) {
    const NoiseFitSummary& fit = r.fit;
    std::printf("%s (%s, %s)", r.name.c_str(), ToString(r.kind), SiUnit(r.kind));
    if (!fit.fitted) {
      std::printf(": no noise fit: %s\n", fit.message.c_str());
      continue;
    }
    std::printf(": IEEE 952 fit to oadev, %d points, reduced chi-square %s\n", fit.points_used,
                Number(fit.reduced_chi_square, 3).c_str());
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseTermUnits& units = UnitsOf(r.kind, k);
      const bool engineer = *units.engineer_key != '\0';
      const double scale = engineer ? units.engineer_per_si : 1.0;
      const char* unit = engineer ? units.engineer_unit : units.si_unit;
      const NoiseTermFigure figure = TermFigure(fit, k, scale);
      if (figure.resolved) {
        std::printf("  %-26s %10s +- %-9s %-14s", units.label, Number(figure.value).c_str(),
                    Number(figure.sigma, 2).c_str(), unit);
      } else {  // its estimate, interval and the figure to quote (column_analysis.h)
        std::printf("  %-26s %s", units.label, TermFigureText(figure, unit).c_str());
      }
      double readout = std::nan("");
      std::string where;
      if (k == kRandomWalk) readout = fit.readout_random_walk, where = "-1/2 line at 1 s";
      if (k == kBiasInstability) {
        readout = fit.readout_bias_instability;
        where = "floor/0.664 at " + Number(fit.readout_bias_tau_s) + " s";
      }
      if (k == kRateRandomWalk) readout = fit.readout_rate_random_walk, where = "+1/2 line at 3 s";
      if (std::isfinite(readout))
        std::printf("  read-out %s (%s)", Number(readout * scale).c_str(), where.c_str());
      std::printf("\n");
    }
    if (r.kind != ColumnKind::kOther) {
      const bool gyro = r.kind == ColumnKind::kGyro;
      std::printf("  Kalibr: %s_noise_density %s %s/sqrt(Hz), %s_random_walk %s %s/sqrt(Hz)\n",
                  gyro ? "gyroscope" : "accelerometer", Number(TermFigure(fit, kRandomWalk).quoted()).c_str(),
                  gyro ? "rad/s" : "m/s^2", gyro ? "gyroscope" : "accelerometer",
                  Number(TermFigure(fit, kRateRandomWalk).quoted()).c_str(), gyro ? "rad/s^2" : "m/s^3");
    }
  }
}

AllanSettings ParseSettings(const AllanArguments& args) {
  AllanSettings settings;
  args.allan.Apply(&settings.options);
  args.noise_fit.Apply(&settings.fit_options);
  args.series.Apply(&settings.series_options);
  if (const std::string problem = ParseTauSpec(args.taus, &settings.tau_spec); !problem.empty()) {
    BadInvocation("--taus: " + problem);
  }
  if (args.kind != "auto" && args.kind != "gyro" && args.kind != "accel" && args.kind != "other") {
    BadInvocation("--kind " + QuoteForMessage(args.kind) + " is not one of: auto, gyro, accel, other");
  }
  for (const std::string& problem :
       {settings.options.Validate(), settings.fit_options.Validate(), settings.series_options.Validate()}) {
    if (!problem.empty()) BadInvocation(problem);
  }
  return settings;
}

// The outputs, checked before anything is read: never an input, never each other; then the time
// unit, the scale and the plot's units and format. False (having said why) when a plot is asked
// for and gnuplot is missing.
bool CheckOutputs(const AllanArguments& args, AllanSettings* settings) {
  std::vector<std::string> outputs = {args.output};
  if (!args.noise_yaml.empty()) outputs.push_back(args.noise_yaml);
  if (!args.plot.empty()) outputs.push_back(args.plot);
  for (size_t i = 0; i < outputs.size(); ++i) {
    RefuseToOverwriteInputs(outputs[i], {args.samples, args.calibration});
    for (size_t j = 0; j < i; ++j) {
      if (outputs[i] == outputs[j]) throw InputError(outputs[i], "named for two outputs");
    }
  }
  settings->seconds_per_unit = args.input.Get().seconds_per_time_unit;
  if (!(args.scale > 0.0) || !std::isfinite(args.scale)) BadInvocation("--scale must be a positive number");
  if (!ParseAllanPlotUnits(args.plot_units, &settings->plot_units)) {
    BadInvocation("--plot-units " + QuoteForMessage(args.plot_units) +
                  " is not one of: " + AllanPlotUnitsNames());
  }
  if (args.plot.empty()) return true;
  if (!HasSuffix(args.plot, ".svg") && !HasSuffix(args.plot, ".png")) {
    throw InputError(args.plot, "--plot must end in .svg or .png");
  }
  if (!GnuplotAvailable()) {
    std::fprintf(stderr,
                 "imufit: error: --plot needs gnuplot, which is not on PATH (Debian: apt-get install "
                 "gnuplot-nox); nothing was written\n");
    return false;
  }
  return true;
}

// The columns asked for, uniformly sampled, times in seconds: as they are, or corrected through
// the calibration (the samples imufit apply would write, without the file).
UniformSeries ReadSeries(const AllanArguments& args, const AllanSettings& settings) {
  const UniformSeriesOptions& series_options = settings.series_options;
  UniformSeries series;
  if (args.calibration.empty()) {
    series = ReadUniformSeries(args.samples, args.columns, series_options);
  } else {
    const Calibration calibration =
        ReadUnitCalibration(args.calibration, args.samples, args.allow_mismatch, args.allow_uncalibrated);
    CorrectFileReport correction;
    series = ReadCorrectedSeries(args.samples, calibration, args.input.Get().Format(), args.columns,
                                 series_options, &correction);
    WarnOutsideFitTempRange(calibration, correction);
    return series;  // SamplesReader has read the times in seconds
  }
  series.sample_interval_s *= settings.seconds_per_unit;
  series.start_time_s *= settings.seconds_per_unit;
  series.end_time_s *= settings.seconds_per_unit;
  series.bridged_time_s *= settings.seconds_per_unit;
  return series;
}

// Every column analysed, its samples moved out of `series` (memory is reused for the phase).
std::vector<ColumnAnalysis> AnalyseColumns(const AllanArguments& args, const AllanSettings& settings,
                                           UniformSeries* series) {
  const int64_t n = static_cast<int64_t>(series->columns[0].size());
  std::vector<int64_t> factors;
  if (const std::string problem = AveragingFactors(settings.tau_spec, settings.options.estimator, n,
                                                   series->sample_interval_s, &factors);
      !problem.empty()) {
    throw InputError(args.samples, problem);
  }
  std::vector<ColumnAnalysis> results;
  for (size_t c = 0; c < series->names.size(); ++c) {
    std::vector<double> rates = std::move(series->columns[c]);
    series->columns[c] = std::vector<double>();
    if (args.scale != 1.0) {
      for (double& rate : rates) rate /= args.scale;
    }
    results.push_back(AnalyseColumn(series->names[c], ColumnKindOf(series->names[c], args.kind),
                                    std::move(rates), series->sample_interval_s, factors, settings.options,
                                    settings.fit_options));
  }
  return results;
}

// A column's curve and noise terms as the files hold them (io/noise_file.h).
AllanCurveRecord CurveRecord(const ColumnAnalysis& analysis) {
  AllanCurveRecord curve;
  curve.column = analysis.name;
  curve.estimator = ToString(analysis.curve.estimator);
  for (const AllanPoint& point : analysis.curve.points) {
    curve.points.push_back(
        {point.tau_s, static_cast<long long>(point.terms), point.dev, point.dev_lo, point.dev_hi});
  }
  return curve;
}

NoiseColumnRecord NoiseColumn(const ColumnAnalysis& analysis) {
  const NoiseFitSummary& fit = analysis.fit;
  NoiseColumnRecord column;
  column.name = analysis.name;
  column.kind = analysis.kind;
  column.fitted = fit.fitted;
  column.reason = fit.message;
  column.points_used = fit.points_used;
  column.reduced_chi_square = fit.reduced_chi_square;
  column.value = fit.value;
  column.sigma = fit.sigma;
  for (int k = 0; k < kNoiseTerms; ++k) column.resolved[k] = IsResolved(fit, k);
  // The read-outs in the units the file writes them (io/noise_file.h).
  const auto written = [&](int term, double si) { return si * UnitsOf(analysis.kind, term).engineer_per_si; };
  column.readout_random_walk = written(kRandomWalk, fit.readout_random_walk);
  column.readout_bias_instability = written(kBiasInstability, fit.readout_bias_instability);
  column.readout_bias_tau_s = fit.readout_bias_tau_s;
  column.readout_rate_random_walk = written(kRateRandomWalk, fit.readout_rate_random_walk);
  return column;
}

// The curves, the noise YAML and the plot: together, or none.
void WriteOutputs(const AllanArguments& args, const AllanSettings& settings, const UniformSeries& series,
                  int64_t sample_count, const std::vector<ColumnAnalysis>& results) {
  OutputTransaction written;
  std::vector<AllanCurveRecord> curves;
  for (const ColumnAnalysis& analysis : results) curves.push_back(CurveRecord(analysis));
  WriteAllanCsv(args.output, curves, &written);
  if (!args.noise_yaml.empty()) {
    NoiseRecord record;
    record.software = SoftwareVersion();
    record.samples = args.samples;
    if (!args.calibration.empty()) {
      record.calibration = args.calibration;
      record.calibration_sha256 = Sha256OfFile(args.calibration);
    }
    record.sample_interval_s = series.sample_interval_s;
    record.sample_count = sample_count;
    record.duration_s = series.end_time_s - series.start_time_s - series.bridged_time_s;
    for (const ColumnAnalysis& analysis : results) record.columns.push_back(NoiseColumn(analysis));
    WriteNoiseYaml(args.noise_yaml, record, &written);
  }
  if (!args.plot.empty()) {
    char title[512];
    std::snprintf(title, sizeof title, "%s: %s, tau0 = %g s, %lld samples, %.3g %% confidence",
                  Analysed(args).c_str(), ToString(results.front().curve.estimator), series.sample_interval_s,
                  static_cast<long long>(sample_count), 100.0 * settings.options.confidence);
    DrawFile(AllanPlot(results, title, settings.plot_units), args.plot, &written);
  }
  written.Commit();
}

int RunAllan(const AllanArguments& args) {
  AllanSettings settings = ParseSettings(args);
  if (!CheckOutputs(args, &settings)) return kExitNotDone;
  UniformSeries series = ReadSeries(args, settings);
  const int64_t n = static_cast<int64_t>(series.columns[0].size());
  const std::vector<ColumnAnalysis> results = AnalyseColumns(args, settings, &series);
  PlausibilityWarnings(args, series, results);
  WriteOutputs(args, settings, series, n, results);
  if (!args.quiet) PrintSummary(args, settings, series, n, results);
  return 0;
}

}  // namespace

CommandRunner AddAllanCommand(CliCommand command) {
  auto args = std::make_shared<AllanArguments>();
  command.Option("--samples,-s", &args->samples, "samples CSV (or .csv.gz) with time_s and the columns")
      .Required();
  command
      .Option("--columns,-c", &args->columns,
              "columns to analyse, comma-separated (default: every gyro_* and accel_* column)")
      .Delimiter(',');
  command.Option("--output,-o", &args->output, "Allan deviation CSV to write (.gz compresses)").Required();
  args->allan.AddOne(command, AllanOptionTable(), "estimator");
  command.Option("--taus,-t", &args->taus,
                 "octave (default: tau0 * 1, 2, 4, ...), decade (1, 2, 4, 10, 20, 40, ...), all, "
                 "per-decade:K (K log-spaced taus per decade), or taus in seconds: 1,10,100");
  args->allan.Add(command, AllanOptionTable(), {"estimator", "threads"});
  command.Option("--kind", &args->kind,
                 "auto (default: gyro_* are gyros in rad/s, accel_* accelerometers in m/s^2), gyro, accel, "
                 "or other (no engineer units)");
  args->series.Add(command, UniformSeriesOptionTable());
  args->noise_fit.Add(command, NoiseFitOptionTable());
  command.Option("--noise-yaml", &args->noise_yaml, "write the noise terms as YAML (top-level key noise:)");
  command.Option("--plot", &args->plot, "draw the curves, fits and read-outs with gnuplot (.svg or .png)");
  command.Option("--plot-units", &args->plot_units,
                 "unit of the plot's gyro panels: native (default: the columns' own, rad/s for a "
                 "corrected file), rad/s, deg/s or deg/h (then accelerometer panels in micro-g)");
  CliOption scale = command.Option(
      "--scale", &args->scale,
      "divide every column by this (raw per SI unit, e.g. 939.65 for 16.4 LSB per deg/s) when the "
      "columns are raw counts (default 1)");
  CliOption calibration =
      command
          .Option("--calibration", &args->calibration,
                  "the unit's calibration YAML: correct the raw samples through it first, as imufit apply "
                  "does (then the columns are among gyro_*, accel_* and temp_c)")
          .Excludes(scale);
  AddTempOption(command, &args->input);
  AddAllowMismatchFlag(command, &args->allow_mismatch);
  AddAllowUncalibratedFlag(command, &args->allow_uncalibrated);
  args->input.TempOption().Needs(calibration);  // a temperature only matters to the correction
  args->allan.AddOne(command, AllanOptionTable(), "threads");
  command.Flag("--quiet,-q", &args->quiet, "print nothing but warnings and errors");
  return [args] { return RunAllan(*args); };
}

}  // namespace imufit
