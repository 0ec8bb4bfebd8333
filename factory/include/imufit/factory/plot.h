// imufit — the one plotting module: plots described as data (series of points, lines, bands and
// error bars, limit lines, labels; a figure is a grid of such panels), drawn by gnuplot. `imufit
// allan --plot`, the certificate and the lot page all draw through it, so every plot of imufit
// looks alike and a test can check what a plot holds without reading SVG.
//
// Drawing needs gnuplot on PATH (Debian: gnuplot-nox). DrawSvg() runs it once for many figures
// and returns inline SVG (for self-contained HTML); DrawFile() writes one figure as .svg or .png,
// atomically. Both throw std::runtime_error when gnuplot is missing or fails.
#ifndef IMUFIT_FACTORY_PLOT_H_
#define IMUFIT_FACTORY_PLOT_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace imufit {

// A qualitative palette (Tableau 10), readable in print and for most colour-blind readers.
const char* PlotColor(int index);

struct PlotSeries {
  enum class Style { kLines, kPoints, kLinesPoints, kBand, kErrorBars };
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
};

// A line of text inside the panel; labels stack from the top left (or the bottom left).
struct PlotLabel {
  std::string text;
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
};

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

// The gnuplot commands that draw `figure` into `output` with `terminal` ("svg" or "png").
std::string GnuplotScript(const PlotFigure& figure, const std::string& terminal, const std::string& output);
// Draws every figure in one gnuplot run.
std::vector<Svg> DrawSvg(const std::vector<PlotFigure>& figures);
// Draws one figure into `path` (ending in .svg or .png), atomically.
void DrawFile(const PlotFigure& figure, const std::string& path);
// Whether gnuplot is on PATH.
bool GnuplotAvailable();

}  // namespace imufit

#endif  // IMUFIT_FACTORY_PLOT_H_
