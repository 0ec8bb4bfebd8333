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
  std::string gyro_unit;   // --gyro-unit: the gyro columns' unit ("" = SI)
  std::string accel_unit;  // --accel-unit
  double vio_inflation = 1.0;
  double record_precision = 0.25;  // --record-precision: "how long to record" resolves to this
  std::string calibration;         // correct the raw samples through it first (as imufit apply does)
  SamplesInputArguments input;     // --temp-c, for a raw log without temp_c; --time-unit
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

// The units a column may be given in (--gyro-unit, --accel-unit), SI per unit: one table for the
// parser, the help and the conversion.
struct InputUnit {
  const char* name;
  ColumnKind kind;
  double si_per_unit;
};
constexpr InputUnit kInputUnits[] = {
    {"rad/s", ColumnKind::kGyro, 1.0},
    {"deg/s", ColumnKind::kGyro, kDegToRad},
    {"deg/h", ColumnKind::kGyro, kDegToRad / 3600.0},
    {"mrad/s", ColumnKind::kGyro, 1e-3},
    {"m/s^2", ColumnKind::kAccel, 1.0},
    {"g", ColumnKind::kAccel, kStandardGravityMps2},
    {"mg", ColumnKind::kAccel, 1e-3 * kStandardGravityMps2},
    {"ug", ColumnKind::kAccel, 1e-6 * kStandardGravityMps2},
};

std::string InputUnitNames(ColumnKind kind) {
  std::string names;
  for (const InputUnit& unit : kInputUnits) {
    if (unit.kind == kind) names += (names.empty() ? "" : ", ") + std::string(unit.name);
  }
  return names;
}

// SI per unit of `name` for columns of `kind` (1 for ""); a name not in the table is a bad invocation.
double SiPerUnit(const std::string& name, ColumnKind kind, const char* option) {
  if (name.empty()) return 1.0;
  for (const InputUnit& unit : kInputUnits) {
    if (unit.kind == kind && name == unit.name) return unit.si_per_unit;
  }
  BadInvocation(std::string(option) + " " + QuoteForMessage(name) +
                " is not one of: " + InputUnitNames(kind));
}

// At rest the accelerometer's mean vector has the norm of gravity; this far from it (relative) it
// is not in m/s^2: about 1 means g, about 1000 mg.
constexpr double kAccelNormTolerance = 0.2;

// The norm of the accelerometer columns' means when there are three of them (a vector), else nan.
double AccelNorm(const std::vector<ColumnAnalysis>& results) {
  double sum = 0.0;
  int count = 0;
  for (const ColumnAnalysis& r : results) {
    if (r.kind != ColumnKind::kAccel) continue;
    sum += r.curve.mean * r.curve.mean;
    ++count;
  }
  return count == 3 ? std::sqrt(sum) : std::nan("");
}

void AccelNormWarning(const AllanArguments& args, const std::vector<ColumnAnalysis>& results) {
  const double norm = AccelNorm(results);
  if (!std::isfinite(norm) || std::abs(norm / kStandardGravityMps2 - 1.0) <= kAccelNormTolerance) return;
  // A log in g usually has its gyros in deg/s.
  const std::string gyro_too = args.gyro_unit.empty() && args.calibration.empty()
                                   ? " (and its gyros probably in deg/s: --gyro-unit deg/s)"
                                   : "";
  std::string guess = "are the columns raw counts, or not the accelerometer's?";
  if (std::abs(norm - 1.0) <= kAccelNormTolerance) guess = "it looks like g: give --accel-unit g" + gyro_too;
  if (std::abs(norm / 1000.0 - 1.0) <= kAccelNormTolerance)
    guess = "it looks like mg: give --accel-unit mg" + gyro_too;
  std::fprintf(
      stderr,
      "imufit: warning: %s: the accelerometer's mean vector has a norm of %s m/s^2 where a unit at rest "
      "reads gravity, 9.81 m/s^2: %s; every figure below is in the wrong unit otherwise\n",
      args.samples.c_str(), Number(norm).c_str(), guess.c_str());
}

void PlausibilityWarnings(const AllanArguments& args, const UniformSeries& series,
                          const std::vector<ColumnAnalysis>& results) {
  AccelNormWarning(args, results);
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

// "0.08 to 20.5 s", "655.4 s", or "" when unknown.
std::string TauRange(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return "";
  return lo == hi ? Number(lo) + " s" : Number(lo) + " to " + Number(hi) + " s";
}

// The misfit said out loud, on stderr (the summary says it again at the column).
void MisfitWarnings(const AllanArguments& args, const std::vector<ColumnAnalysis>& results) {
  for (const ColumnAnalysis& r : results) {
    if (!r.fit.fitted || r.fit.describes_curve) continue;
    std::fprintf(
        stderr,
        "imufit: warning: %s: %s: the IEEE 952 model does not describe the curve (reduced chi-square %s > "
        "%s): its fitted terms are not figures of this sensor; quote the read-outs (docs/allan.md, "
        "\"Which figure to quote\")\n",
        args.samples.c_str(), r.name.c_str(), Number(r.fit.reduced_chi_square, 3).c_str(),
        Number(kMisfitReducedChiSquare).c_str());
  }
}

// The read-out beside term k, in the unit `scale` times SI ("" when the curve has none).
std::string ReadoutText(const NoiseFitSummary& fit, int k, double scale) {
  if (k == kRandomWalk && std::isfinite(fit.readout_random_walk)) {
    return "read-out " + Number(fit.readout_random_walk * scale) + " +- " +
           Number(fit.readout_random_walk_sigma * scale, 2) + " (-1/2 line, " +
           TauRange(fit.readout_random_walk_tau_min_s, fit.readout_random_walk_tau_max_s) + ")";
  }
  if (k == kBiasInstability && std::isfinite(fit.readout_bias_instability)) {
    return "read-out " + Number(fit.readout_bias_instability * scale) + " (minimum / 0.664 at " +
           Number(fit.readout_bias_tau_s) + " s, " + Number(fit.readout_bias_lower * scale, 3) + " to " +
           Number(fit.readout_bias_upper * scale, 3) + " at 2 sigma, " +
           (fit.readout_bias_resolved ? "a resolved minimum)" : "not a resolved minimum: a bound)");
  }
  if (k == kRateRandomWalk && std::isfinite(fit.readout_rate_random_walk)) {
    return "read-out " + Number(fit.readout_rate_random_walk * scale) + " +- " +
           Number(fit.readout_rate_random_walk_sigma * scale, 2) + " (+1/2 line, " +
           TauRange(fit.readout_rate_random_walk_tau_min_s, fit.readout_rate_random_walk_tau_max_s) + ")";
  }
  return "";
}

// A quoted figure in words: "2.42 +- 0.034 deg/sqrt(h)" or "at most 57 deg/h".
std::string QuoteText(const QuotedFigure& quote, const char* unit) {
  if (quote.bound()) return "at most " + Number(quote.value, 3) + " " + unit;
  if (std::isfinite(quote.sigma)) return Number(quote.value) + " +- " + Number(quote.sigma, 2) + " " + unit;
  return Number(quote.value) + " " + unit + " (" + Number(quote.lower, 3) + " to " + Number(quote.upper, 3) +
         " at 2 sigma)";
}

// A duration for people: "40 min", "5.2 h", "3.1 days".
std::string Duration(double seconds) {
  if (!std::isfinite(seconds)) return "n/a";
  if (seconds < 120.0) return Number(seconds, 2) + " s";
  if (seconds < 7200.0) return Number(seconds / 60.0, 2) + " min";
  if (seconds < 3.0 * 86400.0) return Number(seconds / 3600.0, 2) + " h";
  return Number(seconds / 86400.0, 2) + " days";
}

void PrintColumn(const AllanArguments& args, const ColumnAnalysis& r, double duration_s, double tau0_s,
                 double min_clusters) {
  const NoiseFitSummary& fit = r.fit;
  std::printf("%s (%s, %s)", r.name.c_str(), ToString(r.kind), SiUnit(r.kind));
  if (!fit.fitted) {
    std::printf(": no noise fit: %s\n", fit.message.c_str());
    return;
  }
  std::printf(": IEEE 952 fit to oadev, %d points (%s), reduced chi-square %s\n", fit.points_used,
              TauRange(fit.fit_tau_min_s, fit.fit_tau_max_s).c_str(),
              Number(fit.reduced_chi_square, 3).c_str());
  if (!fit.describes_curve) {
    std::printf(
        "  MISFIT: the model does not describe this curve (reduced chi-square above %s): the fitted terms "
        "below are not figures of this sensor; quote the read-outs\n",
        Number(kMisfitReducedChiSquare).c_str());
  }
  if (fit.filter_detected) {
    std::printf(
        "  output filter: consecutive samples correlate (lag-1 %s): %d short tau(s) bent below the -1/2 line "
        "%s; the fit models the filter's 1/tau^2 deficit\n",
        Number(fit.sample_lag1, 2).c_str(), fit.filtered_points,
        std::isfinite(fit.filtered_below_tau_s)
            ? ("left out (below " + Number(fit.filtered_below_tau_s) + " s)").c_str()
            : "left out");
  }
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
    if (k == kQuantization && fit.filter_variance < 0.0) std::printf(" (masked by the output filter)");
    const std::string taus = TauRange(fit.term_tau_min_s[k], fit.term_tau_max_s[k]);
    if (!taus.empty()) std::printf("  fitted on %s", taus.c_str());
    const std::string readout = ReadoutText(fit, k, scale);
    if (!readout.empty()) std::printf("  %s", readout.c_str());
    std::printf("\n");
  }
  if (std::isfinite(fit.skipped_tau_s)) {
    std::printf(
        "  left out of the fit and the read-outs: tau %s s (%s intervals in the record, fewer than "
        "--min-clusters %s)\n",
        Number(fit.skipped_tau_s).c_str(), Number(fit.skipped_clusters, 3).c_str(),
        Number(min_clusters).c_str());
  }
  if (r.kind == ColumnKind::kOther) return;
  std::array<QuotedFigure, kNoiseTerms> quotes;
  for (int k : {kRandomWalk, kBiasInstability, kRateRandomWalk}) {
    quotes[k] = QuoteTerm(fit, k);
    if (!quotes[k].found()) continue;
    const NoiseTermUnits& units = UnitsOf(r.kind, k);
    std::printf("  quote %-20s %s  from %s\n", units.label,
                QuoteText(Scaled(quotes[k], units.engineer_per_si), units.engineer_unit).c_str(),
                QuoteSourceText(quotes[k]).c_str());
  }
  // How long to record, from the figures quoted (a bound stands in for its term: a smaller term
  // needs longer).
  const auto figure = [&](int k) { return quotes[k].found() ? quotes[k].value : 0.0; };
  const RecordLength length =
      RecordLengthFor(figure(kRandomWalk), figure(kBiasInstability), figure(kRateRandomWalk), tau0_s,
                      args.record_precision, min_clusters);
  std::printf("  record for +-%s %% (2 sigma): bias instability %s%s, %s %s%s (this log: %s)\n",
              Number(100.0 * args.record_precision).c_str(), Duration(length.bias_instability_s).c_str(),
              quotes[kBiasInstability].bound() ? " or more (its figure is a bound)" : "",
              UnitsOf(r.kind, kRateRandomWalk).label, Duration(length.rate_random_walk_s).c_str(),
              quotes[kRateRandomWalk].bound() ? " or more (its figure is a bound)" : "",
              Duration(duration_s).c_str());
}

// The estimators' blocks to paste (the noise YAML has them too, with where each figure comes from).
void PrintEstimatorBlocks(const NoiseRecord& record) {
  const KalibrNoiseRecord k = KalibrNoiseOf(record);
  if (!std::isfinite(k.gyroscope_noise_density) && !std::isfinite(k.accelerometer_noise_density)) return;
  std::printf("noise blocks (worst axis of each sensor's quoted figures, x %s%s; advised: %s):\n",
              Number(k.inflation).c_str(), k.inflation == 1.0 ? " as measured" : "", kAdvisedVioInflation);
  const auto line = [](const char* key, double value, const std::string& from) {
    if (std::isfinite(value))
      std::printf("  %-28s %-12s # %s\n", (std::string(key) + ":").c_str(), Number(value).c_str(),
                  from.c_str());
  };
  std::printf(" Kalibr imu.yaml, OpenVINS kalibr_imu_chain.yaml (imu0):\n");
  line("accelerometer_noise_density", k.accelerometer_noise_density, k.accelerometer_noise_density_from);
  line("accelerometer_random_walk", k.accelerometer_random_walk, k.accelerometer_random_walk_from);
  line("gyroscope_noise_density", k.gyroscope_noise_density, k.gyroscope_noise_density_from);
  line("gyroscope_random_walk", k.gyroscope_random_walk, k.gyroscope_random_walk_from);
  line("update_rate", k.update_rate, "Hz");
  std::printf(" VINS-Mono / VINS-Fusion config:\n");
  line("acc_n", k.accelerometer_noise_density, "m/s^2/sqrt(Hz)");
  line("gyr_n", k.gyroscope_noise_density, "rad/s/sqrt(Hz)");
  line("acc_w", k.accelerometer_random_walk, "m/s^3/sqrt(Hz)");
  line("gyr_w", k.gyroscope_random_walk, "rad/s^2/sqrt(Hz)");
}

void PrintSummary(const AllanArguments& args, const AllanSettings& settings, const UniformSeries& series,
                  int64_t sample_count, const std::vector<ColumnAnalysis>& results,
                  const NoiseRecord& record) {
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
    PrintColumn(args, r, record.duration_s, series.sample_interval_s, settings.fit_options.min_clusters);
  }
  PrintEstimatorBlocks(record);
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
  SiPerUnit(args.gyro_unit, ColumnKind::kGyro, "--gyro-unit");  // checked before anything is read
  SiPerUnit(args.accel_unit, ColumnKind::kAccel, "--accel-unit");
  if (!(args.vio_inflation >= 1.0) || !std::isfinite(args.vio_inflation)) {
    BadInvocation("--vio-inflation must be a number of at least 1 (1: the figures as measured)");
  }
  if (!(args.record_precision > 0.0 && args.record_precision < 1.0)) {
    BadInvocation(
        "--record-precision must lie in (0, 1): the relative 2-sigma interval to resolve each term to");
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
    const ColumnKind kind = ColumnKindOf(series->names[c], args.kind);
    if (args.scale != 1.0) {
      for (double& rate : rates) rate /= args.scale;
    }
    const double si_per_unit = kind == ColumnKind::kGyro    ? SiPerUnit(args.gyro_unit, kind, "--gyro-unit")
                               : kind == ColumnKind::kAccel ? SiPerUnit(args.accel_unit, kind, "--accel-unit")
                                                            : 1.0;
    if (si_per_unit != 1.0) {
      for (double& rate : rates) rate *= si_per_unit;
    }
    results.push_back(AnalyseColumn(series->names[c], kind, std::move(rates), series->sample_interval_s,
                                    factors, settings.options, settings.fit_options));
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
  column.readout_random_walk_taus_s = {fit.readout_random_walk_tau_min_s, fit.readout_random_walk_tau_max_s};
  column.readout_rate_random_walk_taus_s = {fit.readout_rate_random_walk_tau_min_s,
                                            fit.readout_rate_random_walk_tau_max_s};
  column.readout_bias_interval = {written(kBiasInstability, fit.readout_bias_lower),
                                  written(kBiasInstability, fit.readout_bias_upper)};
  column.readout_bias_resolved = fit.readout_bias_resolved;
  column.skipped_tau_s = fit.skipped_tau_s;
  column.describes_curve = fit.describes_curve;
  column.fit_taus_s = {fit.fit_tau_min_s, fit.fit_tau_max_s};
  for (int k = 0; k < kNoiseTerms; ++k)
    column.term_taus_s[k] = {fit.term_tau_min_s[k], fit.term_tau_max_s[k]};
  column.filter_detected = fit.filter_detected;
  column.sample_lag1 = fit.sample_lag1;
  column.filtered_below_tau_s = fit.filtered_below_tau_s;
  for (int k : {kRandomWalk, kBiasInstability, kRateRandomWalk}) {
    const NoiseTermUnits& units = UnitsOf(analysis.kind, k);  // the file's units (io/noise_file.h)
    const QuotedFigure quote =
        Scaled(QuoteTerm(fit, k), *units.engineer_key != '\0' ? units.engineer_per_si : 1.0);
    if (!quote.found()) continue;
    NoiseColumnRecord::Quote& q = column.quote[k];
    q.value = quote.value;
    q.at_most = quote.bound();
    if (!q.at_most) {
      q.sigma = quote.sigma;
      q.interval = {quote.lower, quote.upper};
    }
    q.from = QuoteSourceText(quote);
  }
  return column;
}

// The curves, the noise YAML and the plot: together, or none.
NoiseRecord MakeNoiseRecord(const AllanArguments& args, const UniformSeries& series, int64_t sample_count,
                            const std::vector<ColumnAnalysis>& results) {
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
  record.vio_inflation = args.vio_inflation;
  for (const ColumnAnalysis& analysis : results) record.columns.push_back(NoiseColumn(analysis));
  return record;
}

void WriteOutputs(const AllanArguments& args, const AllanSettings& settings, const UniformSeries& series,
                  int64_t sample_count, const std::vector<ColumnAnalysis>& results,
                  const NoiseRecord& record) {
  OutputTransaction written;
  std::vector<AllanCurveRecord> curves;
  for (const ColumnAnalysis& analysis : results) curves.push_back(CurveRecord(analysis));
  WriteAllanCsv(args.output, curves, &written);
  if (!args.noise_yaml.empty()) WriteNoiseYaml(args.noise_yaml, record, &written);
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
  MisfitWarnings(args, results);
  const NoiseRecord record = MakeNoiseRecord(args, series, n, results);
  WriteOutputs(args, settings, series, n, results, record);
  if (!args.quiet) PrintSummary(args, settings, series, n, results, record);
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
  const CliOption gyro_unit =
      command.Option("--gyro-unit", &args->gyro_unit,
                     "unit of the gyro columns: " + InputUnitNames(ColumnKind::kGyro) + " (default rad/s)");
  const CliOption accel_unit = command.Option(
      "--accel-unit", &args->accel_unit,
      "unit of the accelerometer columns: " + InputUnitNames(ColumnKind::kAccel) + " (default m/s^2)");
  command.Option(
      "--vio-inflation", &args->vio_inflation,
      "multiply the figures of the Kalibr, OpenVINS and VINS-Mono blocks by this (default 1: as measured; "
      "the factor is written beside them)");
  command.Option(
      "--record-precision", &args->record_precision,
      "how long to record: the relative 2-sigma interval each term is to be resolved to (default 0.25)");
  CliOption calibration =
      command
          .Option("--calibration", &args->calibration,
                  "the unit's calibration YAML: correct the raw samples through it first, as imufit apply "
                  "does (then the columns are among gyro_*, accel_* and temp_c)")
          .Excludes(scale)
          .Excludes(gyro_unit)
          .Excludes(accel_unit);
  AddTempOption(command, &args->input);
  AddAllowMismatchFlag(command, &args->allow_mismatch);
  AddAllowUncalibratedFlag(command, &args->allow_uncalibrated);
  args->input.TempOption().Needs(calibration);  // a temperature only matters to the correction
  args->allan.AddOne(command, AllanOptionTable(), "threads");
  command.Flag("--quiet,-q", &args->quiet, "print nothing but warnings and errors");
  return [args] { return RunAllan(*args); };
}

}  // namespace imufit
