// The lot page: a LotSummary (lot_summary.h) as one self-contained HTML document, with the lots of
// the results store across lots when the batch had one (history_page.cc's section).
#include "imufit/factory/lot_page.h"

#include <cmath>

#include "imufit/factory/history_page.h"
#include "imufit/io/output_file.h"
#include "page.h"

namespace imufit {
namespace {

using internal::CategoryX;
using internal::Count;
using internal::Fmt;
using internal::kFailRed;
using internal::kHalfWidthChars;
using internal::kHighlight;
using internal::kStripHeightPx;
using internal::kStripUprightHeightPx;
using internal::LimitsText;
using internal::Num;
using internal::Panel;
using internal::Row;
using internal::Series;

// The mean and the 3-sigma lines differ in colour as well as in dash: gnuplot 5.4's SVG terminal
// joins a dotted line to the solid one before it when they share a colour, and draws both solid.
const char* kMeanGrey = "#444444";
const char* kSigmaGrey = "#8a8a8a";

// "gyro_bias_dps.x: Ppk 1.8, Cpk 2.1 (n = 5, indicative)": the panel is half a page wide, the mean,
// sigma and Ppk's interval are in the table above it.
std::string StripTitle(const LotFigure& f) {
  std::string title = f.name;
  if (f.ppk) title += Fmt(": Ppk %.3g", *f.ppk);
  if (f.cpk) title += Fmt(f.ppk ? ", Cpk %.3g" : ": Cpk %.3g", *f.cpk);
  if ((f.ppk || f.cpk) && f.few_units)
    title += " (n = " + Count(static_cast<long long>(f.value.size())) + ", indicative)";
  return title;
}

// A capability's cell: "1.80", below kCapabilityMinUnits with Ppk's interval "1.80 (0.95 .. 2.65)".
std::string CapabilityText(const std::optional<double>& value,
                           const std::optional<std::array<double, 2>>& interval) {
  if (!value) return "\xe2\x80\x93";
  std::string text = Fmt("%.2f", *value);
  if (interval) text += " (" + Fmt("%.2f", (*interval)[0]) + " .. " + Fmt("%.2f", (*interval)[1]) + ")";
  return text;
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
  internal::NiceY(f.view, &plot);
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
  internal::LimitLines(f.limits, f.view, &plot);
  const int height_px = plot.x_tic_rotate_deg ? kStripUprightHeightPx : kStripHeightPx;
  SpreadMarkerLabels(height_px, &plot);
  return internal::OnePanel(plot, internal::kHalfWidthPx, height_px);
}

// ---------------------------------------------------------------- the page, by stages

// The lot in numbers: units, passed, failed, yield, limits, who wrote the page.
void Summary(Html* h, const LotSummary& lot) {
  h->Open("h1").Text("Lot ").Element("span", lot.lot, {{"data-key", "lot"}});
  h->Text(" \xe2\x80\x94 calibration results").Close("h1");
  h->Open("table");
  h->Open("tr").Element("td", "units").Open("td").Element("span", Count(lot.units), {{"data-key", "units"}});
  h->Close("td").Close("tr");
  h->Open("tr").Element("td", "passed").Open("td");
  h->Element("span", Count(lot.passed), {{"class", VerdictName(true)}, {"data-key", "passed"}})
      .Close("td")
      .Close("tr");
  h->Open("tr").Element("td", "failed limits").Open("td");
  h->Element("span", Count(lot.failed), {{"class", VerdictName(false)}, {"data-key", "failed"}})
      .Close("td")
      .Close("tr");
  Row(h, {"not fitted / errors", Count(lot.not_fitted) + " / " + Count(lot.errors)});
  h->Open("tr").Element("td", "yield").Open("td");
  if (std::isfinite(lot.yield_pct)) {
    h->Element("span", Fmt("%.1f", lot.yield_pct), {{"data-key", "yield"}}).Text(" %");
  } else {
    h->Element("span", "not judged (no acceptance limits)", {{"data-key", "yield"}});
  }
  h->Close("td").Close("tr");
  Row(h, {"acceptance limits", lot.limits_name.empty() ? "none given" : lot.limits_name});
  if (!lot.decision_rule.empty()) Row(h, {"decision rule", lot.decision_rule});
  Row(h, {"written", lot.written_utc + " by " + lot.software + ", git " + lot.git_revision});
  h->Close("table");
}

// Every unit: its status, verdict and why; a link to its certificate when it has one.
void Units(Html* h, const LotSummary& lot) {
  h->Element("h2", "Units");
  h->Open("table").Open("thead");
  Row(h, {"unit", "serial", "status", "verdict", "reason"}, "th");
  h->Close("thead").Open("tbody");
  for (const LotUnitRow& u : lot.rows) {
    h->Open("tr", {{"data-unit", u.unit}}).Open("td");
    if (u.has_report) {
      h->Element("a", u.unit, {{"href", u.unit + "/report.html"}});
    } else {
      h->Text(u.unit);
    }
    h->Close("td").Element("td", u.serial).Element("td", u.status);
    h->Element("td", u.verdict, {{"class", u.verdict}}).Element("td", u.message).Close("tr");
  }
  h->Close("tbody").Close("table");
}

// The units whose key figures lie far from the lot's.
void Outliers(Html* h, const LotSummary& lot) {
  h->Element("h2", "Outliers");
  h->Element("p",
             "Robust z = 0.6745 (x - median) / MAD beyond " + Fmt("%.1f", kOutlierRobustZ) +
                 ", and more than " + Fmt("%.0f", kOutlierOwnSigmas) +
                 " of the unit's own 1-sigma from the median (so that noise between identical units is not "
                 "flagged). An outlier is not a failure: it says \"look at this unit\".",
             {{"class", "note"}});
  if (lot.outliers.empty()) {
    h->Element("p", "None.");
  } else {
    h->Open("table").Open("thead");
    Row(h, {"unit", "serial", "figure", "value", "robust z"}, "th");
    h->Close("thead").Open("tbody");
    for (const LotOutlier& o : lot.outliers) {
      h->Open("tr", {{"data-outlier", o.unit}, {"data-figure", o.figure}})
          .Element("td", o.unit)
          .Element("td", o.serial);
      h->Element("td", o.figure);
      Num(h, Fmt("%.6g", o.value) + " " + o.figure_unit);
      Num(h, Fmt("%+.1f", o.z));
      h->Close("tr");
    }
    h->Close("tbody").Close("table");
  }
}

// Per key figure: mean, sigma, sigma within, limits, Ppk, Cpk.
void KeyFigureTable(Html* h, const LotSummary& lot) {
  h->Open("div", {{"class", "keep"}}).Element("h2", "Key figures at 25 degC over the lot");
  h->Element("p",
             "\xcf\x83: the units' standard deviation; \xcf\x83 within: the mean moving range of consecutive "
             "units / 1.128. Ppk = min(upper - mean, mean - lower) / 3\xcf\x83; Cpk the same with \xcf\x83 "
             "within (Cpk well above Ppk: the lot drifts from unit to unit). From fewer than " +
                 Count(kCapabilityMinUnits) + " units both are indicative only: Ppk is given with its " +
                 Fmt("%.0f", 100.0 * kCapabilityConfidence) +
                 " % confidence interval, which is wide for a small lot. Every key figure, each unit's "
                 "value, 1-sigma and U, is in lot_summary.csv.",
             {{"class", "note"}});
  h->Open("table").Open("thead");
  Row(h, {"figure", "units (n)", "mean", "\xcf\x83", "\xcf\x83 within", "limits", "Ppk", "Cpk"}, "th");
  h->Close("thead").Open("tbody");
  for (const LotFigure& f : lot.figures) {
    h->Open("tr", {{"data-lot-figure", f.name}}).Element("td", f.name + " (" + f.unit + ")");
    Num(h, Count(static_cast<long long>(f.value.size())));
    Num(h, Fmt("%.6g", f.mean), {{"data-mean", FormatDouble(f.mean)}});
    Num(h, Fmt("%.3g", f.stdev), {{"data-sigma", FormatDouble(f.stdev)}});
    Num(h, Fmt("%.3g", f.stdev_within));
    Num(h, LimitsText(f.limits));
    Num(h, CapabilityText(f.ppk, f.few_units ? f.ppk_interval : std::nullopt),
        {{"data-ppk", f.ppk ? FormatDouble(*f.ppk) : ""}});
    Num(h, CapabilityText(f.cpk, std::nullopt), {{"data-cpk", f.cpk ? FormatDouble(*f.cpk) : ""}});
    h->Close("tr");
  }
  h->Close("tbody").Close("table").Close("div");
}

// The lot page's plots, drawn in one gnuplot run: the strips, then the history's.
struct LotPageSvgs {
  std::vector<Svg> strips;  // per LotSummary::figures
  internal::LotHistorySvgs history;
  std::string failure;  // why nothing was drawn
};

LotPageSvgs Draw(const std::vector<PlotFigure>& strips, const std::optional<LotHistoryFigures>& history) {
  LotPageSvgs svgs;
  svgs.strips.resize(strips.size());
  std::vector<internal::DrawSlot> slots;
  for (size_t i = 0; i < strips.size(); ++i) slots.push_back({&strips[i], &svgs.strips[i]});
  if (history) internal::AddSlots(*history, &svgs.history, &slots);
  svgs.failure = internal::DrawInto(slots);
  return svgs;
}

void Distributions(Html* h, const LotPageSvgs& svgs) {
  h->Element("h2", "Distributions");
  h->Element("p",
             "Every key figure in the table above on which a unit failed, and the main ones. One point per "
             "fitted unit, in the order of the units table. Red square: the unit failed its "
             "limits (filled: on this figure); orange ring: outlier; grey: the lot's mean (solid) and mean "
             "\xc2\xb1 3\xcf\x83 (dotted); red dashed: the limits.",
             {{"class", "note"}});
  internal::Plots(h, svgs.strips, svgs.failure, "plots2");
}

}  // namespace

std::vector<PlotFigure> LotPlots(const LotSummary& lot) {
  std::vector<PlotFigure> figures;
  for (const LotFigure& f : lot.figures) {
    if (f.plotted) figures.push_back(StripFigure(lot, f));
  }
  return figures;
}

std::string LotPageHtml(const LotSummary& lot) {
  std::optional<LotHistoryFigures> history;
  if (lot.history) history = MakeLotHistoryFigures(*lot.history);
  const LotPageSvgs svgs = Draw(LotPlots(lot), history);
  Html h;
  internal::OpenPage(&h, "Lot " + lot.lot, "Lot " + lot.lot, lot.written_utc);
  Summary(&h, lot);
  Units(&h, lot);
  Outliers(&h, lot);
  KeyFigureTable(&h, lot);
  Distributions(&h, svgs);
  if (lot.history) internal::AcrossLots(&h, *lot.history, svgs.history, svgs.failure);
  return internal::ClosePage(&h);
}

}  // namespace imufit
