// What the documents of factory share (certificate_page.cc, lot_page.cc, history_page.cc): the
// page's frame and style, table cells, plots built and drawn by name, and the lot pages' plot
// pieces. Numbers are formatted by FormatNumber() (report.h).
#ifndef IMUFIT_FACTORY_SRC_PAGE_H_
#define IMUFIT_FACTORY_SRC_PAGE_H_

#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/history_page.h"
#include "imufit/factory/lot_history.h"
#include "imufit/report/html.h"
#include "imufit/report/plot.h"

namespace imufit::internal {

// ---------------------------------------------------------------- every page

std::string Fmt(const char* format, double value);  // FormatNumber()
std::string Count(long long value);
// A yield as every page prints it, in its tables and on its bars: "66.7 %".
std::string YieldText(double pct);

// <html><head> with `title`, the style and a running header (left, right), then <body>.
void OpenPage(Html* h, const std::string& title, const std::string& header_left,
              const std::string& header_right);
// </body></html>, and the document.
std::string ClosePage(Html* h);

// A table row of cells (each text escaped).
void Row(Html* h, std::initializer_list<std::string> cells, const char* tag = "td");
// A path as a page prints it: at most kMostPathChars characters, the leading folders replaced by
// "\xe2\x80\xa6/" (whole folder names only: a name is never cut; a file name longer than that is
// printed whole).
inline constexpr size_t kMostPathChars = 56;
std::string ShortPath(const std::string& path);
// A table cell of a path: ShortPath(), breakable after each '/' (a zero-width space); the whole path in
// data-path.
void PathCell(Html* h, const std::string& path);
// A number's cell (right-aligned, tabular figures).
void Num(Html* h, const std::string& text, const HtmlAttributes& attributes = {});

// ---------------------------------------------------------------- plots

// Figure widths in CSS pixels at print (A4 less its margins is about 695 px, Letter 718 px): drawn
// at the size they are printed, so gnuplot's 10 pt labels stay 10 pt on paper.
inline constexpr int kFullWidthPx = 700;
inline constexpr int kHalfWidthPx = 345;

PlotFigure Figure(int rows, int cols, int width_px, int height_px);
PlotFigure OnePanel(const Plot& plot, int width_px, int height_px);
Plot Panel(const std::string& title, const std::string& x_label, const std::string& y_label);
PlotSeries Series(PlotSeries::Style style, const std::string& title, int color, const std::vector<double>& x,
                  const std::vector<double>& y);

// A figure of a page and where its drawing goes.
struct DrawSlot {
  const PlotFigure* figure;
  Svg* svg;
};
// Draws the figures of `slots` in one gnuplot run, each into its slot; returns why they were not
// drawn ("" when they were).
std::string DrawInto(const std::vector<DrawSlot>& slots);

// The drawn plots, each in its own div (all in a div of class `layout` when given), or, when
// `failure` says why they were not drawn, a note saying so.
void Plots(Html* h, const std::vector<Svg>& svgs, const std::string& failure, const char* layout = nullptr);

// ---------------------------------------------------------------- the lot pages' plots

// The lot pages' plots are drawn at the size they print, as the certificate's (kHalfWidthPx two to
// a row, kFullWidthPx across): drawn wider, the browser shrinks them, and their 10 pt labels print at
// 6 pt. Names under a plot: at most this many (more are thinned out), upright when they would not
// fit side by side in the characters of 10 pt text a panel has room for.
inline constexpr int kMaxCategoryLabels = 24;
inline constexpr int kHalfWidthChars = 40, kFullWidthChars = 80;
inline constexpr int kStripHeightPx = 180, kStripUprightHeightPx = 215;  // upright names need more room
inline constexpr const char* kHighlight = "#ff7f0e";                     // this lot, an outlier's ring
inline constexpr const char* kFailRed = "#c00000";

// What the limits allow, in words: "|value| < 5", "16.1 .. 16.9", "< 0.05".
std::string LimitsText(const std::optional<LimitInterval>& limits);
// Dashed lines at the sides of `limits` in view; the x label notes the sides beyond the scale.
void LimitLines(const std::optional<LimitInterval>& limits, const FigureView& view, Plot* plot);
// The y axis of `view`, in whole steps.
void NiceY(const FigureView& view, Plot* plot);
// An x axis of categories named `labels`, fitting `width_chars` characters.
void CategoryX(const std::vector<std::string>& labels, int width_chars, Plot* plot);

// ---------------------------------------------------------------- the lots across the store

// The history page's drawn plots (history_page.cc); `slots` gains theirs.
struct LotHistorySvgs {
  Svg yield;
  std::vector<Svg> trends;
};
void AddSlots(const LotHistoryFigures& figures, LotHistorySvgs* svgs, std::vector<DrawSlot>* slots);
// The lots of a results store: their yields as a table and bars, then the key figures' lot means
// (also on the lot page); `failure` says why the plots were not drawn.
void AcrossLots(Html* h, const LotHistory& history, const LotHistorySvgs& svgs, const std::string& failure);

}  // namespace imufit::internal

#endif  // IMUFIT_FACTORY_SRC_PAGE_H_
