// The certificate page: a Certificate (certificate.h) as one self-contained HTML document.
#include "imufit/factory/certificate_page.h"

#include <array>

#include "certificate_budget_page.h"
#include "imufit/factory/report.h"
#include "imufit/io/output_file.h"
#include "imufit/report/allan_plot.h"
#include "imufit/report/html.h"
#include "page.h"

namespace imufit {
namespace {

using internal::Count;
using internal::Figure;
using internal::Fmt;
using internal::kFullWidthPx;
using internal::kHalfWidthPx;
using internal::Num;
using internal::Panel;
using internal::Plots;
using internal::Row;
using internal::Series;

// ---------------------------------------------------------------- certificate plots

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
    // A calibration by hand used no rate table, chamber or reference equipment.
    static const char* const kTableFields[] = {
        "laboratory", "station", "location", "rate table", "chamber", "reference equipment calibrated until"};
    for (size_t i = 0; i < (c.field ? 3 : std::size(kTableFields)); ++i) Row(h, {kTableFields[i], ""});
    h->Close("table").Close("div");
    return;
  }
  const imufit::Station& s = *c.station;
  const auto field = [&](const char* name, const std::string& value, const char* key) {
    if (value.empty()) return;
    h->Open("tr").Element("td", name).Element("td", value, {{"data-key", key}}).Close("tr");
  };
  field("laboratory", s.laboratory, "laboratory");
  field("accreditation", s.accreditation, "accreditation");
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
    const char* v = VerdictName(c.verdict->pass);
    h->Open("p").Element("span", v, {{"class", std::string("badge ") + v}, {"data-key", "verdict"}});
    const std::string criteria = Count(static_cast<long long>(c.verdict->criteria.size()));
    h->Text(" " + c.verdict->limits_name + " \xe2\x80\x94 " +
            (c.verdict->pass ? "all " + criteria + " criteria passed"
                             : Count(c.verdict->Failed()) + " of " + criteria + " criteria failed"));
    h->Close("p");
    // What failed, where the signer looks first (the table below has every criterion).
    if (!c.verdict->pass) {
      h->Element("p", "Failed: " + c.verdict->FailedSummary(/*in_words=*/true) + ".",
                 {{"class", VerdictName(false)}, {"data-key", "failed_criteria"}});
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
  const auto field = [&](const char* name, const std::string& value, const char* key) {
    if (value.empty()) return;
    h->Open("tr").Element("td", name).Element("td", value, {{"data-key", key}}).Close("tr");
  };
  field("certificate number", c.number, "certificate_number");
  field("unit serial", serial, "unit_serial");
  field("product model / part number", c.unit_model, "unit_model");
  field("unit firmware", c.unit_firmware, "unit_firmware");
  if (!c.unit.empty()) Row(h, {"unit folder", c.unit});
  field("customer", c.customer, "customer");
  field("customer's order", c.order, "order");
  field("run recorded (UTC)",
        c.acquired_utc.empty() ? "not stated (no '# acquired:' line in the samples header): dates are judged "
                                 "against the fit's"
                               : c.acquired_utc,
        "acquired_utc");
  field("ambient conditions", c.ambient, "ambient");
  Row(h, {"calibration fitted (UTC)", c.calibrated_utc});
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
  h->Element("p", kItemOnlyStatement, {{"class", "note"}, {"data-key", "item_only"}});
  h->Open("div", {{"class", "keep"}});
  h->Element("h2", "Input files");
  h->Open("table").Open("thead");
  Row(h, {"role", "file", "SHA-256"}, "th");
  h->Close("thead").Open("tbody");
  for (const ReportInput& in : c.inputs) {
    h->Open("tr").Element("td", in.role);
    internal::PathCell(h, in.path);
    h->Element("td", in.sha256, {{"class", "hash"}, {"data-sha256", in.role}}).Close("tr");
  }
  h->Close("tbody").Close("table").Close("div");
}

// The plan and the run: segments, site, samples, windows, temperatures.
void PlanAndRun(Html* h, const Certificate& c) {
  h->Open("div").Element("h2", "Plan and run").Open("table");
  const auto list = [](const std::vector<double>& values) {
    std::string text;
    for (double v : values) text += (text.empty() ? "" : ", ") + Fmt("%g", v);
    return text;
  };
  h->Open("tr").Element("td", "plan");
  internal::PathCell(h, c.run.plan_path);
  h->Close("tr");
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
}

// The solver's outcome for a reader: the fit converged (its tolerances reached) or stopped.
std::string SolverInWords(const FitSettings& s) {
  const std::string iterations = Count(s.iterations) + (s.iterations == 1 ? " iteration" : " iterations");
  if (s.termination.find("tolerance") != std::string::npos) return "converged after " + iterations;
  if (s.termination.find("Maximum number of iterations") != std::string::npos)
    return "stopped at its iteration limit, after " + iterations;
  return "stopped after " + iterations;
}

// How the fit was made and what it says of itself.
void FitSettingsTable(Html* h, const FitSettings& s) {
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
    Row(h, {"solver", SolverInWords(s)});
    Row(h, {"bias stability in the sigmas", s.gyro_bias_stability_dph > 0.0 || s.accel_bias_stability_ug > 0.0
                                                ? Fmt("gyro %g deg/h", s.gyro_bias_stability_dph) +
                                                      Fmt(", accel %g micro-g", s.accel_bias_stability_ug)
                                                : "no (white noise only)"});
  }
  Row(h, {"plan's limiting coefficient", LimitingPredictionText(s.limiting)});
  Row(h, {"trim after each move", Fmt("%g s", s.trim_s)});
  Row(h, {"window temperature span", Fmt("%g degC", s.window_temp_span_c)});
  h->Close("table").Close("div");
}

// The run and the fit's settings side by side.
void RunAndSettings(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "cols"}});
  PlanAndRun(h, c);
  FitSettingsTable(h, c.settings);
  h->Close("div");
}

void Acceptance(Html* h, const Verdict& verdict) {
  h->Element("h2",
             "Acceptance: " + (verdict.limits_name.empty() ? std::string("limits") : verdict.limits_name));
  h->Open("table").Open("thead");
  Row(h, {"criterion", "measured \xc2\xb1 U", "limit", "margin", "verdict"}, "th");
  h->Close("thead").Open("tbody");
  for (const CriterionResult& cr : verdict.criteria) {
    HtmlAttributes row = {{"data-criterion", cr.name}, {"data-pass", cr.pass ? "1" : "0"}};
    if (!cr.pass) row.push_back({"class", "failed"});
    h->Open("tr", row).Element("td", cr.title);
    // A value with its U is printed to U's decimal place, its margin too (a value not in the
    // calibration has no U).
    if (cr.expanded > 0.0) {
      const RoundedValue v = RoundToUncertainty(cr.measured, cr.expanded);
      Num(h, v.value + " \xc2\xb1 " + v.uncertainty + " " + cr.unit);
      Num(h, cr.limit_text);
      Num(h, AtDecimals(cr.margin, v.decimals) + " " + cr.unit);
    } else {
      Num(h, cr.measured_text);
      Num(h, cr.limit_text);
      Num(h, cr.margin_text);
    }
    h->Element("td", OutcomeName(cr.outcome) + (cr.reason.empty() ? std::string() : ": " + cr.reason),
               {{"class", VerdictName(cr.pass)}, {"data-outcome", OutcomeName(cr.outcome)}})
        .Close("tr");
  }
  h->Close("tbody").Close("table");
  internal::DecisionRuleNote(h, verdict);
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
    // Under the sensor's heading: "bias X", "g-sensitivity X from Y".
    std::string title = FigureTitle(f.name);
    for (const char* sensor : {"Gyro ", "Accel "}) {
      if (title.rfind(sensor, 0) == 0) title = title.substr(std::string(sensor).size());
    }
    h->Open("tr").Element("td", title);
    // U to two significant digits, the value and its 1-sigma to U's decimal place (GUM 7.2.6).
    const RoundedValue v = RoundToUncertainty(f.value, f.expanded, f.is_coefficient);
    Num(h, v.value, {{"data-figure", f.name}, {"data-value", FormatDouble(f.value)}});
    Num(h, f.sigma > 0.0 && f.expanded > 0.0 ? AtDecimals(f.sigma, v.decimals + 1)
           : f.sigma >= 0.0                  ? Fmt("%.2g", f.sigma)
                                             : "\xe2\x80\x93");
    Num(h, f.expanded > 0.0 ? v.uncertainty : f.expanded == 0.0 ? "0" : "\xe2\x80\x93");
    h->Element("td", f.extrapolated ? f.unit + ", extrapolated" : f.unit,
               f.extrapolated ? HtmlAttributes{{"data-extrapolated", f.name}} : HtmlAttributes{})
        .Close("tr");
  }
  h->Close("tbody").Close("table");
}

void KeyFigures(Html* h, const Certificate& c) {
  h->Open("div", {{"class", "keep"}});
  h->Element("h2", "Coefficients at 25 degC");
  h->Element("p",
             std::string("1-sigma from the fit's covariance (Type A); U is the expanded uncertainty of the "
                         "budget below (") +
                 (c.field ? "Type A and the local gravity's uncertainty"
                          : "Type A and the station's Type B sources") +
                 ") at k = 2 (about 95 % for a normal distribution).",
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

// A noise figure's cell: "value ± sigma", or an unresolved term's upper bound with its estimate and
// interval (TermFigureText).
void NoiseFigure(Html* h, const std::string& figure, const NoiseTermFigure& term) {
  HtmlAttributes attributes = {{"data-figure", figure},
                               {"data-value", term.resolved ? FormatDouble(term.value) : "nan"}};
  if (!term.resolved) attributes.push_back({"data-at-most", FormatDouble(term.upper())});
  Num(h, TermFigureText(term, "", "\xc2\xb1"), attributes);
}

void NoiseTable(Html* h, const NoiseSection& noise) {
  h->Open("table").Open("thead");
  Row(h, {"axis", "ARW, deg/sqrt(h)", "bias instability, deg/h", "taus fitted"}, "th");
  h->Close("thead").Open("tbody");
  bool unresolved = false;
  for (const NoiseAxis& a : noise.axes) {
    h->Open("tr").Element("td", "gyro_" + a.axis);
    if (!a.fitted) {
      h->Element("td", "not fitted: " + a.why_not, {{"colspan", "3"}}).Close("tr");
      continue;
    }
    NoiseFigure(h, "gyro_arw_deg_per_sqrt_hr." + a.axis, a.arw_deg_per_sqrt_hr);
    NoiseFigure(h, "gyro_bias_instability_dph." + a.axis, a.bias_instability_dph);
    unresolved = unresolved || !a.arw_deg_per_sqrt_hr.resolved || !a.bias_instability_dph.resolved;
    Num(h, Count(a.points));
    h->Close("tr");
  }
  h->Close("tbody").Close("table");
  if (unresolved) {
    h->Element(
        "p",
        "A term this run does not resolve (its variance coefficient within 2 standard uncertainties of "
        "0) is given by its estimate and interval, estimate \xc2\xb1 2 sigma with the lower bound "
        "clipped at 0: on a data sheet quote the upper bound, as \"at most\", not the estimate.",
        {{"class", "note"}});
  }
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

// ---------------------------------------------------------------- the page, by stages

// The certificate's plots, drawn in one gnuplot run.
struct CertificateSvgs {
  std::vector<Svg> coefficients;  // per figure of CertificateFigures::coefficients
  Svg errors;
  std::optional<Svg> allan;
  std::string failure;  // why nothing was drawn
};

CertificateSvgs Draw(const CertificateFigures& figures) {
  CertificateSvgs svgs;
  svgs.coefficients.resize(figures.coefficients.size());
  std::vector<internal::DrawSlot> slots;
  for (size_t g = 0; g < figures.coefficients.size(); ++g) {
    slots.push_back({&figures.coefficients[g], &svgs.coefficients[g]});
  }
  slots.push_back({&figures.errors, &svgs.errors});
  if (figures.allan) slots.push_back({&*figures.allan, &svgs.allan.emplace()});
  svgs.failure = internal::DrawInto(slots);
  return svgs;
}

// Coefficients against temperature, two to a row (the heading stays with the first row), then the
// g-sensitivity grid. At one temperature there are none.
void CoefficientPlots(Html* h, const Certificate& c, const CertificateSvgs& svgs) {
  std::vector<std::vector<Svg>> rows;
  const Svg* grid = nullptr;
  for (size_t g = 0; g < svgs.coefficients.size(); ++g) {
    if (c.curves[g].grid) {
      grid = &svgs.coefficients[g];
      continue;
    }
    if (rows.empty() || rows.back().size() == 2) rows.emplace_back();
    rows.back().push_back(svgs.coefficients[g]);
  }
  const auto plot_row = [&](const std::vector<Svg>& row) {
    h->Open("div", {{"class", "plots2 keep"}});
    Plots(h, row, "");
    h->Close("div");
  };
  h->Open("div", {{"class", "keep"}}).Element("h2", "Coefficients against temperature");
  if (OneTemperature(c)) {
    h->Element(
        "p",
        "The run was at one temperature" +
            (c.run.temperatures_c.empty() ? std::string() : Fmt(" (%g degC)", c.run.temperatures_c[0])) +
            ": every coefficient is a constant, stated under \"Coefficients at 25 degC\"; there is no "
            "curve to draw.",
        {{"class", "note"}});
  } else {
    h->Element(
        "p",
        "Lines: the fitted polynomial; bands: its 1-sigma (each term's own, correlations not drawn); "
        "circles: each window's own estimate (the coefficient that explains that window, all others as "
        "fitted) with its noise as 1-sigma bars.",
        {{"class", "note"}});
  }
  if (!svgs.failure.empty()) {
    Plots(h, {}, svgs.failure);
  } else if (!rows.empty()) {
    plot_row(rows.front());
  }
  h->Close("div");
  if (!svgs.failure.empty()) return;
  for (size_t r = 1; r < rows.size(); ++r) plot_row(rows[r]);
  if (grid != nullptr) Plots(h, {*grid}, "");
}

void ErrorPlots(Html* h, const Certificate& c, const CertificateSvgs& svgs) {
  h->Open("div", {{"class", "keep"}}).Element("h2", "Errors before and after correction");
  h->Element("p",
             "Per window, corrected - true for axis x (blue), y (red), z (green); after correction with the "
             "window's noise as bars (1-sigma), before: the raw outputs over the 25 degC scale factors only. "
             "Histogram: gyro (blue), accelerometer (red).",
             {{"class", "note"}});
  Plots(h, {svgs.errors}, svgs.failure);
  h->Close("div");
  ResidualTable(h, c);
}

void NoisePlot(Html* h, const Certificate& c, const CertificateSvgs& svgs) {
  h->Open("div", {{"class", "keep"}}).Element("h2", "Gyro noise (Allan deviation of a static stretch)");
  if (!c.noise.computed) {
    h->Element("p", "Not drawn: " + c.noise.why_not + ".", {{"class", "note"}});
  } else {
    h->Element(
        "p",
        "Measured on segment " + Count(c.noise.segment) + ", " + Fmt("%.0f s", c.noise.duration_s) + " at " +
            Fmt("%.1f degC", c.noise.temp_c) + " (" + c.noise.chosen +
            "; another: --noise-segment): the raw outputs over the scale factor at that temperature. Bars: "
            "68 % "
            "confidence; "
            "lines: the IEEE 952 fit (solid) and its terms (dashed). ARW is read on the -1/2 line at "
            "\xcf\x84 = 1 s (the large dot), bias instability B at the fit's floor 0.664 B (a diamond).",
        {{"class", "note"}});
    Plots(h, {*svgs.allan}, svgs.failure);
    NoiseTable(h, c.noise);
  }
  h->Close("div");
}

}  // namespace

CertificateFigures MakeCertificateFigures(const Certificate& c) {
  CertificateFigures figures;
  if (!OneTemperature(c)) {
    for (const CoefficientGroup& g : c.curves) figures.coefficients.push_back(CoefficientFigure(g));
  }
  figures.errors = ErrorFigure(c);
  if (c.noise.computed) figures.allan = AllanFigure(c.noise);
  return figures;
}

std::vector<PlotFigure> CertificatePlots(const Certificate& c) {
  CertificateFigures figures = MakeCertificateFigures(c);
  std::vector<PlotFigure> in_page_order = std::move(figures.coefficients);
  in_page_order.push_back(std::move(figures.errors));
  if (figures.allan) in_page_order.push_back(std::move(*figures.allan));
  return in_page_order;
}

// A calibration by hand: what it was referred to, and the session in place of the plan and the run.
void FieldSessionSection(Html* h, const Certificate& c) {
  const FieldSession& f = *c.field;
  h->Element("h2", "Calibration by hand: references");
  h->Element("p", kFieldReferenceStatement, {{"data-key", "field_reference"}});
  h->Open("div", {{"class", "cols"}});
  h->Open("div").Element("h2", "Session").Open("table");
  const auto row = [&](const std::string& name, const std::string& value, const char* key) {
    h->Open("tr").Element("td", name).Element("td", value, {{"data-key", key}}).Close("tr");
  };
  const auto known = [](double v, const std::string& text) {
    return v < 0.0 ? std::string("not recorded") : text;
  };
  row("body frame", f.body_frame, "body_frame");
  row("poses at rest", f.poses < 0 ? "not recorded" : Count(f.poses), "field_poses");
  row("turns between them", f.turns < 0 ? "not recorded" : Count(f.turns), "field_turns");
  row("turns left out (gyro at its converter's limit)",
      f.saturated_turns < 0 ? "not recorded" : Count(f.saturated_turns), "field_saturated_turns");
  row("samples read", f.samples < 0 ? "not recorded" : Count(f.samples), "field_samples");
  row("temperature range", Fmt("%.1f", f.temp_range_c[0]) + " .. " + Fmt("%.1f", f.temp_range_c[1]) + " degC",
      "temp_range_c");
  std::string gravity = Fmt("%.6g m/s\xc2\xb2", f.gravity_mps2);
  if (f.gravity_source == kGravityStated) gravity += ", stated (--gravity-mps2)";
  if (f.gravity_source == kGravityStandard) gravity += ", standard gravity (no local gravity given)";
  if (f.gravity_source == kGravityFromLatitude) {
    gravity += ", WGS-84 normal gravity at " + Fmt("%.4f deg", f.latitude_deg.value_or(0.0)) + ", " +
               Fmt("%g m", f.height_m.value_or(0.0));
  }
  if (f.gravity_source.empty()) gravity += " (its source not recorded)";
  row("local gravity", gravity, "field_gravity");
  h->Close("table").Close("div");
  h->Open("div").Element("h2", "Fit").Open("table");
  row("|a| \xe2\x88\x92 g after correction, RMS over the poses",
      known(f.accel_norm_rms_mg, Fmt("%.3g mg", f.accel_norm_rms_mg)), "field_accel_norm_rms_mg");
  row("gravity direction after the turns, RMS",
      known(f.direction_rms_deg, Fmt("%.3g deg", f.direction_rms_deg)), "field_direction_rms_deg");
  row("gyro at rest after correction, RMS",
      known(f.gyro_static_rms_dps, Fmt("%.3g deg/s", f.gyro_static_rms_dps)), "field_gyro_static_rms_dps");
  row("reduced chi-square", known(f.reduced_chi2, Fmt("%.3g", f.reduced_chi2)), "field_reduced_chi2");
  row("noise scales (accel at rest, gyro at rest, turns)",
      known(f.noise_scale[0], Fmt("%.3g", f.noise_scale[0]) + ", " + Fmt("%.3g", f.noise_scale[1]) + ", " +
                                  Fmt("%.3g", f.noise_scale[2])),
      "field_noise_scales");
  row("temperature order (biases, scale factors)",
      f.temp_order == 0 ? "0: constant over the session" : Count(f.temp_order), "field_temp_order");
  row("gyro g-sensitivity", f.g_sensitivity_fitted ? "fitted" : "held at 0", "field_g_sensitivity");
  row("solver",
      f.termination.empty() ? "not recorded" : f.termination + " (" + Count(f.iterations) + " iterations)",
      "field_solver");
  h->Close("table").Close("div").Close("div");
  h->Element(
      "p",
      "Noise scales: each residual group's scatter as a multiple of the log's white noise; above 1 the "
      "fit weighted the group by its larger scatter (hand tremor, drift), so the sigmas include it.",
      {{"class", "note"}});
}

std::string CertificateHtml(const Certificate& c) {
  const std::string serial = c.serial.empty() ? "(no serial)" : c.serial;
  Html h;
  internal::OpenPage(
      &h, "Calibration certificate " + serial,
      std::string(c.field ? "IMU calibration certificate (by hand) " : "IMU calibration certificate ") +
          serial,
      (c.verdict ? std::string(VerdictName(c.verdict->pass)) + " \xe2\x80\x94 " : std::string()) +
          "certificate " + c.number + ", " + (c.acquired_utc.empty() ? c.calibrated_utc : c.acquired_utc));
  Identification(&h, c);
  if (c.field) {
    FieldSessionSection(&h, c);
  } else {
    RunAndSettings(&h, c);
  }
  if (c.verdict) Acceptance(&h, *c.verdict);
  KeyFigures(&h, c);
  internal::BudgetSection(&h, c);
  if (c.field) {
    // A session by hand: no plan segments, window errors or static stretch to draw.
    h.Open("div", {{"class", "keep"}}).Element("h2", "Gyro noise");
    h.Element("p", "Not measured: " + c.noise.why_not + ".",
              {{"class", "note"}, {"data-key", "noise_not_measured"}});
    h.Close("div");
  } else {
    const CertificateSvgs svgs = Draw(MakeCertificateFigures(c));
    CoefficientPlots(&h, c, svgs);
    ErrorPlots(&h, c, svgs);
    NoisePlot(&h, c, svgs);
    Validation(&h, c);
  }
  h.Element("p",
            "Units: angular rate in deg/s, specific force in mg (1 g = 9.80665 m/s\xc2\xb2); coefficients at "
            "25 degC. Each value is rounded to the decimal place of its expanded uncertainty U (two "
            "significant digits).",
            {{"class", "note"}});
  return internal::ClosePage(&h);
}

}  // namespace imufit
