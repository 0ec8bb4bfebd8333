#include "imufit/factory/report.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/noise_model.h"

extern char** environ;

namespace imufit {
namespace {

namespace fs = std::filesystem;

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr int kCurvePoints = 61;  // temperatures at which the coefficient curves are drawn
// The Allan section needs a static stretch of at least this long (else it says why not).
constexpr double kMinAllanStretchS = 60.0;
constexpr int kNoiseTermRandomWalk = 1;       // N, rad/s * sqrt(s)  (noise_model.h: Q, N, B, K, R)
constexpr int kNoiseTermBiasInstability = 2;  // B, rad/s
const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f"};

std::string Fmt(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string ReadText(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

// A coefficient's cubic and its 1-sigma band (terms taken as independent: the band is indicative).
struct Cubic {
  const double* c;
  const double* s;  // may be null
  double At(double dt) const { return c[0] + dt * (c[1] + dt * (c[2] + dt * c[3])); }
  double SigmaAt(double dt, int first_term) const {
    if (s == nullptr) return 0.0;
    double variance = 0.0, power = 1.0;
    for (int k = 0; k < kPolynomialTerms; ++k, power *= dt) {
      if (k >= first_term) variance += (s[k] * power) * (s[k] * power);
    }
    return std::sqrt(variance);
  }
};

Cubic Coefficient(const Calibration& cal, bool gyro, int index) {
  const double* p = gyro ? cal.model.gyro.data() : cal.model.accel.data();
  const double* s = cal.sigma ? (gyro ? cal.sigma->gyro.data() : cal.sigma->accel.data()) : nullptr;
  return {p + index * kPolynomialTerms, s ? s + index * kPolynomialTerms : nullptr};
}

// One group of coefficients against temperature, in familiar units.
struct CurveGroup {
  std::string title;
  std::string unit;
  std::vector<std::string> names;
  std::vector<std::vector<std::array<double, 3>>> curves;  // per name: (T, value, sigma)
};

std::vector<CurveGroup> CoefficientCurves(const Calibration& cal) {
  const double lo = cal.fit_temp_range_c[0], hi = cal.fit_temp_range_c[1];
  std::vector<double> temps;
  for (int i = 0; i < kCurvePoints; ++i) temps.push_back(lo + (hi - lo) * i / (kCurvePoints - 1));
  std::vector<CurveGroup> groups;
  const auto group = [&](std::string title, std::string unit, bool gyro, int first, int count, auto value) {
    CurveGroup g{std::move(title), std::move(unit), {}, {}};
    for (int i = 0; i < count; ++i) {
      g.names.push_back(kCoefficientNames[first + i].axis);
      std::vector<std::array<double, 3>> curve;
      for (double t : temps) {
        double v = 0.0, s = 0.0;
        value(Coefficient(cal, gyro, first + i), i, t - 25.0, &v, &s);
        curve.push_back({t, v, s});
      }
      g.curves.push_back(std::move(curve));
    }
    groups.push_back(std::move(g));
  };
  const auto scale_at = [&](bool gyro, int axis, double dt) {
    return Coefficient(cal, gyro, kScaleCoefficient + axis).At(dt);
  };
  group("Gyro bias", "deg/s", true, kBiasCoefficient, 3,
        [&](const Cubic& c, int i, double dt, double* v, double* s) {
          const double k = kRadToDeg / scale_at(true, i, dt);
          *v = c.At(dt) * k;
          *s = c.SigmaAt(dt, 0) * std::abs(k);
        });
  group("Gyro scale factor change from 25 degC", "ppm", true, kScaleCoefficient, 3,
        [&](const Cubic& c, int, double dt, double* v, double* s) {
          *v = (c.At(dt) / c.c[0] - 1.0) * 1e6;
          *s = c.SigmaAt(dt, 1) / std::abs(c.c[0]) * 1e6;
        });
  group("Gyro misalignment", "mrad", true, kMisalignmentCoefficient, 6,
        [&](const Cubic& c, int, double dt, double* v, double* s) {
          *v = c.At(dt) * 1e3;
          *s = c.SigmaAt(dt, 0) * 1e3;
        });
  group("Gyro g-sensitivity", "deg/s/g", true, kGSensitivityCoefficient, 9,
        [&](const Cubic& c, int i, double dt, double* v, double* s) {
          const double k = kRadToDeg * kStandardGravityMps2 / scale_at(true, i / 3, dt);
          *v = c.At(dt) * k;
          *s = c.SigmaAt(dt, 0) * std::abs(k);
        });
  group("Accelerometer bias", "mg", false, kBiasCoefficient, 3,
        [&](const Cubic& c, int i, double dt, double* v, double* s) {
          const double k = 1e3 / (scale_at(false, i, dt) * kStandardGravityMps2);
          *v = c.At(dt) * k;
          *s = c.SigmaAt(dt, 0) * std::abs(k);
        });
  group("Accelerometer scale factor change from 25 degC", "ppm", false, kScaleCoefficient, 3,
        [&](const Cubic& c, int, double dt, double* v, double* s) {
          *v = (c.At(dt) / c.c[0] - 1.0) * 1e6;
          *s = c.SigmaAt(dt, 1) / std::abs(c.c[0]) * 1e6;
        });
  group("Accelerometer misalignment", "mrad", false, kMisalignmentCoefficient, 6,
        [&](const Cubic& c, int, double dt, double* v, double* s) {
          *v = c.At(dt) * 1e3;
          *s = c.SigmaAt(dt, 0) * 1e3;
        });
  return groups;
}

std::string GnuplotQuote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return quoted + "\"";
}

const char* kTerminal =
    "set terminal svg size 760,330 dynamic noenhanced font 'DejaVu Sans,11' background rgb 'white'\n";

std::string CurvesScript(const CurveGroup& g, int output) {
  std::ostringstream gp;
  gp.precision(10);
  for (size_t n = 0; n < g.curves.size(); ++n) {
    gp << "$c" << n << " << EOD\n";
    for (const auto& p : g.curves[n])
      gp << p[0] << " " << p[1] << " " << p[1] - p[2] << " " << p[1] + p[2] << "\n";
    gp << "EOD\n";
  }
  gp << kTerminal << "set output '@OUT" << output << "@'\n";
  gp << "set title " << GnuplotQuote(g.title + " (" + g.unit + "), 1-sigma band") << "\n";
  gp << "set xlabel 'temperature, degC'\nset ylabel " << GnuplotQuote(g.unit) << "\n";
  gp << "set grid\nset key outside right top\nset style fill transparent solid 0.18 noborder\n";
  gp << "plot ";
  for (size_t n = 0; n < g.curves.size(); ++n) {
    const std::string color = std::string("lc rgb '") + kColors[n % 9] + "'";
    gp << (n ? ", " : "") << "$c" << n << " using 1:3:4 with filledcurves " << color << " notitle, $c" << n
       << " using 1:2 with lines lw 2 " << color << " title " << GnuplotQuote(g.names[n]);
  }
  gp << "\nunset output\nreset\n";
  return gp.str();
}

std::string ResidualScript(const std::vector<WindowError>& errors, const Plan& plan, bool gyro, int output) {
  std::ostringstream gp;
  gp.precision(10);
  for (int kind = 0; kind < 2; ++kind) {
    gp << "$r" << kind << " << EOD\n";
    for (const WindowError& e : errors) {
      const TableSegment* segment = plan.Find(e.segment);
      if ((segment && segment->IsStatic()) != (kind == 0)) continue;
      gp << e.temp_c << " "
         << (gyro ? e.gyro_radps.norm() * kRadToDeg : e.accel_mps2.norm() / kStandardGravityMps2 * 1e3)
         << "\n";
    }
    gp << "0 NaN\nEOD\n";
  }
  gp << kTerminal << "set output '@OUT" << output << "@'\n";
  gp << "set title "
     << GnuplotQuote(std::string(gyro ? "Gyro" : "Accelerometer") +
                     " error after correction, per window (|corrected - true|)")
     << "\n";
  gp << "set xlabel 'temperature, degC'\nset ylabel " << GnuplotQuote(gyro ? "deg/s" : "mg") << "\n";
  gp << "set grid\nset key outside right top\n";
  gp << "plot $r0 using 1:2 with points pt 7 ps 0.5 lc rgb '#1f77b4' title 'static positions', "
        "$r1 using 1:2 with points pt 9 ps 0.6 lc rgb '#d62728' title 'rate segments'\n";
  gp << "unset output\nreset\n";
  return gp.str();
}

const char* kStyle = R"css(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; font-size: 13px; color: #111; margin: 24px auto; max-width: 980px; }
h1 { font-size: 22px; margin: 0 0 4px 0; } h2 { font-size: 16px; border-bottom: 1px solid #999; margin-top: 22px; }
table { border-collapse: collapse; margin: 6px 0; } td, th { border: 1px solid #bbb; padding: 2px 7px; text-align: left; }
th { background: #eee; } td.num { text-align: right; font-variant-numeric: tabular-nums; font-family: "DejaVu Sans Mono", monospace; }
.hash { font-family: "DejaVu Sans Mono", monospace; font-size: 11px; word-break: break-all; }
.PASS { color: #06642a; font-weight: bold; } .FAIL { color: #b00; font-weight: bold; }
.badge { display: inline-block; padding: 4px 14px; font-size: 18px; border: 2px solid; border-radius: 4px; }
.plot svg { width: 100%; height: auto; } .plot { page-break-inside: avoid; break-inside: avoid; }
.note { color: #555; font-size: 12px; }
@media print { body { margin: 0; max-width: none; } h2 { page-break-after: avoid; } table { page-break-inside: avoid; } }
)css";

std::string Row(std::initializer_list<std::string> cells, const char* tag = "td") {
  std::string row = "<tr>";
  for (const std::string& c : cells) row += std::string("<") + tag + ">" + c + "</" + tag + ">";
  return row + "</tr>\n";
}

std::string Num(const std::string& text) { return "<td class=\"num\">" + text + "</td>"; }

std::string Plots(const std::vector<std::string>& svgs, const std::string& failure) {
  std::string html;
  for (const std::string& svg : svgs) html += "<div class=\"plot\">" + svg + "</div>\n";
  if (!failure.empty()) html += "<p class=\"note\">Plots not drawn: " + HtmlEscape(failure) + "</p>\n";
  return html;
}

std::string VerdictHtml(const Verdict& verdict) {
  std::string html =
      "<table><tr><th>criterion</th><th>measured</th><th>limit</th><th>margin</th><th>verdict</th></tr>\n";
  for (const CriterionResult& c : verdict.criteria) {
    html += "<tr data-criterion=\"" + HtmlEscape(c.name) + "\" data-pass=\"" + (c.pass ? "1" : "0") +
            "\"><td>" + HtmlEscape(c.name) + "</td>" + Num(HtmlEscape(c.measured_text)) +
            Num(HtmlEscape(c.limit_text)) + Num(Fmt("%.4g", c.margin) + " " + HtmlEscape(c.unit)) +
            "<td class=\"" + (c.pass ? "PASS" : "FAIL") + "\">" + (c.pass ? "PASS" : "FAIL") + "</td></tr>\n";
  }
  return html + "</table>\n";
}

// The Allan deviation of the gyro over the longest static stretch of the run (raw counts over the
// 25 degC scale factor: rad/s), with the IEEE 952 fit's ARW and bias instability.
std::string AllanSection(const UnitReport& r, const std::string& samples_path) {
  std::string html = "<h2>Gyro noise (Allan deviation, longest static stretch)</h2>\n";
  SamplesReader reader(samples_path, true);
  std::vector<Sample> best, current;
  Sample sample;
  const auto close_stretch = [&] {
    if (current.size() > best.size()) best.swap(current);
    current.clear();
  };
  while (reader.Next(&sample)) {
    const TableSegment* segment = r.plan.Find(sample.segment);
    if (segment == nullptr || !segment->IsStatic() ||
        (!current.empty() && current.back().segment != sample.segment)) {
      close_stretch();
    }
    if (segment != nullptr && segment->IsStatic()) current.push_back(sample);
  }
  close_stretch();
  const double duration_s = best.size() > 1 ? best.back().time_s - best.front().time_s : 0.0;
  if (duration_s < kMinAllanStretchS) {
    return html + "<p class=\"note\">Not drawn: the longest static stretch is " + Fmt("%.1f", duration_s) +
           " s; at least " + Fmt("%.0f", kMinAllanStretchS) +
           " s are needed (imufit allan on a long static log).</p>\n";
  }
  const double tau0_s = duration_s / (best.size() - 1);
  std::vector<int64_t> factors;
  AveragingFactors(TauSpec(), AllanEstimator::kOadev, static_cast<int64_t>(best.size()), tau0_s, &factors);
  AllanOptions options;
  options.threads = 1;
  std::ostringstream gp;
  gp.precision(10);
  std::string table =
      "<table><tr><th>axis</th><th>ARW, deg/&radic;h</th><th>bias instability, "
      "deg/h</th><th>points</th></tr>\n";
  const char* axes = "xyz";
  for (int axis = 0; axis < 3; ++axis) {
    const double scale = Coefficient(r.calibration, true, kScaleCoefficient + axis).c[0];
    std::vector<double> rates;
    for (const Sample& s : best) rates.push_back(s.gyro(axis) / scale);
    const AllanResult allan = ComputeAllanFromRates(std::move(rates), tau0_s, factors, options);
    const NoiseFitSummary fit = FitNoiseModel(allan.points, allan.n_samples);
    gp << "$a" << axis << " << EOD\n";
    for (const AllanPoint& p : allan.points) gp << p.tau_s << " " << p.dev * kRadToDeg * 3600.0 << "\n";
    gp << "EOD\n";
    const std::string name = std::string("gyro_") + axes[axis];
    if (fit.fitted) {
      const double arw = fit.value[kNoiseTermRandomWalk] * kRadToDeg * 60.0;
      const double arw_sigma = fit.sigma[kNoiseTermRandomWalk] * kRadToDeg * 60.0;
      const double bi = fit.value[kNoiseTermBiasInstability] * kRadToDeg * 3600.0;
      const double bi_sigma = fit.sigma[kNoiseTermBiasInstability] * kRadToDeg * 3600.0;
      table += "<tr><td>" + name + "</td><td class=\"num\" data-figure=\"gyro_arw_deg_per_sqrt_hr." +
               axes[axis] + "\" data-value=\"" + FormatDouble(arw) + "\">" + Fmt("%.4g", arw) + " &plusmn; " +
               Fmt("%.2g", arw_sigma) + "</td>" +
               Num(Fmt("%.4g", bi) + " &plusmn; " + Fmt("%.2g", bi_sigma)) +
               Num(std::to_string(fit.points_used)) + "</tr>\n";
    } else {
      table += "<tr><td>" + name + "</td><td colspan=\"3\">not fitted: " + HtmlEscape(fit.message) +
               "</td></tr>\n";
    }
  }
  table += "</table>\n";
  gp << kTerminal
     << "set output '@OUT0@'\nset logscale xy\nset format y '%g'\nset grid xtics ytics mxtics mytics\n"
     << "set title "
     << GnuplotQuote("Gyro overlapping Allan deviation, segment " + std::to_string(best.front().segment) +
                     Fmt(", %.0f s", duration_s) + Fmt(" at %.1f degC", best.front().temp_c))
     << "\nset xlabel 'tau, s'\nset ylabel 'deg/h'\nset key outside right top\nplot ";
  for (int axis = 0; axis < 3; ++axis) {
    gp << (axis ? ", " : "") << "$a" << axis << " using 1:2 with linespoints pt 7 ps 0.6 lw 2 lc rgb '"
       << kColors[axis] << "' title '" << axes[axis] << "'";
  }
  gp << "\nunset output\nreset\n";
  try {
    html += Plots(RunGnuplotSvg(gp.str(), 1), "");
  } catch (const std::exception& e) {
    html += Plots({}, e.what());
  }
  return html + table;
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::vector<std::string> RunGnuplotSvg(const std::string& script, int outputs) {
  std::string folder = (fs::temp_directory_path() / "imufit-plot-XXXXXX").string();
  if (::mkdtemp(folder.data()) == nullptr)
    throw std::runtime_error("cannot create a temporary folder for gnuplot");
  std::string text = script;
  for (int i = 0; i < outputs; ++i) {
    const std::string mark = "@OUT" + std::to_string(i) + "@";
    const std::string file = folder + "/" + std::to_string(i) + ".svg";
    for (size_t at; (at = text.find(mark)) != std::string::npos;) text.replace(at, mark.size(), file);
  }
  const std::string script_path = folder + "/plot.gp", errors_path = folder + "/errors.txt";
  std::ofstream(script_path) << text;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, errors_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::string program = "gnuplot", script_argument = script_path;
  std::vector<char*> argv = {program.data(), script_argument.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = -1;
  if (spawned == 0) waitpid(pid, &status, 0);
  std::vector<std::string> svgs;
  for (int i = 0; i < outputs; ++i) {
    std::string svg = ReadText(folder + "/" + std::to_string(i) + ".svg");
    const size_t start = svg.find("<svg");  // drop the XML prolog and doctype: inline SVG in HTML
    svgs.push_back(start == std::string::npos ? "" : svg.substr(start));
  }
  const std::string errors = ReadText(errors_path);
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  if (spawned != 0) throw std::runtime_error("gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)");
  for (const std::string& svg : svgs) {
    if (svg.empty() || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      throw std::runtime_error("gnuplot failed: " + errors.substr(0, 400));
    }
  }
  return svgs;
}

UnitReport MakeUnitReport(const Calibration& calibration, const Plan& plan, RunWindows run,
                          const std::vector<ReportInput>& inputs, const std::optional<Verdict>& verdict) {
  UnitReport report;
  report.created_utc = UtcNow();
  report.git_revision = IMUFIT_GIT_REVISION;
  report.software = calibration.software;
  for (ReportInput input : inputs) {
    if (input.path.empty()) continue;
    if (input.sha256.empty()) input.sha256 = Sha256OfFile(input.path);
    report.inputs.push_back(input);
  }
  report.calibration = calibration;
  report.plan = plan;
  report.run = std::move(run);
  report.verdict = verdict;
  return report;
}

UnitReport MakeUnitReport(const UnitOutcome& unit, const std::string& limits_path) {
  const FitRunResult& fit = *unit.fit;
  UnitReport report =
      MakeUnitReport(*fit.calibration, fit.plan, fit.run,
                     {{"plan", unit.plan_path, unit.plan_sha256},
                      {"samples", unit.samples_path, unit.samples_sha256},
                      {"limits", limits_path, ""}},
                     unit.verdict.empty() ? std::nullopt : std::optional<Verdict>(unit.verdict_detail));
  report.calibration.serial = unit.serial;
  report.unit = unit.unit;
  report.folds = fit.folds;
  return report;
}

std::string UnitReportHtml(const UnitReport& r) {
  const Calibration& cal = r.calibration;
  const std::string serial = cal.serial.empty() ? "(no serial)" : cal.serial;
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>Calibration certificate "
       << HtmlEscape(serial) << "</title>\n<style>" << kStyle << "</style></head><body>\n";
  html << "<h1>IMU calibration certificate &mdash; <span data-key=\"serial\">" << HtmlEscape(serial)
       << "</span></h1>\n";
  if (r.verdict) {
    const char* v = r.verdict->pass ? "PASS" : "FAIL";
    html << "<p><span class=\"badge " << v << "\" data-key=\"verdict\">" << v << "</span> "
         << HtmlEscape(r.verdict->limits_name) << " &mdash; " << r.verdict->Failed() << " of "
         << r.verdict->criteria.size() << " criteria failed</p>\n";
  }
  html << "<table>\n" << Row({"unit serial", HtmlEscape(serial)});
  if (!r.unit.empty()) html << Row({"unit folder", HtmlEscape(r.unit)});
  html << Row({"calibrated (UTC)", HtmlEscape(cal.created_utc)})
       << Row({"report written (UTC)", HtmlEscape(r.created_utc)})
       << Row({"software", "<span data-key=\"software\">" + HtmlEscape(cal.software) + "</span>"})
       << Row({"software of this report", HtmlEscape(r.software) + ", git " + HtmlEscape(r.git_revision)})
       << "</table>\n";

  html << "<h2>Input files</h2>\n<table><tr><th>role</th><th>file</th><th>SHA-256</th></tr>\n";
  for (const ReportInput& in : r.inputs) {
    html << "<tr><td>" << HtmlEscape(in.role) << "</td><td>" << HtmlEscape(in.path)
         << "</td><td class=\"hash\" data-sha256=\"" << HtmlEscape(in.role) << "\">" << in.sha256
         << "</td></tr>\n";
  }
  html << "</table>\n";

  // The run.
  int statics = 0;
  std::set<double> rates_dps;
  for (const TableSegment& s : r.plan.segments) {
    statics += s.IsStatic() ? 1 : 0;
    if (!s.IsStatic()) rates_dps.insert(std::abs(s.rate_radps) * kRadToDeg);
  }
  std::string rates;
  for (double rate : rates_dps) rates += (rates.empty() ? "" : ", ") + Fmt("%g", rate);
  std::set<long> temps;
  for (const Window& w : r.run.windows) temps.insert(std::lround(w.temp_c));
  html << "<h2>Plan and run</h2>\n<table>\n"
       << Row({"plan", HtmlEscape(r.plan.path)})
       << Row({"segments", std::to_string(r.plan.segments.size()) + " (" + std::to_string(statics) +
                               " static, " + std::to_string(r.plan.segments.size() - statics) +
                               " rate; |rate| " + rates + " deg/s)"})
       << Row({"local gravity", Fmt("%.6g m/s&sup2;", r.plan.site.gravity_mps2)})
       << Row({"latitude", r.plan.site.latitude_rad ? Fmt("%.4f deg", *r.plan.site.latitude_rad * kRadToDeg)
                                                    : "not given"})
       << Row({"samples read", std::to_string(r.run.stats.samples)})
       << Row({"windows", std::to_string(r.run.windows.size())})
       << Row({"temperature range covered", "<span data-key=\"temp_range_c\">" +
                                                Fmt("%.1f", cal.fit_temp_range_c[0]) + " .. " +
                                                Fmt("%.1f", cal.fit_temp_range_c[1]) + "</span> degC"})
       << "</table>\n";

  if (r.verdict) html << "<h2>Acceptance</h2>\n" << VerdictHtml(*r.verdict);

  html << "<h2>Coefficients at 25 degC (&plusmn; 1 "
          "sigma)</h2>\n<table><tr><th>coefficient</th><th>value</th><th>1-sigma</th><th>unit</th></tr>\n";
  for (const Figure& f : KeyFigures(cal)) {
    html << "<tr><td>" << HtmlEscape(f.name) << "</td><td class=\"num\" data-figure=\"" << HtmlEscape(f.name)
         << "\" data-value=\"" << FormatDouble(f.value) << "\">" << Fmt("%+.6g", f.value) << "</td>"
         << Num(f.sigma >= 0.0 ? Fmt("%.3g", f.sigma) : "&ndash;") << "<td>" << HtmlEscape(f.unit)
         << "</td></tr>\n";
  }
  html << "</table>\n";

  // Plots: every coefficient group, then the residuals (one gnuplot run).
  const std::vector<CurveGroup> groups = CoefficientCurves(cal);
  const std::vector<WindowError> errors =
      PredictWindows(cal.model, r.run.windows, r.plan.site, r.plan.segments);
  std::string script;
  for (size_t g = 0; g < groups.size(); ++g) script += CurvesScript(groups[g], static_cast<int>(g));
  const int gyro_plot = static_cast<int>(groups.size());
  script +=
      ResidualScript(errors, r.plan, true, gyro_plot) + ResidualScript(errors, r.plan, false, gyro_plot + 1);
  std::vector<std::string> svgs;
  std::string failure;
  try {
    svgs = RunGnuplotSvg(script, gyro_plot + 2);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  const auto slice = [&](size_t from, size_t to) {
    std::vector<std::string> part;
    for (size_t i = from; i < to && i < svgs.size(); ++i) part.push_back(svgs[i]);
    return part;
  };
  html << "<h2>Coefficients against temperature</h2>\n"
       << "<p class=\"note\">Bands: 1-sigma from each term's own sigma (correlations between terms not "
          "drawn).</p>\n"
       << Plots(slice(0, groups.size()), failure);

  html << "<h2>Residuals before and after correction</h2>\n" << Plots(slice(groups.size(), groups.size() + 2), "");
  // Before correction: the raw outputs divided by the unit's own 25 degC scale factors only (no
  // bias, misalignment, g-sensitivity or temperature dependence), i.e. what the calibration fixes.
  SensorModel scale_only = SensorModel::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    const int c0 = (kScaleCoefficient + axis) * kPolynomialTerms;
    scale_only.gyro[c0] = cal.model.gyro[c0];
    scale_only.accel[c0] = cal.model.accel[c0];
  }
  std::vector<ErrorStats> stats = ErrorsBySegment(errors);
  stats.push_back(SummariseErrors(errors));
  const std::vector<WindowError> errors_before =
      PredictWindows(scale_only, r.run.windows, r.plan.site, r.plan.segments);
  std::vector<ErrorStats> before = ErrorsBySegment(errors_before);
  before.push_back(SummariseErrors(errors_before));
  html << "<p class=\"note\">Per window, |corrected - true|; <em>before</em>: the raw outputs divided by the "
          "unit's 25 degC scale factors only.</p>\n"
          "<table><tr><th>segment</th><th>up</th><th>rate, deg/s</th><th>windows</th>"
          "<th>gyro RMS before, deg/s</th><th>gyro RMS, deg/s</th><th>gyro max, deg/s</th>"
          "<th>accel RMS before, mg</th><th>accel RMS, mg</th><th>accel max, mg</th></tr>\n";
  for (size_t i = 0; i < stats.size(); ++i) {
    const ErrorStats& s = stats[i];
    const ErrorStats& b = before[i];  // the same segments, in the same order
    const TableSegment* seg = s.segment < 0 ? nullptr : r.plan.Find(s.segment);
    std::string up = "";
    if (seg) up = Fmt("[%g,", seg->up.x()) + Fmt(" %g,", seg->up.y()) + Fmt(" %g]", seg->up.z());
    html << "<tr" << (s.segment < 0 ? " data-key=\"residual_all\"" : "") << "><td>"
         << (s.segment < 0 ? "all" : std::to_string(s.segment)) << "</td><td>" << up << "</td>"
         << Num(seg ? Fmt("%g", seg->rate_radps * kRadToDeg) : "") << Num(std::to_string(s.windows))
         << Num(Fmt("%.4f", b.gyro_rms_radps * kRadToDeg)) << Num(Fmt("%.5f", s.gyro_rms_radps * kRadToDeg))
         << Num(Fmt("%.5f", s.gyro_max_radps * kRadToDeg))
         << Num(Fmt("%.3f", b.accel_rms_mps2 / kStandardGravityMps2 * 1e3))
         << Num(Fmt("%.4f", s.accel_rms_mps2 / kStandardGravityMps2 * 1e3))
         << Num(Fmt("%.4f", s.accel_max_mps2 / kStandardGravityMps2 * 1e3)) << "</tr>\n";
  }
  html << "</table>\n";

  for (const ReportInput& in : r.inputs) {
    if (in.role != "samples") continue;
    try {
      html << AllanSection(r, in.path);
    } catch (const std::exception& e) {
      html << "<p class=\"note\">Allan deviation not computed: " << HtmlEscape(e.what()) << "</p>\n";
    }
  }

  html << "<h2>Validation (leave one temperature out)</h2>\n";
  if (r.folds.empty()) {
    html << "<p class=\"note\">Not run (imufit fit --validate runs it).</p>\n";
  } else {
    html << "<table><tr><th>held-out temperature, degC</th><th>windows</th><th>gyro RMS, deg/s</th><th>gyro "
            "max, deg/s</th>"
            "<th>accel RMS, mg</th><th>accel max, mg</th></tr>\n";
    for (const HeldOutGroup& g : r.folds) {
      if (!g.fitted) {
        html << "<tr><td>" << Fmt("%.1f", g.temp_c)
             << "</td><td colspan=\"5\">not fitted: " << HtmlEscape(g.why_not) << "</td></tr>\n";
        continue;
      }
      html << "<tr><td>" << Fmt("%.1f", g.temp_c) << "</td>" << Num(std::to_string(g.errors.windows))
           << Num(Fmt("%.5f", g.errors.gyro_rms_radps * kRadToDeg))
           << Num(Fmt("%.5f", g.errors.gyro_max_radps * kRadToDeg))
           << Num(Fmt("%.4f", g.errors.accel_rms_mps2 / kStandardGravityMps2 * 1e3))
           << Num(Fmt("%.4f", g.errors.accel_max_mps2 / kStandardGravityMps2 * 1e3)) << "</tr>\n";
    }
    html << "</table>\n";
  }
  html << "<p class=\"note\">Units: deg/s and mg at 25 degC; 1 g = 9.80665 m/s&sup2;. Coefficient model and "
          "file "
          "format: docs/spec.md; conversions: docs/factory.md.</p>\n</body></html>\n";
  return html.str();
}

void WriteUnitReport(const std::string& path, const UnitReport& report) {
  WriteFileAtomically(path, UnitReportHtml(report));
}

std::vector<RobustZ> RobustZScores(const std::vector<double>& values) {
  std::vector<RobustZ> scores(values.size());
  if (values.size() < 3) return scores;
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  const double m = median(values);
  std::vector<double> deviations;
  for (double v : values) deviations.push_back(std::abs(v - m));
  const double mad = median(deviations);
  for (size_t i = 0; i < values.size(); ++i) {
    if (!(mad > 0.0)) continue;  // half the lot identical: no spread to judge by
    scores[i].z = 0.6745 * (values[i] - m) / mad;
    scores[i].outlier = std::abs(scores[i].z) > kOutlierRobustZ;
  }
  return scores;
}

std::string LotReportHtml(const std::string& lot, const BatchResult& batch, const std::string& software) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>Lot " << HtmlEscape(lot)
       << "</title>\n<style>" << kStyle << "</style></head><body>\n";
  const int units = static_cast<int>(batch.units.size());
  html << "<h1>Lot <span data-key=\"lot\">" << HtmlEscape(lot) << "</span></h1>\n<table>\n"
       << Row({"units", "<span data-key=\"units\">" + std::to_string(units) + "</span>"})
       << Row({"passed",
               "<span class=\"PASS\" data-key=\"passed\">" + std::to_string(batch.passed) + "</span>"})
       << Row({"failed limits",
               "<span class=\"FAIL\" data-key=\"failed\">" + std::to_string(batch.failed) + "</span>"})
       << Row({"not fitted / errors",
               std::to_string(batch.not_fitted) + " / " + std::to_string(batch.errors)})
       << Row({"yield", "<span data-key=\"yield\">" +
                            Fmt("%.1f", units ? 100.0 * batch.passed / units : 0.0) + "</span> %"})
       << Row({"written",
               HtmlEscape(UtcNow()) + " by " + HtmlEscape(software) + ", git " + IMUFIT_GIT_REVISION})
       << "</table>\n";

  html << "<h2>Units</h2>\n<table><tr><th>unit</th><th>serial</th><th>status</th><th>verdict</th><th>reason</"
          "th></tr>\n";
  for (const UnitOutcome& u : batch.units) {
    const std::string name = u.status == "fitted" ? "<a href=\"" + HtmlEscape(u.unit) + "/report.html\">" +
                                                        HtmlEscape(u.unit) + "</a>"
                                                  : HtmlEscape(u.unit);
    html << "<tr data-unit=\"" << HtmlEscape(u.unit) << "\"><td>" << name << "</td><td>"
         << HtmlEscape(u.serial) << "</td><td>" << HtmlEscape(u.status) << "</td><td class=\""
         << HtmlEscape(u.verdict) << "\">" << HtmlEscape(u.verdict) << "</td><td>" << HtmlEscape(u.message)
         << "</td></tr>\n";
  }
  html << "</table>\n";

  // Distributions: one strip plot per key figure over the fitted units; outliers in red.
  std::string script, outliers;
  int plots = 0;
  for (const std::string& name : kSummaryFigures) {
    std::vector<double> values;
    std::vector<const UnitOutcome*> owners;
    std::string unit;
    for (const UnitOutcome& u : batch.units) {
      if (const Figure* f = FindFigure(u.figures, name)) {
        values.push_back(f->value);
        owners.push_back(&u);
        unit = f->unit;
      }
    }
    if (values.empty()) continue;
    const std::vector<RobustZ> z = RobustZScores(values);
    std::ostringstream gp;
    gp.precision(12);
    for (int kind = 0; kind < 2; ++kind) {
      gp << "$s" << kind << " << EOD\n";
      for (size_t i = 0; i < values.size(); ++i) {
        if (z[i].outlier == (kind == 1)) gp << values[i] << " " << (i % 5) * 0.15 << "\n";
      }
      gp << "NaN NaN\nEOD\n";
    }
    for (size_t i = 0; i < values.size(); ++i) {
      if (!z[i].outlier) continue;
      outliers += "<tr data-outlier=\"" + HtmlEscape(owners[i]->unit) + "\" data-figure=\"" +
                  HtmlEscape(name) + "\"><td>" + HtmlEscape(owners[i]->unit) + "</td><td>" +
                  HtmlEscape(owners[i]->serial) + "</td><td>" + HtmlEscape(name) + "</td>" +
                  Num(Fmt("%.6g", values[i]) + " " + HtmlEscape(unit)) + Num(Fmt("%+.1f", z[i].z)) +
                  "</tr>\n";
    }
    gp << "set terminal svg size 460,150 dynamic noenhanced font 'DejaVu Sans,10' background rgb "
          "'white'\nset output '@OUT"
       << plots << "@'\n"
       << "set title " << GnuplotQuote(name + " (" + unit + ")")
       << "\nunset ytics\nset yrange [-0.3:0.9]\nset grid xtics\n"
       << "set offsets graph 0.05, graph 0.05, 0, 0\nunset key\n"
       << "plot $s0 using 1:2 with points pt 7 ps 0.8 lc rgb '#1f77b4', $s1 using 1:2 with points pt 7 ps "
          "1.2 lc rgb '#d62728'\n"
       << "unset output\nreset\n";
    script += gp.str();
    ++plots;
  }
  html << "<h2>Outliers (robust z = 0.6745 (x - median) / MAD, |z| &gt; " << Fmt("%.1f", kOutlierRobustZ)
       << ")</h2>\n";
  if (outliers.empty()) {
    html << "<p>None.</p>\n";
  } else {
    html << "<table><tr><th>unit</th><th>serial</th><th>figure</th><th>value</th><th>robust z</th></tr>\n"
         << outliers << "</table>\n";
  }
  html << "<h2>Distributions of the key figures at 25 degC</h2>\n<p class=\"note\">One dot per fitted unit; "
          "red: outlier.</p>\n";
  if (plots > 0) {
    try {
      html << "<div style=\"display: grid; grid-template-columns: 1fr 1fr; gap: 4px\">\n";
      for (const std::string& svg : RunGnuplotSvg(script, plots))
        html << "<div class=\"plot\">" << svg << "</div>\n";
      html << "</div>\n";
    } catch (const std::exception& e) {
      html << "</div><p class=\"note\">Plots not drawn: " << HtmlEscape(e.what()) << "</p>\n";
    }
  }
  html << "</body></html>\n";
  return html.str();
}

}  // namespace imufit
