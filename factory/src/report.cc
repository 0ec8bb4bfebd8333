// The renderer: a Certificate or a LotSummary as HTML. It formats numbers and lays out tables and
// plots; every number it shows was computed in certificate.cc.
#include "imufit/factory/report.h"

#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "imufit/factory/allan_plot.h"
#include "imufit/factory/html.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

std::string Printf(const char* format, double value) {
  char text[96];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

std::string FormatNumber(const char* format, double value) {
  const std::string text = Printf(format, value);
  if (text != Printf(format, -0.0) && text != Printf(format, 0.0)) return text;
  std::string unsigned_format = format;  // the '+' flag dropped from the conversion
  for (size_t at = unsigned_format.find('%'); at != std::string::npos;
       at = unsigned_format.find('%', at + 2)) {
    if (unsigned_format[at + 1] == '%') continue;
    size_t flag = at + 1;
    while (flag < unsigned_format.size() && std::strchr("-+ #0", unsigned_format[flag]) != nullptr) {
      if (unsigned_format[flag] == '+') {
        unsigned_format.erase(flag, 1);
      } else {
        ++flag;
      }
    }
  }
  return Printf(unsigned_format.c_str(), 0.0);
}

namespace {

std::string Fmt(const char* format, double value) { return FormatNumber(format, value); }

std::string Count(long long value) { return std::to_string(value); }

// Screen and print: fluid width (fits A4 and Letter), no heading left alone at a page's foot, no
// table row split, small sections kept whole.
const char* kStyle = R"css(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; font-size: 12px; color: #111; margin: 20px auto; max-width: 980px; }
h1 { font-size: 20px; margin: 0 0 6px 0; } h2 { font-size: 15px; border-bottom: 1px solid #999; margin: 16px 0 6px 0; }
h3 { font-size: 13px; margin: 10px 0 4px 0; }
table { border-collapse: collapse; margin: 4px 0; } td, th { border: 1px solid #bbb; padding: 1px 6px; text-align: left; vertical-align: top; }
th { background: #eee; } .path { overflow-wrap: anywhere; } td.num { text-align: right; font-variant-numeric: tabular-nums; font-family: "DejaVu Sans Mono", monospace; white-space: nowrap; }
thead { display: table-header-group; } td:first-child { white-space: nowrap; } tr { break-inside: avoid; page-break-inside: avoid; }
.hash { font-family: "DejaVu Sans Mono", monospace; font-size: 10px; word-break: break-all; }
.PASS { color: #06642a; font-weight: bold; } .FAIL { color: #b00; font-weight: bold; }
.badge { display: inline-block; padding: 3px 14px; font-size: 18px; border: 2px solid; border-radius: 4px; }
.plot svg { width: 100%; height: auto; } .plot { break-inside: avoid; page-break-inside: avoid; }
.plots2 { display: grid; grid-template-columns: 1fr 1fr; gap: 2px 10px; }
.cols { display: grid; grid-template-columns: 1fr 1fr; gap: 12px; } .cols > div { break-inside: avoid; } .cols table { width: 100%; }
.keep { break-inside: avoid; page-break-inside: avoid; }
.warn { background: #fff4d6; border: 1px solid #e0b000; padding: 4px 8px; margin: 6px 0; }
.note { color: #555; font-size: 11px; }
tr.failed td { background: #fde4e4; }
.outlier { color: #b00; } .failed-unit { color: #b00; font-weight: bold; } tr.current td { background: #ffe9d6; font-weight: bold; }
h2, h3 { break-after: avoid; page-break-after: avoid; }
.sign { width: 100%; margin-top: 6px; } .sign td { height: 26px; } .sign td:first-child { width: 22%; }
.sign td:nth-child(2) { width: 30%; } .sign td:nth-child(3) { width: 30%; } table.fill { width: 100%; }
table.fill td:first-child { width: 35%; }
@media print { body { margin: 0; max-width: none; font-size: 10px; } td, th { padding: 0 5px; } h2 { margin: 10px 0 4px 0; }
  table { line-height: 1.1; }
  .page-break { break-before: page; } }
)css";

// A table row of cells (each text escaped).
void Row(Html* h, std::initializer_list<std::string> cells, const char* tag = "td") {
  h->Open("tr");
  for (const std::string& c : cells) h->Element(tag, c);
  h->Close("tr");
}

void Num(Html* h, const std::string& text, const HtmlAttributes& attributes = {}) {
  HtmlAttributes all = {{"class", "num"}};
  all.insert(all.end(), attributes.begin(), attributes.end());
  h->Element("td", text, all);
}

void Plots(Html* h, const std::vector<Svg>& svgs, size_t from, size_t to, const std::string& failure,
           const char* layout = nullptr) {
  if (!failure.empty()) {
    h->Element("p", "Plots not drawn: " + failure, {{"class", "note"}});
    return;
  }
  if (layout != nullptr) h->Open("div", {{"class", layout}});
  for (size_t i = from; i < to && i < svgs.size(); ++i) {
    h->Open("div", {{"class", "plot"}}).Figure(svgs[i]).Close("div");
  }
  if (layout != nullptr) h->Close("div");
}

// ---------------------------------------------------------------- certificate plots

PlotFigure Figure(int rows, int cols, int width_px, int height_px) {
  PlotFigure figure;
  figure.rows = rows;
  figure.cols = cols;
  figure.width_px = width_px;
  figure.height_px = height_px;
  return figure;
}

Plot Panel(const std::string& title, const std::string& x_label, const std::string& y_label) {
  Plot plot;
  plot.title = title;
  plot.x_label = x_label;
  plot.y_label = y_label;
  return plot;
}

PlotSeries Series(PlotSeries::Style style, const std::string& title, int color, const std::vector<double>& x,
                  const std::vector<double>& y) {
  PlotSeries s;
  s.style = style;
  s.title = title;
  s.color = PlotColor(color);
  s.x = x;
  s.y = y;
  return s;
}

// Figure widths in CSS pixels at print (A4 less its margins is about 695 px, Letter 718 px): drawn
// at the size they are printed, so gnuplot's 10 pt labels stay 10 pt on paper.
constexpr int kFullWidthPx = 700;
constexpr int kHalfWidthPx = 345;

PlotFigure CoefficientFigure(const CoefficientGroup& g) {
  PlotFigure figure;
  const auto panel = [&](const CoefficientCurve& c, int color, Plot* plot) {
    PlotSeries band = Series(PlotSeries::Style::kBand, "", color, c.temp_c, c.value);
    band.lo = c.lo;
    band.hi = c.hi;
    plot->series.push_back(band);
    PlotSeries line = Series(PlotSeries::Style::kLines, g.grid ? "" : c.axis, color, c.temp_c, c.value);
    line.line_width = 1.5;
    plot->series.push_back(line);
    // The windows' own estimates over the curve: open circles with their 1-sigma bars (a bar
    // shorter than the circle is hidden by it).
    PlotSeries points = Series(PlotSeries::Style::kErrorBars, "", color, {}, {});
    for (const CoefficientPoint& p : c.points) {
      points.x.push_back(p.temp_c);
      points.y.push_back(p.value);
      points.error.push_back(p.sigma);
    }
    points.point_type = 6;
    points.point_size = 0.45;
    points.line_width = 1;
    plot->series.push_back(points);
  };
  if (g.grid) {
    figure = Figure(3, 3, kFullWidthPx, 320);
    figure.title = g.title + " (" + g.unit + ") against temperature, degC";
    for (const CoefficientCurve& c : g.curves) {
      Plot plot;
      plot.labels.push_back({c.axis});  // inside the panel: no title line
      plot.key = false;
      plot.max_x_tics = 7;
      plot.max_y_tics = 4;
      panel(c, 0, &plot);
      figure.panels.push_back(plot);
    }
    return figure;
  }
  figure = Figure(1, 1, kHalfWidthPx, 160);
  Plot plot = Panel(g.title, "temperature, degC", g.unit);
  plot.max_x_tics = 7;
  plot.max_y_tics = 5;
  for (size_t i = 0; i < g.curves.size(); ++i) panel(g.curves[i], static_cast<int>(i), &plot);
  figure.panels.push_back(plot);
  return figure;
}

// The errors of every window before and after correction, against temperature and time, with the
// run's temperature and the histogram of the normalised errors: one 3 x 3 grid.
// A run at one temperature (a hand session, a single soak): its coefficients are constants, so
// there are no curves against temperature to draw, and its errors are drawn against time.
bool OneTemperature(const Certificate& c) { return c.run.temperatures_c.size() < 2; }

PlotFigure ErrorFigure(const Certificate& c) {
  const WindowResiduals& r = c.residuals;
  const bool one_temperature = OneTemperature(c);
  PlotFigure figure = one_temperature ? Figure(2, 3, kFullWidthPx, 320) : Figure(3, 3, kFullWidthPx, 480);
  const char* axes[] = {"x", "y", "z"};  // keyed in the section's note, so the panels keep their width
  const auto panel = [&](const std::string& title, const std::vector<double>& x, const std::string& x_label,
                         const std::string& unit, const std::array<std::vector<double>, 3>& values,
                         const std::array<std::vector<double>, 3>* noise) {
    Plot plot = Panel(title, x_label, unit);
    plot.key = false;
    plot.max_x_tics = 7;
    plot.max_y_tics = 5;
    for (int axis = 0; axis < 3; ++axis) {
      PlotSeries s = Series(noise ? PlotSeries::Style::kErrorBars : PlotSeries::Style::kPoints, axes[axis],
                            axis, x, values[axis]);
      if (noise) s.error = (*noise)[axis];
      s.point_size = 0.3;
      s.line_width = 1;
      plot.series.push_back(s);
    }
    figure.panels.push_back(plot);
  };
  const std::vector<double>& x = one_temperature ? r.time_s : r.temp_c;
  const std::string x_label = one_temperature ? "time, s" : "temperature, degC";
  panel("Gyro error after correction", x, x_label, "deg/s", r.gyro_dps, &r.gyro_noise_dps);
  panel("Accel error after correction", x, x_label, "mg", r.accel_mg, &r.accel_noise_mg);
  Plot histogram = Panel("Normalised errors after", "error / window noise", "windows x axes");
  histogram.key = false;
  histogram.max_x_tics = 11;
  histogram.max_y_tics = 5;
  histogram.y_from_zero = true;
  PlotSeries gyro = Series(PlotSeries::Style::kLinesPoints, "gyro", 0, r.histogram_center, r.gyro_histogram);
  PlotSeries accel =
      Series(PlotSeries::Style::kLinesPoints, "accel", 1, r.histogram_center, r.accel_histogram);
  gyro.point_size = accel.point_size = 0.4;
  histogram.series = {gyro, accel};
  figure.panels.push_back(histogram);
  if (one_temperature) {
    panel("Gyro error before", x, x_label, "deg/s", r.gyro_before_dps, nullptr);
    panel("Accel error before", x, x_label, "mg", r.accel_before_mg, nullptr);
    return figure;
  }
  panel("Gyro error after, against time", r.time_s, "time, s", "deg/s", r.gyro_dps, nullptr);
  panel("Accel error after, against time", r.time_s, "time, s", "mg", r.accel_mg, nullptr);
  Plot temp = Panel("Temperature (window means)", "time, s", "degC");
  temp.key = false;
  temp.max_x_tics = 7;
  temp.max_y_tics = 5;
  PlotSeries temps = Series(PlotSeries::Style::kPoints, "", 3, c.run.time_s, c.run.window_temp_c);
  temps.point_size = 0.3;
  temp.series.push_back(temps);
  figure.panels.push_back(temp);
  panel("Gyro error before", r.temp_c, "temperature, degC", "deg/s", r.gyro_before_dps, nullptr);
  panel("Accel error before", r.temp_c, "temperature, degC", "mg", r.accel_before_mg, nullptr);
  return figure;
}

// The gyro's Allan deviation as `imufit allan --plot --plot-units deg/h` draws it (allan_plot.h):
// the curves with their confidence bars, the IEEE 952 fit and its terms, ARW and bias instability
// marked where they are read; at the certificate's printed width.
PlotFigure AllanFigure(const NoiseSection& noise) {
  PlotFigure figure = AllanPlot(noise.columns, "", AllanPlotUnits::kDegPerHour);
  figure.width_px = kFullWidthPx;
  figure.height_px = 330;
  for (Plot& panel : figure.panels) {
    panel.title = "";        // the section's note says which stretch
    panel.key_above = true;  // the panel keeps the page's width
  }
  return figure;
}

// ---------------------------------------------------------------- certificate sections

// A piece of equipment as "model, serial S".
std::string EquipmentText(const StationEquipment& e) {
  if (e.serial.empty()) return e.model;
  return (e.model.empty() ? "" : e.model + ", ") + "serial " + e.serial;
}

// Where and by whom, from the station file; without one, lines to fill in by hand.
void Station(Html* h, const Certificate& c) {
  h->Open("div").Open("table", {{"class", "fill"}});
  if (!c.station) {
    for (const char* field :
         {"station", "location", "rate table", "chamber", "reference equipment calibrated until"})
      Row(h, {field, ""});
    h->Close("table").Close("div");
    return;
  }
  const imufit::Station& s = *c.station;
  const auto field = [&](const char* name, const std::string& value, const char* key) {
    if (value.empty()) return;
    h->Open("tr").Element("td", name).Element("td", value, {{"data-key", key}}).Close("tr");
  };
  field("station", s.name + (s.id.empty() ? "" : " (" + s.id + ")"), "station");
  field("location", s.location, "location");
  field("operator", s.operator_name, "operator");
  field("rate table", EquipmentText(s.rate_table), "rate_table");
  field("chamber", EquipmentText(s.chamber), "chamber");
  field("reference equipment calibrated until", s.reference_calibration_due, "reference_calibration_due");
  field("notes", s.notes, "station_notes");
  h->Close("table").Close("div");
}

// The lines a quality engineer signs: who calibrated the unit (the station's operator, when known)
// and who reviewed the certificate.
void Signatures(Html* h, const Certificate& c) {
  h->Open("table", {{"class", "sign"}}).Open("thead");
  Row(h, {"", "name", "signature", "date"}, "th");
  h->Close("thead").Open("tbody");
  h->Open("tr").Element("td", "Calibrated by");
  h->Element("td", c.station ? c.station->operator_name : "", {{"data-key", "calibrated_by"}});
  h->Element("td", "").Element("td", "").Close("tr");
  Row(h, {"Reviewed by (quality)", "", "", ""});
  h->Close("tbody").Close("table");
}

void Identification(Html* h, const Certificate& c) {
  const std::string serial = c.serial.empty() ? "(no serial)" : c.serial;
  h->Open("h1")
      .Text("IMU calibration certificate \xe2\x80\x94 ")
      .Element("span", serial, {{"data-key", "serial"}});
  h->Close("h1");
  if (c.verdict) {
    const char* v = c.verdict->pass ? "PASS" : "FAIL";
    h->Open("p").Element("span", v, {{"class", std::string("badge ") + v}, {"data-key", "verdict"}});
    const std::string criteria = Count(static_cast<long long>(c.verdict->criteria.size()));
    h->Text(" " + c.verdict->limits_name + " \xe2\x80\x94 " +
            (c.verdict->pass ? "all " + criteria + " criteria passed"
                             : Count(c.verdict->Failed()) + " of " + criteria + " criteria failed"));
    h->Close("p");
    // What failed, where the signer looks first (the table below has every criterion).
    if (!c.verdict->pass) {
      h->Element("p", "Failed: " + c.verdict->FailedSummary() + ".",
                 {{"class", "FAIL"}, {"data-key", "failed_criteria"}});
    }
  } else {
    h->Element("p",
               "No acceptance limits were given: this certificate states the calibration, not a verdict.",
               {{"class", "note"}});
  }
  for (const std::string& w : c.warnings) {
    h->Open("div", {{"class", "warn"}, {"data-warning", w}}).Text("Warning: " + w).Close("div");
  }
  h->Open("div", {{"class", "cols"}});
  h->Open("div").Open("table", {{"class", "fill"}});
  Row(h, {"unit serial", serial});
  if (!c.unit.empty()) Row(h, {"unit folder", c.unit});
  Row(h, {"calibrated (UTC)", c.calibrated_utc});
  Row(h, {"certificate written (UTC)", c.written_utc});
  h->Open("tr")
      .Element("td", "calibration software")
      .Element("td", c.calibration_software, {{"data-key", "software"}});
  h->Close("tr");
  Row(h, {"certificate software", c.report_software + ", git " + c.git_revision});
  Row(h, {"reference temperature of the coefficients", Fmt("%g degC", c.reference_temp_c)});
  h->Close("table").Close("div");
  Station(h, c);
  h->Close("div");
  Signatures(h, c);
  h->Open("div", {{"class", "keep"}});
  h->Element("h2", "Input files");
  h->Open("table").Open("thead");
  Row(h, {"role", "file", "SHA-256"}, "th");
  h->Close("thead").Open("tbody");
  for (const ReportInput& in : c.inputs) {
    h->Open("tr").Element("td", in.role).Element("td", in.path, {{"class", "path"}});
    h->Element("td", in.sha256, {{"class", "hash"}, {"data-sha256", in.role}}).Close("tr");
  }
  h->Close("tbody").Close("table").Close("div");
}

void RunAndSettings(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "cols"}});
  h->Open("div").Element("h2", "Plan and run").Open("table");
  const auto list = [](const std::vector<double>& values) {
    std::string text;
    for (double v : values) text += (text.empty() ? "" : ", ") + Fmt("%g", v);
    return text;
  };
  h->Open("tr").Element("td", "plan").Element("td", c.run.plan_path, {{"class", "path"}}).Close("tr");
  std::string segments = Count(c.run.segments) + " (" + Count(c.run.static_segments) + " static";
  if (!c.run.rates_dps.empty()) segments += "; rates " + list(c.run.rates_dps) + " deg/s";
  if (c.run.turn_segments > 0) {
    segments += "; " + Count(c.run.turn_segments) + (c.run.turn_segments == 1 ? " turn of " : " turns of ") +
                list(c.run.turn_angles_deg) + " deg";
  }
  Row(h, {"segments", segments + ")"});

  Row(h, {"local gravity", Fmt("%.6g m/s\xc2\xb2", c.run.gravity_mps2)});
  Row(h, {"latitude", c.run.latitude_deg ? Fmt("%.4f deg", *c.run.latitude_deg) : "not given"});
  Row(h, {"samples read", Count(c.run.samples)});
  // Whether every plan segment has a window: said either way (the warnings name the ones without).
  const std::vector<int>& missing = c.run.segments_without_windows;
  std::string ids;
  for (int id : missing) ids += (ids.empty() ? "" : ", ") + Count(id);
  h->Open("tr").Element("td", "windows").Open("td").Text(Count(c.run.windows));
  h->Element("span",
             missing.empty() ? ", in every plan segment"
                             : (missing.size() == 1 ? "; none in segment " : "; none in segments ") + ids,
             {{"data-key", "segments_without_windows"},
              {"data-value", Count(static_cast<long long>(missing.size()))}});
  h->Close("td").Close("tr");
  std::string temps;
  for (double t : c.run.temperatures_c) temps += (temps.empty() ? "" : ", ") + Fmt("%g", t);
  Row(h, {"temperatures (windows, nearest degC)", temps});
  h->Open("tr").Element("td", "temperature range fitted");
  h->Open("td").Element("span",
                        Fmt("%.1f", c.run.temp_range_c[0]) + " .. " + Fmt("%.1f", c.run.temp_range_c[1]),
                        {{"data-key", "temp_range_c"}});
  h->Text(" degC").Close("td").Close("tr");
  h->Close("table").Close("div");

  const FitSettings& s = c.settings;
  h->Open("div").Element("h2", "Fit settings and diagnostics").Open("table");
  if (!s.known) {
    Row(h, {"fit diagnostics", "not in the calibration (no fit: block)"});
  } else {
    Row(h, {"robust loss", s.loss});
    Row(h, {"windows used / down-weighted", Count(s.windows_used) + " / " + Count(s.windows_downweighted)});
    Row(h, {"reduced chi-square gyro / accel",
            Fmt("%.3g", s.gyro_reduced_chi2) + " / " + Fmt("%.3g", s.accel_reduced_chi2)});
    Row(h, {"temperature orders gyro / accel", Count(s.gyro_temp_order) + " / " + Count(s.accel_temp_order)});
    Row(h, {"g-sensitivity", s.g_sensitivity_fitted ? "fitted" : "held at zero"});
    Row(h, {"solver",
            s.termination + " " + Count(s.iterations) + (s.iterations == 1 ? " iteration" : " iterations")});
    Row(h, {"bias stability in the sigmas", s.gyro_bias_stability_dph > 0.0 || s.accel_bias_stability_ug > 0.0
                                                ? Fmt("gyro %g deg/h", s.gyro_bias_stability_dph) +
                                                      Fmt(", accel %g micro-g", s.accel_bias_stability_ug)
                                                : "no (white noise only)"});
  }
  Row(h, {"trim after each move", Fmt("%g s", s.trim_s)});
  Row(h, {"window temperature span", Fmt("%g degC", s.window_temp_span_c)});
  h->Close("table").Close("div");
  h->Close("div");
}

void Acceptance(Html* h, const Verdict& verdict) {
  h->Element("h2",
             "Acceptance: " + (verdict.limits_name.empty() ? std::string("limits") : verdict.limits_name));
  h->Open("table").Open("thead");
  Row(h, {"criterion", "measured", "limit", "margin", "verdict"}, "th");
  h->Close("thead").Open("tbody");
  for (const CriterionResult& cr : verdict.criteria) {
    HtmlAttributes row = {{"data-criterion", cr.name}, {"data-pass", cr.pass ? "1" : "0"}};
    if (!cr.pass) row.push_back({"class", "failed"});
    h->Open("tr", row).Element("td", cr.name);
    Num(h, cr.measured_text);
    Num(h, cr.limit_text);
    Num(h, cr.margin_text);
    h->Element("td", cr.pass ? "PASS" : "FAIL", {{"class", cr.pass ? "PASS" : "FAIL"}}).Close("tr");
  }
  h->Close("tbody").Close("table");
}

void FigureTable(Html* h, const std::vector<KeyFigureRow>& figures, bool gyro) {
  // The sensor's prefix is the table's heading, so that two tables fit side by side on A4.
  // Figures of neither sensor (coverage) are in the plan and run table.
  const std::string prefix = gyro ? "gyro_" : "accel_";
  h->Open("table").Open("thead");
  Row(h, {gyro ? "gyro" : "accelerometer", "value", "1-sigma", "U (k = 2)", "unit"}, "th");
  h->Close("thead").Open("tbody");
  for (const KeyFigureRow& f : figures) {
    if (f.name.rfind(prefix, 0) != 0) continue;
    h->Open("tr").Element("td", f.name.substr(prefix.size()));
    Num(h, Fmt(f.is_coefficient ? "%+.6g" : "%.6g", f.value),
        {{"data-figure", f.name}, {"data-value", FormatDouble(f.value)}});
    Num(h, f.sigma >= 0.0 ? Fmt("%.3g", f.sigma) : "\xe2\x80\x93");
    Num(h, f.expanded >= 0.0 ? Fmt("%.3g", f.expanded) : "\xe2\x80\x93");
    h->Element("td", f.unit).Close("tr");
  }
  h->Close("tbody").Close("table");
}

void KeyFigures(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "keep"}});
  h->Element("h2", "Coefficients at 25 degC");
  h->Element("p",
             "1-sigma from the fit's covariance; U is the expanded uncertainty at k = 2 (about 95 % for a "
             "normal distribution).",
             {{"class", "note"}});
  h->Open("div", {{"class", "cols"}});
  h->Open("div");
  FigureTable(h, c.figures, true);
  h->Close("div").Open("div");
  FigureTable(h, c.figures, false);
  h->Close("div").Close("div").Close("div");
}

void ResidualTable(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "keep"}}).Element("h2", "Errors per segment");
  h->Element("p",
             "Per window, |corrected - true|, RMS and largest over the segment's windows; before: the raw "
             "outputs divided by the unit's 25 degC scale factors only.",
             {{"class", "note"}});
  h->Open("table").Open("thead").Open("tr");
  for (const char* title : {"segment", "up", "motion", "windows"}) {
    h->Element("th", title, {{"rowspan", "2"}});
  }
  h->Element("th", "gyro, deg/s", {{"colspan", "3"}}).Element("th", "accelerometer, mg", {{"colspan", "3"}});
  h->Close("tr");
  Row(h, {"RMS before", "RMS after", "max after", "RMS before", "RMS after", "max after"}, "th");
  h->Close("thead").Open("tbody");
  for (const ResidualRow& r : c.residual_table_printed) {
    h->Open("tr", r.segment < 0 ? HtmlAttributes{{"data-key", "residual_all"}} : HtmlAttributes{});
    h->Element("td", r.segment < 0 ? "all" : Count(r.segment)).Element("td", r.up).Element("td", r.motion);
    Num(h, Count(r.windows));
    Num(h, Fmt("%.4f", r.gyro_rms_before_dps));
    Num(h, Fmt("%.5f", r.gyro_rms_dps));
    Num(h, Fmt("%.5f", r.gyro_max_dps));
    if (r.accel_windows == 0) {
      h->Element("td", "specific force not constant", {{"colspan", "3"}, {"class", "note"}});
    } else {
      Num(h, Fmt("%.3f", r.accel_rms_before_mg));
      Num(h, Fmt("%.4f", r.accel_rms_mg));
      Num(h, Fmt("%.4f", r.accel_max_mg));
    }
    h->Close("tr");
  }
  h->Close("tbody").Close("table").Close("div");
  std::string note = "RMS of the normalised errors (1 when the errors are the windows' own noise): gyro " +
                     Fmt("%.2f", c.residuals.normalised_gyro_rms) + ", accelerometer " +
                     Fmt("%.2f", c.residuals.normalised_accel_rms) + ".";
  if (c.residual_rows_omitted > 0) {
    note += " The " + Count(c.residual_rows_omitted) +
            " segments with the smallest errors after correction are not listed (all: every segment).";
  }
  h->Element("p", note, {{"class", "note"}});
}

void NoiseTable(Html* h, const NoiseSection& noise) {
  h->Open("table").Open("thead");
  Row(h, {"axis", "ARW, deg/sqrt(h)", "bias instability, deg/h", "taus fitted"}, "th");
  h->Close("thead").Open("tbody");
  for (const NoiseAxis& a : noise.axes) {
    h->Open("tr").Element("td", "gyro_" + a.axis);
    if (!a.fitted) {
      h->Element("td", "not fitted: " + a.why_not, {{"colspan", "3"}}).Close("tr");
      continue;
    }
    if (a.arw_resolved) {
      Num(h, Fmt("%.3g", a.arw_deg_per_sqrt_hr) + " \xc2\xb1 " + Fmt("%.2g", a.arw_sigma),
          {{"data-figure", "gyro_arw_deg_per_sqrt_hr." + a.axis},
           {"data-value", FormatDouble(a.arw_deg_per_sqrt_hr)}});
    } else {
      Num(h, "not resolved", {{"data-figure", "gyro_arw_deg_per_sqrt_hr." + a.axis}, {"data-value", "nan"}});
    }
    if (a.bias_instability_resolved) {
      Num(h, Fmt("%.3g", a.bias_instability_dph) + " \xc2\xb1 " + Fmt("%.2g", a.bias_instability_sigma),
          {{"data-figure", "gyro_bias_instability_dph." + a.axis},
           {"data-value", FormatDouble(a.bias_instability_dph)}});
    } else {
      Num(h, "not resolved", {{"data-figure", "gyro_bias_instability_dph." + a.axis}, {"data-value", "nan"}});
    }
    Num(h, Count(a.points));
    h->Close("tr");
  }
  h->Close("tbody").Close("table");
}

void Validation(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "keep"}}).Element("h2", "Validation (leave one temperature out)");
  if (c.validation.empty()) {
    h->Element("p", "Not run (imufit fit --validate runs it).", {{"class", "note"}}).Close("div");
    return;
  }
  h->Open("table").Open("thead");
  Row(h,
      {"held-out temperature, degC", "windows", "gyro RMS, deg/s", "gyro max, deg/s", "accel RMS, mg",
       "accel max, mg"},
      "th");
  h->Close("thead").Open("tbody");
  for (const ValidationRow& v : c.validation) {
    h->Open("tr").Element("td", Fmt("%.1f", v.temp_c));
    if (!v.fitted) {
      h->Element("td", "not fitted: " + v.why_not, {{"colspan", "5"}}).Close("tr");
      continue;
    }
    Num(h, Count(v.windows));
    Num(h, Fmt("%.5f", v.gyro_rms_dps));
    Num(h, Fmt("%.5f", v.gyro_max_dps));
    Num(h, Fmt("%.4f", v.accel_rms_mg));
    Num(h, Fmt("%.4f", v.accel_max_mg));
    h->Close("tr");
  }
  h->Close("tbody").Close("table");
  for (const ValidationRow& v : c.validation) {
    if (!v.fitted || !v.order_lowered) continue;
    h->Element("p",
               "Without " + Fmt("%.1f", v.temp_c) + " degC the fold is fitted at temperature order " +
                   Count(v.gyro_temp_order) + " (gyro) / " + Count(v.accel_temp_order) +
                   " (accel): the other temperatures determine no more.",
               {{"class", "note"}});
  }
  h->Close("div");
}

}  // namespace

std::vector<PlotFigure> CertificatePlots(const Certificate& c) {
  std::vector<PlotFigure> figures;
  if (!OneTemperature(c)) {
    for (const CoefficientGroup& g : c.curves) figures.push_back(CoefficientFigure(g));
  }
  figures.push_back(ErrorFigure(c));
  if (c.noise.computed) figures.push_back(AllanFigure(c.noise));
  return figures;
}

std::string CertificateHtml(const Certificate& c) {
  const std::vector<PlotFigure> figures = CertificatePlots(c);
  std::vector<Svg> svgs;
  std::string failure;
  try {
    svgs = DrawSvg(figures);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  const std::string serial = c.serial.empty() ? "(no serial)" : c.serial;
  Html h;
  h.Open("html", {{"lang", "en"}}).Open("head").Void("meta", {{"charset", "utf-8"}});
  h.Element("title", "Calibration certificate " + serial).Style(kStyle);
  h.PageStyle("IMU calibration certificate " + serial,
              c.verdict ? std::string(c.verdict->pass ? "PASS" : "FAIL") + " \xe2\x80\x94 " + c.calibrated_utc
                        : c.calibrated_utc,
              "auto");
  h.Close("head").Open("body");
  Identification(&h, c);
  RunAndSettings(&h, c);
  if (c.verdict) Acceptance(&h, *c.verdict);
  KeyFigures(&h, c);

  // Coefficients against temperature, two to a row (the heading stays with the first row), then
  // the g-sensitivity grid. Figure i of CertificatePlots() is group i; at one temperature there are
  // none, and the errors are figure 0.
  const size_t groups = OneTemperature(c) ? 0 : c.curves.size();
  std::vector<std::vector<size_t>> rows;
  size_t grid = groups;
  for (size_t g = 0; g < groups; ++g) {
    if (c.curves[g].grid) {
      grid = g;
      continue;
    }
    if (rows.empty() || rows.back().size() == 2) rows.emplace_back();
    rows.back().push_back(g);
  }
  const auto plot_row = [&](const std::vector<size_t>& row) {
    h.Open("div", {{"class", "plots2 keep"}});
    for (size_t g : row) Plots(&h, svgs, g, g + 1, "");
    h.Close("div");
  };
  h.Open("div", {{"class", "keep"}}).Element("h2", "Coefficients against temperature");
  if (OneTemperature(c)) {
    h.Element(
        "p",
        "The run was at one temperature" +
            (c.run.temperatures_c.empty() ? std::string() : Fmt(" (%g degC)", c.run.temperatures_c[0])) +
            ": every coefficient is a constant, stated under \"Coefficients at 25 degC\"; there is no "
            "curve to draw.",
        {{"class", "note"}});
  } else {
    h.Element("p",
              "Lines: the fitted polynomial; bands: its 1-sigma (each term's own, correlations not drawn); "
              "circles: each window's own estimate (the coefficient that explains that window, all others as "
              "fitted) with its noise as 1-sigma bars.",
              {{"class", "note"}});
  }
  if (!failure.empty()) {
    Plots(&h, svgs, 0, 0, failure);
  } else if (!rows.empty()) {
    plot_row(rows.front());
  }
  h.Close("div");
  for (size_t r = 1; r < rows.size() && failure.empty(); ++r) plot_row(rows[r]);
  if (grid < groups && failure.empty()) Plots(&h, svgs, grid, grid + 1, "");

  h.Open("div", {{"class", "keep"}}).Element("h2", "Errors before and after correction");
  h.Element("p",
            "Per window, corrected - true for axis x (blue), y (red), z (green); after correction with the "
            "window's noise as bars (1-sigma), before: the raw outputs over the 25 degC scale factors only. "
            "Histogram: gyro (blue), accelerometer (red).",
            {{"class", "note"}});
  Plots(&h, svgs, groups, groups + 1, failure);
  h.Close("div");
  ResidualTable(&h, c);

  h.Open("div", {{"class", "keep"}}).Element("h2", "Gyro noise (Allan deviation, longest static stretch)");
  if (!c.noise.computed) {
    h.Element("p", "Not drawn: " + c.noise.why_not + ".", {{"class", "note"}});
  } else {
    h.Element(
        "p",
        "Segment " + Count(c.noise.segment) + ", " + Fmt("%.0f s", c.noise.duration_s) + " at " +
            Fmt("%.1f degC", c.noise.temp_c) +
            ": the raw outputs over the scale factor at that temperature. Bars: 68 % confidence; "
            "lines: the IEEE 952 fit (solid) and its terms (dashed). ARW is read on the -1/2 line at "
            "\xcf\x84 = 1 s (the large dot), bias instability B at the fit's floor 0.664 B (a diamond).",
        {{"class", "note"}});
    Plots(&h, svgs, groups + 1, groups + 2, failure);
    NoiseTable(&h, c.noise);
  }
  h.Close("div");
  Validation(&h, c);
  h.Element("p",
            "Units: angular rate in deg/s, specific force in mg (1 g = 9.80665 m/s\xc2\xb2); key figures at "
            "25 degC. Coefficient model and file format: docs/spec.md; conversions: docs/factory.md.",
            {{"class", "note"}});
  h.Close("body").Close("html");
  return h.Finish();
}

void WriteCertificate(const std::string& path, const Certificate& certificate,
                      OutputTransaction* transaction) {
  WriteFileAtomically(path, CertificateHtml(certificate), transaction);
}

// ---------------------------------------------------------------- the lot page

namespace {

// The lot page's plots are drawn at the size they print, as the certificate's (kHalfWidthPx two to
// a row, kFullWidthPx across): drawn wider, the browser shrinks them, and their 10 pt labels print at
// 6 pt. Names under a plot: at most this many (more are thinned out), upright when they would not
// fit side by side in the characters of 10 pt text a panel has room for.
constexpr int kMaxCategoryLabels = 24;
constexpr int kHalfWidthChars = 40, kFullWidthChars = 80;
constexpr int kStripHeightPx = 180, kStripUprightHeightPx = 215;  // upright names need more room
constexpr size_t kMaxBarNotes = 24;         // yields printed on their bars up to this many lots
constexpr double kNoteInsideBarPct = 15.0;  // a yield note goes inside its bar from this yield up
const char* kHighlight = "#ff7f0e";         // this lot, an outlier's ring
const char* kFailRed = "#c00000";
// The mean and the 3-sigma lines differ in colour as well as in dash: gnuplot 5.4's SVG terminal
// joins a dotted line to the solid one before it when they share a colour, and draws both solid.
const char* kMeanGrey = "#444444";
const char* kSigmaGrey = "#8a8a8a";

PlotFigure OnePanel(const Plot& plot, int width_px, int height_px) {
  PlotFigure figure = Figure(1, 1, width_px, height_px);
  figure.panels.push_back(plot);
  return figure;
}

// What the limits allow, in words: "|value| < 5", "16.1 .. 16.9", "< 0.05".
std::string LimitsText(const std::optional<LimitInterval>& limits) {
  if (!limits) return "\xe2\x80\x93";
  if (limits->symmetric && limits->upper) return "|value| < " + Fmt("%g", *limits->upper);
  if (limits->lower && limits->upper)
    return Fmt("%.6g", *limits->lower) + " .. " + Fmt("%.6g", *limits->upper);
  return limits->upper ? "< " + Fmt("%g", *limits->upper) : "> " + Fmt("%g", *limits->lower);
}

// Dashed lines at the sides of `limits` in view; the x label notes the sides beyond the scale.
void LimitLines(const std::optional<LimitInterval>& limits, const FigureView& view, Plot* plot) {
  if (!limits) return;
  if (limits->lower && view.lower_in_view)
    plot->markers.push_back({*limits->lower, Fmt("%g", *limits->lower), kFailRed});
  if (limits->upper && view.upper_in_view)
    plot->markers.push_back({*limits->upper, Fmt("%g", *limits->upper), kFailRed});
  // The sides off scale, in words: both ("limit |value| < 5 beyond this scale"), or the one that is
  // not drawn (a symmetric limit with its other side drawn is not "beyond this scale").
  const bool lower_drawn = limits->lower && view.lower_in_view,
             upper_drawn = limits->upper && view.upper_in_view;
  const bool lower_off = limits->lower && !lower_drawn, upper_off = limits->upper && !upper_drawn;
  if (!lower_off && !upper_off) return;
  if (!lower_drawn && !upper_drawn) {
    plot->x_label += "; limit " + LimitsText(limits) + " beyond this scale";
  } else if (upper_off) {
    plot->x_label += "; upper limit " + Fmt("%g", *limits->upper) + " above this scale";
  } else {
    plot->x_label += "; lower limit " + Fmt("%g", *limits->lower) + " below this scale";
  }
}

void NiceY(const FigureView& view, Plot* plot) {
  const AxisScale y = NiceAxis(view.range[0], view.range[1]);
  plot->y_range = std::array<double, 2>{y.lo, y.hi};
  plot->y_tic_step = y.step;
  plot->y_format = y.format;
}

void CategoryX(const std::vector<std::string>& labels, int width_chars, Plot* plot) {
  const CategoryAxis axis = CategoryTics(labels, kMaxCategoryLabels, width_chars);
  plot->x_tics = axis.tics;
  plot->x_tic_rotate_deg = axis.rotate_deg;
  plot->x_range = axis.range;
}

// "gyro_bias_dps.x: Ppk 1.8, Cpk 2.1": the panel is half a page wide, the mean and sigma are in the
// table above it.
std::string StripTitle(const LotFigure& f) {
  std::string title = f.name;
  if (f.ppk) title += Fmt(": Ppk %.3g", *f.ppk);
  if (f.cpk) title += Fmt(f.ppk ? ", Cpk %.3g" : ": Cpk %.3g", *f.cpk);
  return title;
}

// A strip plot of one figure over the lot: a point per unit at its row, the limits, the mean and
// mean -+ 3 sigma; a failed unit as a square (filled when this figure is outside its limits), an
// outlier ringed.
PlotFigure StripFigure(const LotSummary& lot, const LotFigure& f) {
  std::vector<std::string> labels;
  for (const LotUnitRow& r : lot.rows) labels.push_back(r.label);
  Plot plot =
      Panel(StripTitle(f), lot.unit_prefix.empty() ? "unit" : lot.unit_prefix + "\xe2\x80\xa6", f.unit);
  plot.key = false;
  CategoryX(labels, kHalfWidthChars, &plot);
  NiceY(f.view, &plot);
  PlotSeries normal = Series(PlotSeries::Style::kPoints, "", 0, {}, {});
  PlotSeries failed_elsewhere = normal, failed_here = normal, outlier = normal;
  normal.point_size = 0.8;
  failed_elsewhere.color = failed_here.color = kFailRed;
  failed_elsewhere.point_type = 4;  // open square: failed on another criterion
  failed_here.point_type = 5;       // filled square: this figure is outside its limits
  failed_elsewhere.point_size = failed_here.point_size = 1.0;
  outlier.color = kHighlight;
  outlier.point_type = 6;  // a ring around the point
  outlier.point_size = 2.0;
  for (size_t i = 0; i < f.value.size(); ++i) {
    PlotSeries& s = f.outside_limits[i] ? failed_here : f.failed[i] ? failed_elsewhere : normal;
    s.x.push_back(f.row[i]);
    s.y.push_back(f.value[i]);
    if (f.z[i].outlier) {
      outlier.x.push_back(f.row[i]);
      outlier.y.push_back(f.value[i]);
    }
  }
  plot.series = {normal, failed_elsewhere, failed_here, outlier};
  plot.markers.push_back({f.mean, "mean", kMeanGrey, false, 1});
  if (f.stdev > 0.0) {
    plot.markers.push_back({f.three_sigma[0],
                            "\xe2\x88\x92"
                            "3\xcf\x83",
                            kSigmaGrey, false, 3});
    plot.markers.push_back({f.three_sigma[1], "+3\xcf\x83", kSigmaGrey, false, 3});
  }
  LimitLines(f.limits, f.view, &plot);
  return OnePanel(plot, kHalfWidthPx, plot.x_tic_rotate_deg ? kStripUprightHeightPx : kStripHeightPx);
}

// The lots of a results store: their yields as a table and bars, then the key figures' lot means;
// the plots are svgs[first...] (LotHistoryPlots' order).
void AcrossLots(Html* h, const LotHistory& history, const std::vector<Svg>& svgs, size_t first,
                const std::string& failure) {
  h->Open("div", {{"class", "keep"}, {"data-key", "history"}});
  h->Element("h2", "Across lots");
  h->Element("p",
             "Every lot in the results store " + history.store_path +
                 " (each unit by its latest fit), oldest first" +
                 (history.current >= 0 ? "; this lot in orange." : "."),
             {{"class", "note"}});
  h->Open("table").Open("thead");
  Row(h, {"lot", "units", "passed", "failed", "not fitted", "yield"}, "th");
  h->Close("thead").Open("tbody");
  for (size_t i = 0; i < history.lots.size(); ++i) {
    const LotYield& y = history.lots[i];
    HtmlAttributes row = {{"data-history-lot", y.lot}};
    if (static_cast<int>(i) == history.current) row.push_back({"class", "current"});
    h->Open("tr", row).Element("td", y.lot);
    Num(h, Count(y.units));
    Num(h, Count(y.passed));
    Num(h, Count(y.failed));
    Num(h, Count(y.not_fitted));
    Num(h, Fmt("%.1f %%", history.yield_pct[i]), {{"data-yield", FormatDouble(history.yield_pct[i])}});
    h->Close("tr");
  }
  h->Close("tbody").Close("table");
  Plots(h, svgs, first, first + 1, failure);
  h->Close("div");
  h->Element("h3", "Key figures across lots");
  if (history.lots.size() < 2) {
    h->Element("p", "Only this lot is in the results store: there is no other lot to compare it with yet.",
               {{"class", "note"}});
    return;
  }
  Plots(h, svgs, first + 1, svgs.size(), failure, "plots2");
}

// Draws `figures` in one gnuplot run; `failure` says why not.
std::vector<Svg> TryDraw(const std::vector<PlotFigure>& figures, std::string* failure) {
  try {
    return DrawSvg(figures);
  } catch (const std::exception& e) {
    *failure = e.what();
    return {};
  }
}

}  // namespace

std::vector<PlotFigure> LotPlots(const LotSummary& lot) {
  std::vector<PlotFigure> figures;
  for (const LotFigure& f : lot.figures) figures.push_back(StripFigure(lot, f));
  return figures;
}

std::vector<PlotFigure> LotHistoryPlots(const LotHistory& history) {
  std::vector<std::string> names;
  for (const LotYield& y : history.lots) names.push_back(y.lot);
  std::vector<PlotFigure> figures;
  Plot yield = Panel("Yield per lot (units that passed their limits)", "lot", "yield, %");
  yield.key = false;
  CategoryX(names, kFullWidthChars, &yield);
  yield.y_range = std::array<double, 2>{0.0, 100.0};
  yield.y_tic_step = 20.0;
  yield.y_format = "%.0f";
  PlotSeries others = Series(PlotSeries::Style::kBoxes, "", 0, {}, {});
  PlotSeries current = others;
  current.color = kHighlight;
  for (size_t i = 0; i < history.lots.size(); ++i) {
    PlotSeries& s = static_cast<int>(i) == history.current ? current : others;
    s.x.push_back(i);
    s.y.push_back(history.yield_pct[i]);
    if (history.lots.size() <= kMaxBarNotes) {
      PlotNote note;
      note.x = i;
      note.y = history.yield_pct[i];
      note.text = Fmt("%.0f %%", history.yield_pct[i]) + " of " + Count(history.lots[i].units);
      const bool inside = history.yield_pct[i] >= kNoteInsideBarPct;
      note.dy_chars = inside ? -0.9 : 0.7;
      note.color = inside ? "#ffffff" : note.color;
      note.align = PlotNote::Align::kCenter;
      yield.notes.push_back(note);
    }
  }
  yield.series = {others, current};
  figures.push_back(OnePanel(yield, kFullWidthPx, yield.x_tic_rotate_deg ? 260 : 210));
  if (history.lots.size() < 2) return figures;  // one lot: no trend to draw (AcrossLots says so)
  for (const LotTrend& t : history.trends) {
    Plot plot = Panel(t.name + ": lot mean \xc2\xb1 1\xcf\x83", "lot", t.unit);
    plot.key = false;
    CategoryX(names, kHalfWidthChars, &plot);
    NiceY(t.view, &plot);
    PlotSeries lots = Series(PlotSeries::Style::kErrorBars, "", 0, {}, {});
    lots.point_size = 0.8;
    PlotSeries this_lot = lots;
    this_lot.color = kHighlight;
    this_lot.point_size = 1.2;
    for (size_t i = 0; i < t.mean.size(); ++i) {
      if (t.count[i] == 0) continue;
      PlotSeries& s = static_cast<int>(i) == history.current ? this_lot : lots;
      s.x.push_back(i);
      s.y.push_back(t.mean[i]);
      s.error.push_back(t.sigma[i]);
    }
    plot.series = {lots, this_lot};
    LimitLines(t.limits, t.view, &plot);
    figures.push_back(
        OnePanel(plot, kHalfWidthPx, plot.x_tic_rotate_deg ? kStripUprightHeightPx : kStripHeightPx));
  }
  return figures;
}

std::string LotPageHtml(const LotSummary& lot) {
  Html h;
  h.Open("html", {{"lang", "en"}}).Open("head").Void("meta", {{"charset", "utf-8"}});
  h.Element("title", "Lot " + lot.lot).Style(kStyle).PageStyle("Lot " + lot.lot, lot.written_utc, "auto");
  h.Close("head").Open("body");
  h.Open("h1").Text("Lot ").Element("span", lot.lot, {{"data-key", "lot"}});
  h.Text(" \xe2\x80\x94 calibration results").Close("h1");
  h.Open("table");
  h.Open("tr").Element("td", "units").Open("td").Element("span", Count(lot.units), {{"data-key", "units"}});
  h.Close("td").Close("tr");
  h.Open("tr").Element("td", "passed").Open("td");
  h.Element("span", Count(lot.passed), {{"class", "PASS"}, {"data-key", "passed"}}).Close("td").Close("tr");
  h.Open("tr").Element("td", "failed limits").Open("td");
  h.Element("span", Count(lot.failed), {{"class", "FAIL"}, {"data-key", "failed"}}).Close("td").Close("tr");
  Row(&h, {"not fitted / errors", Count(lot.not_fitted) + " / " + Count(lot.errors)});
  h.Open("tr")
      .Element("td", "yield")
      .Open("td")
      .Element("span", Fmt("%.1f", lot.yield_pct), {{"data-key", "yield"}});
  h.Text(" %").Close("td").Close("tr");
  Row(&h, {"acceptance limits", lot.limits_name.empty() ? "none given" : lot.limits_name});
  Row(&h, {"written", lot.written_utc + " by " + lot.software + ", git " + lot.git_revision});
  h.Close("table");

  h.Element("h2", "Units");
  h.Open("table").Open("thead");
  Row(&h, {"unit", "serial", "status", "verdict", "reason"}, "th");
  h.Close("thead").Open("tbody");
  for (const LotUnitRow& u : lot.rows) {
    h.Open("tr", {{"data-unit", u.unit}}).Open("td");
    if (u.has_report) {
      h.Element("a", u.unit, {{"href", u.unit + "/report.html"}});
    } else {
      h.Text(u.unit);
    }
    h.Close("td").Element("td", u.serial).Element("td", u.status);
    h.Element("td", u.verdict, {{"class", u.verdict}}).Element("td", u.message).Close("tr");
  }
  h.Close("tbody").Close("table");

  h.Element("h2", "Outliers");
  h.Element("p",
            "Robust z = 0.6745 (x - median) / MAD beyond " + Fmt("%.1f", kOutlierRobustZ) +
                ", and more than " + Fmt("%.0f", kOutlierOwnSigmas) +
                " of the unit's own 1-sigma from the median (so that noise between identical units is not "
                "flagged). An outlier is not a failure: it says \"look at this unit\".",
            {{"class", "note"}});
  if (lot.outliers.empty()) {
    h.Element("p", "None.");
  } else {
    h.Open("table").Open("thead");
    Row(&h, {"unit", "serial", "figure", "value", "robust z"}, "th");
    h.Close("thead").Open("tbody");
    for (const LotOutlier& o : lot.outliers) {
      h.Open("tr", {{"data-outlier", o.unit}, {"data-figure", o.figure}})
          .Element("td", o.unit)
          .Element("td", o.serial);
      h.Element("td", o.figure);
      Num(&h, Fmt("%.6g", o.value) + " " + o.figure_unit);
      Num(&h, Fmt("%+.1f", o.z));
      h.Close("tr");
    }
    h.Close("tbody").Close("table");
  }

  h.Open("div", {{"class", "keep"}}).Element("h2", "Key figures at 25 degC over the lot");
  h.Element("p",
            "\xcf\x83: the units' standard deviation; \xcf\x83 within: the mean moving range of consecutive "
            "units / 1.128. Ppk = min(upper - mean, mean - lower) / 3\xcf\x83; Cpk the same with \xcf\x83 "
            "within (Cpk well above Ppk: the lot drifts from unit to unit).",
            {{"class", "note"}});
  h.Open("table").Open("thead");
  Row(&h, {"figure", "units", "mean", "\xcf\x83", "\xcf\x83 within", "limits", "Ppk", "Cpk"}, "th");
  h.Close("thead").Open("tbody");
  for (const LotFigure& f : lot.figures) {
    h.Open("tr", {{"data-lot-figure", f.name}}).Element("td", f.name + " (" + f.unit + ")");
    Num(&h, Count(static_cast<long long>(f.value.size())));
    Num(&h, Fmt("%.6g", f.mean), {{"data-mean", FormatDouble(f.mean)}});
    Num(&h, Fmt("%.3g", f.stdev), {{"data-sigma", FormatDouble(f.stdev)}});
    Num(&h, Fmt("%.3g", f.stdev_within));
    Num(&h, LimitsText(f.limits));
    Num(&h, f.ppk ? Fmt("%.2f", *f.ppk) : "\xe2\x80\x93", {{"data-ppk", f.ppk ? FormatDouble(*f.ppk) : ""}});
    Num(&h, f.cpk ? Fmt("%.2f", *f.cpk) : "\xe2\x80\x93", {{"data-cpk", f.cpk ? FormatDouble(*f.cpk) : ""}});
    h.Close("tr");
  }
  h.Close("tbody").Close("table").Close("div");

  std::vector<PlotFigure> figures = LotPlots(lot);
  const size_t strips = figures.size();
  if (lot.history) {
    for (PlotFigure& f : LotHistoryPlots(*lot.history)) figures.push_back(std::move(f));
  }
  std::string failure;
  const std::vector<Svg> svgs = TryDraw(figures, &failure);
  h.Element("h2", "Distributions");
  h.Element("p",
            "One point per fitted unit, in the order of the units table. Red square: the unit failed its "
            "limits (filled: on this figure); orange ring: outlier; grey: the lot's mean (solid) and mean "
            "\xc2\xb1 3\xcf\x83 (dotted); red dashed: the limits.",
            {{"class", "note"}});
  Plots(&h, svgs, 0, strips, failure, "plots2");

  if (lot.history) AcrossLots(&h, *lot.history, svgs, strips, failure);
  h.Close("body").Close("html");
  return h.Finish();
}

std::string LotHistoryHtml(const LotHistory& history) {
  const std::string title = "Lots in " + history.store_path;
  Html h;
  h.Open("html", {{"lang", "en"}}).Open("head").Void("meta", {{"charset", "utf-8"}});
  h.Element("title", title).Style(kStyle).PageStyle(title, "", "auto");
  h.Close("head").Open("body").Element("h1", title);
  std::string failure;
  const std::vector<Svg> svgs = TryDraw(LotHistoryPlots(history), &failure);
  AcrossLots(&h, history, svgs, 0, failure);
  h.Close("body").Close("html");
  return h.Finish();
}

}  // namespace imufit
