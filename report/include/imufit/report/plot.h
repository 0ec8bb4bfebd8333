// imufit — the one plotting module: plots described as data (series of points, lines, bands and
// error bars, limit lines, labels; a figure is a grid of such panels), drawn by gnuplot. `imufit
// allan --plot`, the certificate and the lot page all draw through it, so every plot of imufit
// looks alike and a test can check what a plot holds without reading SVG.
//
// Drawing needs gnuplot on PATH (Debian: gnuplot-nox). DrawSvg() runs it once for many figures
// and returns inline SVG (for self-contained HTML); DrawFile() writes one figure as .svg or .png,
// atomically. Both throw std::runtime_error when gnuplot is missing or fails.
#ifndef IMUFIT_REPORT_PLOT_H_
#define IMUFIT_REPORT_PLOT_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/io/output_file.h"

namespace imufit {

// A qualitative palette (Tableau 10), readable in print and for most colour-blind readers.
const char* PlotColor(int index);

struct PlotSeries {
  // kBoxes: bars from 0 to y, 0.7 x units wide (categories at x = 0, 1, 2, ...).
  enum class Style { kLines, kPoints, kLinesPoints, kBand, kErrorBars, kBoxes };
  Style style = Style::kLines;
  std::string title;  // "" leaves the series out of the key
  std::string color = "#1f77b4";
  std::vector<double> x, y;
  std::vector<double> lo, hi;  // kBand (y unused) and kErrorBars: the interval at each x
  std::vector<double> error;   // kErrorBars instead of lo, hi: y +- error
  double line_width = 1.5;
  bool dashed = false;
  int point_type = 7;  // gnuplot's: 7 filled circle, 5 filled square, 9 filled triangle, 6 open circle
  double point_size = 0.6;
};

// A straight line across the panel at `value` (horizontal: a y value; vertical: an x value), e.g.
// an acceptance limit, labelled at its end.
struct PlotMarker {
  double value = 0.0;
  std::string label;
  std::string color = "#b00000";
  bool vertical = false;
  int dash_type = 2;  // gnuplot's: 1 solid, 2 dashed, 3 dotted
  std::optional<double> label_at =
      std::nullopt;  // where the label sits (SpreadMarkerLabels()); nullopt: at `value`
};

// A line of text inside the panel; labels stack from the top left (or the bottom left).
struct PlotLabel {
  std::string text;
};

// A tick mark of the x axis with its own text (a unit's or a lot's name at its category).
struct PlotTic {
  double value = 0.0;
  std::string label;
};

// Text at a point of the data (a value read off a curve, a bar's height), with a point drawn there
// when point_type >= 0. The text starts at the point (is centred on it, ends there), moved by
// character widths and heights, so that notes stack without knowing the axes' scales.
struct PlotNote {
  enum class Align { kLeft, kCenter, kRight };
  double x = 0.0, y = 0.0;  // data coordinates
  std::string text;
  std::string color = "#222222";
  double dx_chars = 0.0, dy_chars = 0.0;
  Align align = Align::kLeft;
  int point_type = -1;
  double point_size = 1.0;
  bool opaque = false;  // the text on a white ground, over the lines behind it
};

struct Plot {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  bool y_tics = true;
  bool key = true;
  bool key_above = false;  // the key in one row above the panel instead of at its right (narrow panels)
  // At most this many tick labels on a linear axis (0 or 1: gnuplot's choice, which does not look at
  // the panel's size): the step is 1, 2, 2.5 or 5 times a power of ten, the axis ends with the data.
  int max_x_tics = 0, max_y_tics = 0;
  bool y_from_zero = false;  // the y axis starts at 0 (counts)
  bool labels_at_bottom = false;
  std::optional<std::array<double, 2>> x_range, y_range;
  std::vector<PlotSeries> series;
  std::vector<PlotMarker> markers;
  std::vector<PlotLabel> labels;
  // A linear y axis: tick marks every y_tic_step from the range's start, printed with y_format
  // (printf, e.g. "%.4f"); 0 and "" leave them to gnuplot. NiceAxis() picks range, step and format.
  double y_tic_step = 0.0;
  std::string y_format;
  std::vector<PlotTic> x_tics;  // replace gnuplot's x tick marks; empty: gnuplot's own
  int x_tic_rotate_deg = 0;     // 90: labels read bottom to top (many or long labels)
  std::vector<PlotNote> notes;
};

// Text of 10 pt is this tall on a panel; a panel's plotting area is at least this share of its
// height (the rest: title, tick labels and axis label).
inline constexpr double kLabelHeightPx = 14.0;
inline constexpr double kPlotAreaShare = 0.6;
// The least distance, in y data units, between the labels of two horizontal markers of `plot`
// (whose y_range is set) in a panel `height_px` high.
double MarkerLabelGap(const Plot& plot, int height_px);
// Moves the labels of `plot`'s horizontal markers apart (label_at) so that no two are closer than
// MarkerLabelGap(): a limit's label never sits on the mean's or 3 sigma's. The lines stay where they are.
void SpreadMarkerLabels(int height_px, Plot* plot);

// A linear axis that shows [lo, hi] with 3 % to spare each side: widened to whole steps of 1, 2 or
// 5 x 10^k, about `tics` steps in all, with the printf format of the fewest decimals that tell neighbouring
// ticks apart
// ("%.0f" for steps of 1 and more). A zero-width range is widened around its value.
struct AxisScale {
  double lo = 0.0, hi = 1.0, step = 0.2;
  std::string format = "%.1f";
};
AxisScale NiceAxis(double lo, double hi, int tics = 5);

// An x axis of categories 0, 1, 2, ... named `labels` (units, lots): every label while at most
// `max_labels`, else every k-th from the first so that at most max_labels show; turned upright
// (rotate_deg 90) when the labels shown would not fit side by side in `width_chars` characters.
struct CategoryAxis {
  std::vector<PlotTic> tics;
  int rotate_deg = 0;
  std::array<double, 2> range{-0.5, 0.5};  // half a category beyond the first and the last
};
CategoryAxis CategoryTics(const std::vector<std::string>& labels, int max_labels, int width_chars);

struct PlotFigure {
  std::string title;  // above the grid ("" = none)
  int rows = 1, cols = 1;
  int width_px = 760, height_px = 330;
  std::vector<Plot> panels;  // row by row; at most rows * cols
};

// Inline SVG markup drawn by gnuplot: the only markup the HTML builder (html.h) takes unescaped.
struct Svg {
  std::string markup;
};

// `svg` without its <title> and <desc> elements: gnuplot's "Gnuplot", "Produced by GNUPLOT ..." and
// each series' name, which browsers show as tooltips over a page's plots.
std::string WithoutTooltips(std::string svg);

// The gnuplot commands that draw `figure` into `output` with `terminal` ("svg" or "png").
std::string GnuplotScript(const PlotFigure& figure, const std::string& terminal, const std::string& output);
// Draws every figure in one gnuplot run.
std::vector<Svg> DrawSvg(const std::vector<PlotFigure>& figures);
// Draws one figure into `path` (ending in .svg or .png), atomically, in `transaction` when not null.
void DrawFile(const PlotFigure& figure, const std::string& path, OutputTransaction* transaction = nullptr);
// Whether gnuplot is on PATH.
bool GnuplotAvailable();

}  // namespace imufit

#endif  // IMUFIT_REPORT_PLOT_H_
