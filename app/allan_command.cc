// imufit allan — Allan deviation (and relatives) of columns of a samples file, their confidence
// intervals, the IEEE 952 noise terms, a noise YAML file and a plot (docs/spec.md section 4, issue 4).
//
// Units: the columns are taken as SI rates (a corrected samples file: gyro rad/s, accel m/s^2).
// Engineer units are converted here, once, on output:
//   gyro   ARW deg/sqrt(h) = N * (180/pi) * 60          (N in rad/sqrt(s), sqrt(h) = 60 sqrt(s))
//          bias instability deg/h = B * (180/pi) * 3600
//          RRW deg/h/sqrt(h) = K * (180/pi) * 3600 * 60
//   accel  VRW m/s/sqrt(h) = N * 60
//          bias instability micro-g = B / 9.80665 m/s^2 * 1e6
//          acceleration random walk m/s/h/sqrt(h) = K * 3600 * 60
// Kalibr's imu.yaml continuous-time densities are N (noise density, rad/s/sqrt(Hz) = rad/sqrt(s))
// and K (random walk, rad/s^2/sqrt(Hz)) as they are.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "commands.h"
#include "imufit/io/path.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/series_reader.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/noise_model.h"

namespace imufit {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kSecondsPerHour = 3600.0;
constexpr double kSqrtSecondsPerSqrtHour = 60.0;
constexpr double kStandardGravityMps2 = 9.80665;
constexpr double kMicro = 1e6;
// A term is reported as resolved when its variance coefficient (Q^2, N^2, ...) exceeds this many of
// its standard uncertainties (on the coefficient itself: its square root is not Gaussian near 0).
constexpr double kResolvedSigmas = 2.0;

enum class ColumnKind { kGyro, kAccel, kOther };

// How one noise term of one kind of column is named and scaled on output.
struct TermUnits {
  const char* si_key;        // YAML key of the SI value
  const char* si_unit;
  const char* engineer_key;  // YAML key in engineer units ("" = none)
  const char* engineer_unit;
  double engineer_per_si;
  const char* label;         // for people
};

const TermUnits& UnitsOf(ColumnKind kind, int term) {
  static const TermUnits kGyro[kNoiseTerms] = {
      {"quantization_rad", "rad", "", "", 1.0, "quantization"},
      {"random_walk_rad_per_sqrt_s", "rad/sqrt(s)", "arw_deg_per_sqrt_hr", "deg/sqrt(h)",
       kDegPerRad * kSqrtSecondsPerSqrtHour, "angle random walk"},
      {"bias_instability_radps", "rad/s", "bias_instability_deg_per_hr", "deg/h", kDegPerRad * kSecondsPerHour,
       "bias instability"},
      {"rate_random_walk_radps_per_sqrt_s", "rad/s/sqrt(s)", "rrw_deg_per_hr_per_sqrt_hr", "deg/h/sqrt(h)",
       kDegPerRad * kSecondsPerHour * kSqrtSecondsPerSqrtHour, "rate random walk"},
      {"rate_ramp_radps_per_s", "rad/s^2", "rate_ramp_deg_per_hr_per_hr", "deg/h/h",
       kDegPerRad * kSecondsPerHour * kSecondsPerHour, "rate ramp"}};
  static const TermUnits kAccel[kNoiseTerms] = {
      {"quantization_mps", "m/s", "", "", 1.0, "quantization"},
      {"random_walk_mps_per_sqrt_s", "m/s/sqrt(s)", "vrw_mps_per_sqrt_hr", "m/s/sqrt(h)", kSqrtSecondsPerSqrtHour,
       "velocity random walk"},
      {"bias_instability_mps2", "m/s^2", "bias_instability_ug", "micro-g", kMicro / kStandardGravityMps2,
       "bias instability"},
      {"rate_random_walk_mps2_per_sqrt_s", "m/s^2/sqrt(s)", "acceleration_random_walk_mps_per_hr_per_sqrt_hr",
       "m/s/h/sqrt(h)", kSecondsPerHour * kSqrtSecondsPerSqrtHour, "acceleration random walk"},
      {"rate_ramp_mps3", "m/s^3", "rate_ramp_ug_per_hr", "micro-g/h", kMicro / kStandardGravityMps2 * kSecondsPerHour,
       "acceleration ramp"}};
  static const TermUnits kOther[kNoiseTerms] = {
      {"quantization_y_s", "unit*s", "", "", 1.0, "quantization"},
      {"random_walk_y_sqrt_s", "unit*sqrt(s)", "", "", 1.0, "random walk (white)"},
      {"bias_instability_y", "unit", "", "", 1.0, "bias instability (flicker)"},
      {"rate_random_walk_y_per_sqrt_s", "unit/sqrt(s)", "", "", 1.0, "rate random walk"},
      {"rate_ramp_y_per_s", "unit/s", "", "", 1.0, "ramp"}};
  switch (kind) {
    case ColumnKind::kGyro: return kGyro[term];
    case ColumnKind::kAccel: return kAccel[term];
    case ColumnKind::kOther: break;
  }
  return kOther[term];
}

const char* KindName(ColumnKind kind) {
  switch (kind) {
    case ColumnKind::kGyro: return "gyro";
    case ColumnKind::kAccel: return "accel";
    case ColumnKind::kOther: break;
  }
  return "other";
}

const char* KindUnit(ColumnKind kind) {
  switch (kind) {
    case ColumnKind::kGyro: return "rad/s";
    case ColumnKind::kAccel: return "m/s^2";
    case ColumnKind::kOther: break;
  }
  return "unit";
}

struct AllanArguments {
  std::string samples;
  std::vector<std::string> columns;
  std::string output;
  std::string estimator = "oadev";
  std::string taus = "octave";
  std::string edf_noise = "auto";
  std::string kind = "auto";
  std::string gaps = "error";
  std::string noise_yaml;
  std::string plot;
  double confidence = 0.683;
  double time_tolerance = 0.1;
  double min_clusters = 8.0;
  int threads = 0;
  bool quiet = false;
};

// One analysed column: its curve (the chosen estimator) and the noise fit (on the Allan variance).
struct ColumnResult {
  std::string name;
  ColumnKind kind = ColumnKind::kOther;
  AllanResult curve;
  AllanResult allan;  // the overlapping Allan deviation the fit used (== curve for oadev)
  NoiseFitSummary fit;
};

[[noreturn]] void BadInvocation(const std::string& message) { throw InputError("imufit allan", message); }

std::string FindOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return "";
  std::stringstream folders(path);
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) continue;
    const std::string candidate = folder + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

std::string Number(double value, int digits = 4) {
  if (!std::isfinite(value)) return "n/a";
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

// YAML scalar: shortest round-trip text, .nan / .inf as YAML spells them.
std::string YamlNumber(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  return FormatDouble(value);
}

std::string YamlString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

// ---------------------------------------------------------------- outputs

void WriteCsv(const std::string& path, const std::vector<ColumnResult>& results) {
  OutputFile file(path);
  file.Write("column,estimator,tau_s,terms,dev,dev_lo,dev_hi\n");
  for (const ColumnResult& result : results) {
    for (const AllanPoint& point : result.curve.points) {
      file.Write(result.name);
      file.Write(",");
      file.Write(ToString(result.curve.estimator));
      file.Write(",");
      file.WriteNumber(point.tau_s);
      file.Write("," + std::to_string(point.terms) + ",");
      file.WriteNumber(point.dev);
      file.Write(",");
      file.WriteNumber(point.dev_lo);
      file.Write(",");
      file.WriteNumber(point.dev_hi);
      file.Write("\n");
    }
  }
  file.Commit();
}

// The largest fitted value of `term` over the columns of `kind` (Kalibr takes one number for all
// three axes: the worst one is the safe choice), or nan when there is none.
double WorstAxis(const std::vector<ColumnResult>& results, ColumnKind kind, int term) {
  double worst = std::nan("");
  for (const ColumnResult& result : results) {
    if (result.kind != kind || !result.fit.fitted) continue;
    if (!(worst >= result.fit.value[term])) worst = result.fit.value[term];
  }
  return worst;
}

void WriteNoiseYaml(const std::string& path, const AllanArguments& args, const UniformSeries& series,
                    int64_t sample_count, const std::vector<ColumnResult>& results) {
  std::ostringstream yaml;
  yaml << "# Noise figures by imufit allan: the IEEE Std 952 model fitted to the overlapping Allan\n"
       << "# variance. Every figure is [value, 1-sigma uncertainty]. Merge into a calibration by\n"
       << "# appending this file: its only top-level key is `noise`.\n"
       << "noise:\n"
       << "  format: imufit-noise\n"
       << "  version: 1\n"
       << "  software: " << YamlString(SoftwareVersion()) << "\n"
       << "  samples: " << YamlString(args.samples) << "\n"
       << "  sample_interval_s: " << YamlNumber(series.sample_interval_s) << "\n"
       << "  sample_count: " << sample_count << "\n"
       << "  duration_s: " << YamlNumber(series.end_time_s - series.start_time_s - series.bridged_time_s) << "\n"
       << "  model: \"sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2\"\n"
       << "  columns:\n";
  for (const ColumnResult& result : results) {
    const NoiseFitSummary& fit = result.fit;
    yaml << "    " << result.name << ":\n"
         << "      kind: " << KindName(result.kind) << "\n"
         << "      unit: " << YamlString(KindUnit(result.kind)) << "\n"
         << "      fitted: " << (fit.fitted ? "true" : "false") << "\n";
    if (!fit.fitted) {
      yaml << "      reason: " << YamlString(fit.message) << "\n";
      continue;
    }
    yaml << "      points_used: " << fit.points_used << "\n"
         << "      reduced_chi_square: " << YamlNumber(fit.reduced_chi_square) << "\n";
    for (int k = 0; k < kNoiseTerms; ++k) {
      const TermUnits& units = UnitsOf(result.kind, k);
      yaml << "      " << units.si_key << ": [" << YamlNumber(fit.value[k]) << ", " << YamlNumber(fit.sigma[k])
           << "]\n";
    }
    for (int k = 0; k < kNoiseTerms; ++k) {
      const TermUnits& units = UnitsOf(result.kind, k);
      if (*units.engineer_key == '\0') continue;
      yaml << "      " << units.engineer_key << ": [" << YamlNumber(fit.value[k] * units.engineer_per_si) << ", "
           << YamlNumber(fit.sigma[k] * units.engineer_per_si) << "]\n";
    }
    const TermUnits& n = UnitsOf(result.kind, kRandomWalk);
    const TermUnits& b = UnitsOf(result.kind, kBiasInstability);
    const TermUnits& k = UnitsOf(result.kind, kRateRandomWalk);
    const bool engineer = *n.engineer_key != '\0';
    yaml << "      readout:  # IEEE 952 graphical read-outs of the measured curve\n"
         << "        " << (engineer ? n.engineer_key : n.si_key) << ": "
         << YamlNumber(fit.readout_random_walk * n.engineer_per_si) << "\n"
         << "        " << (engineer ? b.engineer_key : b.si_key) << ": "
         << YamlNumber(fit.readout_bias_instability * b.engineer_per_si) << "\n"
         << "        bias_instability_tau_s: " << YamlNumber(fit.readout_bias_tau_s) << "\n"
         << "        " << (engineer ? k.engineer_key : k.si_key) << ": "
         << YamlNumber(fit.readout_rate_random_walk * k.engineer_per_si) << "\n";
  }
  const bool has_gyro = std::any_of(results.begin(), results.end(),
                                    [](const ColumnResult& r) { return r.kind == ColumnKind::kGyro && r.fit.fitted; });
  const bool has_accel = std::any_of(results.begin(), results.end(),
                                     [](const ColumnResult& r) { return r.kind == ColumnKind::kAccel && r.fit.fitted; });
  if (has_gyro || has_accel) {
    yaml << "  kalibr:  # imu.yaml continuous-time values, the worst axis of each sensor\n";
    if (has_gyro) {
      yaml << "    gyroscope_noise_density: " << YamlNumber(WorstAxis(results, ColumnKind::kGyro, kRandomWalk))
           << "  # rad/s/sqrt(Hz)\n"
           << "    gyroscope_random_walk: " << YamlNumber(WorstAxis(results, ColumnKind::kGyro, kRateRandomWalk))
           << "  # rad/s^2/sqrt(Hz)\n";
    }
    if (has_accel) {
      yaml << "    accelerometer_noise_density: "
           << YamlNumber(WorstAxis(results, ColumnKind::kAccel, kRandomWalk)) << "  # m/s^2/sqrt(Hz)\n"
           << "    accelerometer_random_walk: "
           << YamlNumber(WorstAxis(results, ColumnKind::kAccel, kRateRandomWalk)) << "  # m/s^3/sqrt(Hz)\n";
    }
    yaml << "    update_rate: " << YamlNumber(1.0 / series.sample_interval_s) << "  # Hz\n";
  }
  WriteFileAtomically(path, yaml.str());
}

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string GnuplotString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

// Writes the gnuplot script: one panel per kind of column (they have different units), in each a
// curve with confidence bars per column, its fitted model (solid), the model's terms (dashed) and
// the read-out points (open circles).
std::string PlotScript(const std::string& output, const std::string& title, const AllanArguments& args,
                       const std::vector<ColumnResult>& results) {
  static const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2",
                                  "#17becf"};
  constexpr int kModelPoints = 160;
  std::ostringstream gp;
  gp.precision(10);
  const bool png = HasSuffix(args.plot, ".png");
  std::vector<ColumnKind> kinds;
  for (const ColumnResult& r : results) {
    if (std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) kinds.push_back(r.kind);
  }
  const int width = kinds.size() > 1 ? 1600 : 1100;
  if (png) {
    gp << "set terminal pngcairo size " << width << ",760 font 'DejaVu Sans,11' background rgb 'white'\n";
  } else {
    gp << "set terminal svg size " << width << ",760 dynamic font 'DejaVu Sans,11' background rgb 'white'\n";
  }
  gp << "set output " << GnuplotString(output) << "\n";
  // Data blocks: curve (tau dev lo hi), model (tau total Q N B K R), read-outs (tau dev).
  for (size_t c = 0; c < results.size(); ++c) {
    const ColumnResult& r = results[c];
    gp << "$curve" << c << " << EOD\n";
    for (const AllanPoint& p : r.curve.points) {
      const double lo = std::isfinite(p.dev_lo) ? p.dev_lo : p.dev;
      const double hi = std::isfinite(p.dev_hi) ? p.dev_hi : p.dev;
      gp << p.tau_s << " " << p.dev << " " << lo << " " << hi << "\n";
    }
    gp << "EOD\n";
    if (!r.fit.fitted || r.curve.points.empty()) continue;
    gp << "$model" << c << " << EOD\n";
    const double first = r.curve.points.front().tau_s;
    const double last = r.curve.points.back().tau_s;
    for (int i = 0; i <= kModelPoints; ++i) {
      const double tau = first * std::pow(last / first, static_cast<double>(i) / kModelPoints);
      gp << tau << " " << r.fit.ModelDeviation(tau);
      for (int k = 0; k < kNoiseTerms; ++k) gp << " " << r.fit.TermDeviation(k, tau);
      gp << "\n";
    }
    gp << "EOD\n$readout" << c << " << EOD\n";
    if (std::isfinite(r.fit.readout_random_walk)) gp << "1 " << r.fit.readout_random_walk << "\n";
    if (std::isfinite(r.fit.readout_bias_instability)) {
      gp << r.fit.readout_bias_tau_s << " " << 0.664 * r.fit.readout_bias_instability << "\n";
    }
    if (std::isfinite(r.fit.readout_rate_random_walk)) gp << "3 " << r.fit.readout_rate_random_walk << "\n";
    gp << "EOD\n";
  }
  gp << "set multiplot layout 1," << kinds.size() << " title " << GnuplotString(title) << " noenhanced\n";
  for (ColumnKind kind : kinds) {
    double y_min = INFINITY;
    double y_max = 0.0;
    for (const ColumnResult& r : results) {
      if (r.kind != kind) continue;
      for (const AllanPoint& p : r.curve.points) {
        if (!(p.dev > 0.0)) continue;  // a constant column has nothing to show on a log scale
        y_min = std::min(y_min, std::isfinite(p.dev_lo) ? p.dev_lo : p.dev);
        y_max = std::max(y_max, std::isfinite(p.dev_hi) ? p.dev_hi : p.dev);
      }
    }
    gp << "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
       << "set grid xtics ytics mxtics mytics lc rgb '#e0e0e0'\n"
       << "set key top right opaque box noenhanced\n"
       << "set xlabel 'averaging time {/Symbol t} (s)'\n"
       << "set ylabel " << GnuplotString(std::string(ToString(results.front().curve.estimator)) + " (" +
                                         (results.front().curve.estimator == AllanEstimator::kTdev
                                              ? std::string(KindUnit(kind)) + " s"
                                              : std::string(KindUnit(kind))) +
                                         ")")
       << "\n";
    if (y_max > 0.0 && y_min > 0.0) gp << "set yrange [" << y_min / 3.0 << ":" << y_max * 3.0 << "]\n";
    const std::vector<AllanPoint>& taus = results.front().curve.points;
    gp << "set xrange [" << taus.front().tau_s / 1.5 << ":" << taus.back().tau_s * 1.5 << "]\n";
    gp << "plot ";
    bool first_item = true;
    auto item = [&](const std::string& text) {
      gp << (first_item ? "" : ", \\\n     ") << text;
      first_item = false;
    };
    // The IEEE 952 model is the Allan variance's: drawn over Allan-variance curves only.
    const AllanEstimator estimator = results.front().curve.estimator;
    const bool draw_model = estimator == AllanEstimator::kOadev || estimator == AllanEstimator::kAdev ||
                            estimator == AllanEstimator::kTotdev;
    bool any_fit = false;
    for (size_t c = 0; c < results.size(); ++c) {
      const ColumnResult& r = results[c];
      if (r.kind != kind) continue;
      const std::string color = std::string("lc rgb '") + kColors[c % 8] + "'";
      item("$curve" + std::to_string(c) + " using 1:2:3:4 with yerrorbars " + color + " pt 7 ps 0.7 title " +
           GnuplotString(r.name));
      if (!r.fit.fitted || !draw_model) continue;
      any_fit = true;
      item("$model" + std::to_string(c) + " using 1:2 with lines " + color + " lw 2 title " +
           GnuplotString(r.name + " model"));
      for (int k = 0; k < kNoiseTerms; ++k) {
        if (!(r.fit.variance[k] > 0.0)) continue;
        item("$model" + std::to_string(c) + " using 1:" + std::to_string(k + 3) + " with lines " + color +
             " dt 2 lw 1 notitle");
      }
      item("$readout" + std::to_string(c) + " using 1:2 with points " + color + " pt 6 ps 2.2 lw 2 notitle");
    }
    if (any_fit) {
      item("NaN with lines lc rgb 'black' dt 2 title 'model terms (Q, N, B, K, R)'");
      item("NaN with points lc rgb 'black' pt 6 ps 2.2 lw 2 title 'read-outs: N at 1 s, 0.664 B, K at 3 s'");
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

void WritePlot(const std::string& gnuplot, const AllanArguments& args, const UniformSeries& series,
               int64_t sample_count, const std::vector<ColumnResult>& results) {
  namespace fs = std::filesystem;
  OutputFile image_file(args.plot);  // gnuplot draws into its temporary file
  const std::string& image = image_file.temp_path();
  std::string script = (fs::temp_directory_path() / "imufit-allan-XXXXXX").string();
  const int script_fd = ::mkstemp(script.data());
  if (script_fd < 0) throw std::runtime_error("cannot create a temporary gnuplot script");
  ::close(script_fd);
  const std::string errors = script + ".err";
  char title[512];
  std::snprintf(title, sizeof title, "%s: %s, tau0 = %g s, %lld samples, %.3g %% confidence", args.samples.c_str(),
                ToString(results.front().curve.estimator), series.sample_interval_s,
                static_cast<long long>(sample_count), 100.0 * args.confidence);
  std::ofstream(script) << PlotScript(image, title, args, results);
  const std::string command = ShellQuote(gnuplot) + " " + ShellQuote(script) + " 2> " + ShellQuote(errors);
  const int status = std::system(command.c_str());
  std::ifstream error_stream(errors);
  std::string message((std::istreambuf_iterator<char>(error_stream)), std::istreambuf_iterator<char>());
  ::unlink(script.c_str());
  ::unlink(errors.c_str());
  std::error_code ec;
  if (status != 0 || fs::file_size(image, ec) == 0) {
    throw std::runtime_error("gnuplot could not draw " + args.plot + ": " + message.substr(0, 600));
  }
  image_file.Commit();
}

void PrintSummary(const AllanArguments& args, const UniformSeries& series, int64_t sample_count,
                  const std::vector<ColumnResult>& results) {
  std::printf("%s: %lld samples at %s s (%s s), %s, %zu taus, %.3g %% confidence\n", args.samples.c_str(),
              static_cast<long long>(sample_count),
              Number(series.sample_interval_s, 6).c_str(),
              Number(series.end_time_s - series.start_time_s - series.bridged_time_s, 6).c_str(),
              ToString(results.front().curve.estimator), results.front().curve.points.size(), 100.0 * args.confidence);
  if (series.gaps_bridged > 0) {
    std::printf("  bridged %lld gap(s) totalling %s s\n", static_cast<long long>(series.gaps_bridged),
                Number(series.bridged_time_s).c_str());
  }
  for (const ColumnResult& r : results) {
    const NoiseFitSummary& fit = r.fit;
    std::printf("%s (%s, %s)", r.name.c_str(), KindName(r.kind), KindUnit(r.kind));
    if (!fit.fitted) {
      std::printf(": no noise fit: %s\n", fit.message.c_str());
      continue;
    }
    std::printf(": IEEE 952 fit to oadev, %d points, reduced chi-square %s\n", fit.points_used,
                Number(fit.reduced_chi_square, 3).c_str());
    for (int k = 0; k < kNoiseTerms; ++k) {
      const TermUnits& units = UnitsOf(r.kind, k);
      const bool engineer = *units.engineer_key != '\0';
      const double scale = engineer ? units.engineer_per_si : 1.0;
      const char* unit = engineer ? units.engineer_unit : units.si_unit;
      const bool resolved = fit.variance[k] > kResolvedSigmas * fit.variance_sigma[k];
      std::printf("  %-26s %10s +- %-9s %-14s", units.label, Number(fit.value[k] * scale).c_str(),
                  Number(fit.sigma[k] * scale, 2).c_str(), unit);
      if (!resolved) std::printf(" (not resolved)");
      double readout = std::nan("");
      std::string where;
      if (k == kRandomWalk) readout = fit.readout_random_walk, where = "-1/2 line at 1 s";
      if (k == kBiasInstability) {
        readout = fit.readout_bias_instability;
        where = "floor/0.664 at " + Number(fit.readout_bias_tau_s) + " s";
      }
      if (k == kRateRandomWalk) readout = fit.readout_rate_random_walk, where = "+1/2 line at 3 s";
      if (std::isfinite(readout)) std::printf("  read-out %s (%s)", Number(readout * scale).c_str(), where.c_str());
      std::printf("\n");
    }
    if (r.kind != ColumnKind::kOther) {
      const bool gyro = r.kind == ColumnKind::kGyro;
      std::printf("  Kalibr: %s_noise_density %s %s/sqrt(Hz), %s_random_walk %s %s/sqrt(Hz)\n",
                  gyro ? "gyroscope" : "accelerometer", Number(fit.value[kRandomWalk]).c_str(),
                  gyro ? "rad/s" : "m/s^2", gyro ? "gyroscope" : "accelerometer",
                  Number(fit.value[kRateRandomWalk]).c_str(), gyro ? "rad/s^2" : "m/s^3");
    }
  }
}

int RunAllan(const AllanArguments& args) {
  AllanOptions options;
  if (!ParseAllanEstimator(args.estimator, &options.estimator)) {
    BadInvocation("--estimator " + QuoteForMessage(args.estimator) + " is not one of: " + AllanEstimatorNames());
  }
  if (!ParseEdfNoise(args.edf_noise, &options.edf_noise)) {
    BadInvocation("--edf-noise " + QuoteForMessage(args.edf_noise) + " is not one of: " + EdfNoiseNames());
  }
  TauSpec tau_spec;
  if (const std::string problem = ParseTauSpec(args.taus, &tau_spec); !problem.empty()) {
    BadInvocation("--taus: " + problem);
  }
  if (args.kind != "auto" && args.kind != "gyro" && args.kind != "accel" && args.kind != "other") {
    BadInvocation("--kind " + QuoteForMessage(args.kind) + " is not one of: auto, gyro, accel, other");
  }
  if (args.gaps != "error" && args.gaps != "bridge") {
    BadInvocation("--gaps " + QuoteForMessage(args.gaps) + " is not one of: error, bridge");
  }
  options.confidence = args.confidence;
  options.threads = args.threads;
  if (const std::string problem = options.Validate(); !problem.empty()) BadInvocation(problem);
  NoiseFitOptions fit_options;
  fit_options.min_clusters = args.min_clusters;
  if (const std::string problem = fit_options.Validate(); !problem.empty()) BadInvocation(problem);

  // Outputs: never an input, never each other; a plot needs gnuplot — all checked before reading.
  std::vector<std::string> outputs = {args.output};
  if (!args.noise_yaml.empty()) outputs.push_back(args.noise_yaml);
  if (!args.plot.empty()) outputs.push_back(args.plot);
  for (size_t i = 0; i < outputs.size(); ++i) {
    RefuseToOverwriteInputs(outputs[i], {args.samples});
    for (size_t j = 0; j < i; ++j) {
      if (outputs[i] == outputs[j]) throw InputError(outputs[i], "named for two outputs");
    }
  }
  std::string gnuplot;
  if (!args.plot.empty()) {
    if (!HasSuffix(args.plot, ".svg") && !HasSuffix(args.plot, ".png")) {
      throw InputError(args.plot, "--plot must end in .svg or .png");
    }
    gnuplot = FindOnPath("gnuplot");
    if (gnuplot.empty()) {
      std::fprintf(stderr,
                   "imufit: error: --plot needs gnuplot, which is not on PATH (Debian: apt-get install "
                   "gnuplot-nox); nothing was written\n");
      return 1;
    }
  }

  UniformSeriesOptions series_options;
  series_options.time_tolerance = args.time_tolerance;
  series_options.bridge_gaps = args.gaps == "bridge";
  UniformSeries series = ReadUniformSeries(args.samples, args.columns, series_options);
  const int64_t n = static_cast<int64_t>(series.columns[0].size());
  std::vector<int64_t> factors;
  if (const std::string problem =
          AveragingFactors(tau_spec, options.estimator, n, series.sample_interval_s, &factors);
      !problem.empty()) {
    throw InputError(args.samples, problem);
  }

  std::vector<ColumnResult> results;
  for (size_t c = 0; c < series.names.size(); ++c) {
    ColumnResult result;
    result.name = series.names[c];
    if (args.kind == "gyro" || (args.kind == "auto" && result.name.rfind("gyro", 0) == 0)) {
      result.kind = ColumnKind::kGyro;
    } else if (args.kind == "accel" || (args.kind == "auto" && result.name.rfind("accel", 0) == 0)) {
      result.kind = ColumnKind::kAccel;
    }
    // The rates become the phase in place; the column's memory goes with it after this column.
    std::vector<double> phase = std::move(series.columns[c]);
    series.columns[c] = std::vector<double>();
    const double mean = RatesToPhase(&phase, options.threads);
    result.curve = ComputeAllan(phase, series.sample_interval_s, factors, options);
    result.curve.mean = mean;
    // The IEEE 952 model is the Allan variance's; fit it to the overlapping Allan deviation.
    if (options.estimator == AllanEstimator::kOadev) {
      result.allan = result.curve;
    } else {
      AllanOptions allan_options = options;
      allan_options.estimator = AllanEstimator::kOadev;
      result.allan = ComputeAllan(phase, series.sample_interval_s, factors, allan_options);
    }
    result.fit = FitNoiseModel(result.allan.points, n, fit_options);
    results.push_back(std::move(result));
  }

  OutputTransaction written;  // the curves, the noise YAML and the plot together, or none
  WriteCsv(args.output, results);
  if (!args.noise_yaml.empty()) WriteNoiseYaml(args.noise_yaml, args, series, n, results);
  if (!args.plot.empty()) WritePlot(gnuplot, args, series, n, results);
  written.Commit();
  if (!args.quiet) PrintSummary(args, series, n, results);
  return 0;
}

}  // namespace

CommandRunner AddAllanCommand(CLI::App* root) {
  auto args = std::make_shared<AllanArguments>();
  CLI::App* command = root->add_subcommand(
      "allan",
      "Allan deviation of columns of a samples file, with confidence intervals, the IEEE 952 noise terms "
      "(quantization, random walk, bias instability, rate random walk, ramp) and Kalibr noise densities. "
      "Columns are rates in SI units (a corrected file: gyro rad/s, accel m/s^2). Writes "
      "column,estimator,tau_s,terms,dev,dev_lo,dev_hi.");
  command->add_option("--samples,-s", args->samples, "samples CSV (or .csv.gz) with time_s and the columns")
      ->required();
  command->add_option("--columns,-c", args->columns, "columns to analyse, comma-separated (default: every gyro_* and accel_* column)")
      ->delimiter(',');
  command->add_option("--output,-o", args->output, "Allan deviation CSV to write (.gz compresses)")->required();
  command->add_option("--estimator,-e", args->estimator, "adev, oadev (default), mdev, tdev, hdev, ohdev or totdev");
  command->add_option("--taus,-t", args->taus,
                      "octave (default: tau0 * 1, 2, 4, ...), decade (1, 2, 4, 10, 20, 40, ...), all, "
                      "per-decade:K (K log-spaced taus per decade), or taus in seconds: 1,10,100");
  command->add_option("--confidence", args->confidence, "two-sided confidence of dev_lo..dev_hi (default 0.683)");
  command->add_option("--edf-noise", args->edf_noise,
                      "noise type for the confidence intervals' degrees of freedom: auto (default, lag-1 "
                      "autocorrelation per tau), wpm, fpm, wfm, ffm, rwfm");
  command->add_option("--kind", args->kind,
                      "auto (default: gyro_* are gyros in rad/s, accel_* accelerometers in m/s^2), gyro, accel, "
                      "or other (no engineer units)");
  command->add_option("--time-tolerance", args->time_tolerance,
                      "largest deviation of a time step from the sample interval, in intervals (default 0.1)");
  command->add_option("--gaps", args->gaps, "error (default): a gap in time_s is an error; bridge: join the data across gaps");
  command->add_option("--min-clusters", args->min_clusters,
                      "the noise fit leaves out taus with fewer than this many intervals in the record (default 8)");
  command->add_option("--noise-yaml", args->noise_yaml, "write the noise terms as YAML (top-level key noise:)");
  command->add_option("--plot", args->plot, "draw the curves, fits and read-outs with gnuplot (.svg or .png)");
  command->add_option("--threads", args->threads, "worker threads (default 0: all cores)");
  command->add_flag("--quiet,-q", args->quiet, "print nothing but warnings and errors");
  return [args] { return RunAllan(*args); };
}

}  // namespace imufit
