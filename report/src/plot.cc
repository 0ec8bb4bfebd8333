#include "imufit/report/plot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "imufit/base/text.h"
#include "imufit/io/output_file.h"
#include "imufit/io/path.h"
#include "imufit/model/check.h"
#include "temp_folder.h"

extern char** environ;

namespace imufit {
namespace {

namespace fs = std::filesystem;

std::string Quote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += (c == '\n') ? ' ' : c;
  }
  return quoted + "\"";
}

std::string ReadBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

void WriteData(std::ostream& gp, const std::string& name, const PlotSeries& s) {
  gp << name << " << EOD\n";
  bool any = false;
  for (size_t i = 0; i < s.x.size(); ++i) {
    const bool band = s.style == PlotSeries::Style::kBand || s.style == PlotSeries::Style::kErrorBars;
    const double y = i < s.y.size() ? s.y[i] : NAN;
    const bool symmetric = band && i < s.error.size();
    if (band && !symmetric && (i >= s.lo.size() || i >= s.hi.size())) continue;
    gp << s.x[i] << " " << (std::isfinite(y) ? y : NAN);
    if (symmetric) gp << " " << y - s.error[i] << " " << y + s.error[i];
    if (band && !symmetric) gp << " " << s.lo[i] << " " << s.hi[i];
    gp << "\n";
    any = true;
  }
  if (!any) gp << "NaN NaN NaN NaN\n";  // gnuplot refuses an empty block
  gp << "EOD\n";
}

std::string With(const PlotSeries& s) {
  std::ostringstream w;
  const std::string color = "lc rgb '" + s.color + "'";
  switch (s.style) {
    case PlotSeries::Style::kLines:
      w << "using 1:2 with lines lw " << s.line_width << (s.dashed ? " dt 2 " : " ") << color;
      break;
    case PlotSeries::Style::kPoints:
      w << "using 1:2 with points pt " << s.point_type << " ps " << s.point_size << " " << color;
      break;
    case PlotSeries::Style::kLinesPoints:
      w << "using 1:2 with linespoints lw " << s.line_width << " pt " << s.point_type << " ps "
        << s.point_size << (s.dashed ? " dt 2 " : " ") << color;
      break;
    case PlotSeries::Style::kBand:
      w << "using 1:3:4 with filledcurves fs transparent solid 0.18 noborder " << color;
      break;
    case PlotSeries::Style::kErrorBars:
      w << "using 1:2:3:4 with yerrorbars lw " << s.line_width << " pt " << s.point_type << " ps "
        << s.point_size << " " << color;
      break;
    case PlotSeries::Style::kBoxes:
      w << "using 1:2:(0.7) with boxes fs solid 0.75 noborder " << color;
      break;
  }
  w << " " << (s.title.empty() ? "notitle" : "title " + Quote(s.title));
  return w.str();
}

std::string RunGnuplot(const std::string& script_text, const std::string& folder) {
  const std::string script_path = folder + "/plot.gp", errors_path = folder + "/errors.txt";
  std::ofstream(script_path) << script_text;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, errors_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::string program = "gnuplot", argument = script_path;
  std::vector<char*> argv = {program.data(), argument.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = -1;
  if (spawned == 0) waitpid(pid, &status, 0);
  if (spawned != 0) return "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return "gnuplot failed: " + ReadBytes(errors_path).substr(0, 400);
  return "";
}

using internal::TempFolder;

// Margins around the data, as fractions of its extent, so that no point sits on the frame.
constexpr double kXMargin = 0.04, kYMargin = 0.06;

// The extent of the panel's data along x or y (y: the intervals of bands and error bars too);
// false when it holds no finite value.
bool DataExtent(const Plot& plot, bool y_axis, double* lo, double* hi) {
  *lo = INFINITY;
  *hi = -INFINITY;
  const auto take = [&](double v) {
    if (!std::isfinite(v)) return;
    *lo = std::min(*lo, v);
    *hi = std::max(*hi, v);
  };
  for (const PlotSeries& s : plot.series) {
    if (!y_axis) {
      for (double v : s.x) take(v);
      continue;
    }
    if (s.style != PlotSeries::Style::kBand) {
      for (double v : s.y) take(v);
    }
    for (double v : s.lo) take(v);
    for (double v : s.hi) take(v);
    for (size_t i = 0; i < s.error.size() && i < s.y.size(); ++i) {
      take(s.y[i] - s.error[i]);
      take(s.y[i] + s.error[i]);
    }
  }
  return *lo <= *hi;
}

// A tick step of 1, 2, 2.5 or 5 times a power of ten that puts at most `most` tick labels on
// [lo, hi]; 0 when the extent is empty.
double TickStep(double lo, double hi, int most) {
  const double span = hi - lo;
  if (!(span > 0.0) || most < 2) return 0.0;
  const double raw = span / (most - 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10.0 * power;
}

// What a tick label takes at the terminal's 10-point DejaVu Sans: a digit's width, and the gap
// kept between two labels, in characters.
constexpr double kTickCharPx = 6.4;
constexpr double kTickGapChars = 1.5;
// Of a panel's width, what its y tick labels, y label and right margin take.
constexpr double kPanelFramePx = 80.0;

// The width of a panel's plotting area, px.
double PlotWidthPx(const PlotFigure& figure) {
  return std::max(1.0, static_cast<double>(figure.width_px) / std::max(figure.cols, 1) - kPanelFramePx);
}

// ---------------------------------------------------------------- a panel's script, by stages

// Title, axis labels, log scales and tick formats.
void WriteAxes(std::ostream& gp, const Plot& plot) {
  gp << "reset\nset encoding utf8\nset grid lc rgb '#dddddd'\nset border lc rgb '#444444'\n";
  gp << "set bars small\n";
  gp << "set title " << Quote(plot.title) << "\n";
  gp << "set xlabel " << Quote(plot.x_label) << "\nset ylabel " << Quote(plot.y_label) << "\n";
  if (plot.log_x)
    gp << "set logscale x\nset format x '%g'\nset mxtics 10\n";
  else
    gp << "set format x '%g'\n";
  if (plot.log_y)
    gp << "set logscale y\nset format y '%g'\nset mytics 10\n";
  else
    gp << "set format y '%g'\n";
  if (!plot.y_tics) gp << "unset ytics\n";
  if (plot.y_tics && plot.y_tic_step > 0.0) gp << "set ytics " << plot.y_tic_step << "\n";
  if (!plot.y_format.empty()) gp << "set format y " << Quote(plot.y_format) << "\n";
  if (!plot.x_tics.empty()) {
    gp << "set xtics (";
    for (size_t t = 0; t < plot.x_tics.size(); ++t) {
      gp << (t ? ", " : "") << Quote(plot.x_tics[t].label) << " " << plot.x_tics[t].value;
    }
    gp << ")"
       << (plot.x_tic_rotate_deg ? " rotate by " + std::to_string(plot.x_tic_rotate_deg) + " right" : "")
       << "\n";
  }
}

// Fixed ranges, the margins around the data otherwise, and the key.
void WriteRangesAndKey(std::ostream& gp, const Plot& plot) {
  if (plot.x_range) gp << "set xrange [" << (*plot.x_range)[0] << ":" << (*plot.x_range)[1] << "]\n";
  if (plot.y_range) gp << "set yrange [" << (*plot.y_range)[0] << ":" << (*plot.y_range)[1] << "]\n";
  if (!plot.x_range) {
    gp << "set offsets graph " << kXMargin << ", graph " << kXMargin << ", graph " << kYMargin << ", graph "
       << (plot.y_from_zero ? 0.0 : kYMargin) << "\n";
  }
  if (plot.y_from_zero && !plot.y_range) gp << "set yrange [0:*]\n";
  if (!plot.key) {
    gp << "unset key\n";
  } else {
    gp << (plot.key_above ? "set key outside center top horizontal samplen 1.5 spacing 0.9\n"
                          : "set key outside right top samplen 1.5 spacing 0.9\n");
  }
}

// The tick labels of `step` on [lo, hi] side by side, in pixels at kTickCharPx a character with
// a gap of kTickGapChars between two.
double TickLabelsWidthPx(double lo, double hi, double step) {
  size_t chars = 0;
  int labels = 0;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step && labels < 1000; t += step, ++labels) {
    const double shown = std::abs(t) < 1e-9 * step ? 0.0 : t;
    chars = std::max(chars, NumberText("%g", shown).size());
  }
  return labels * (chars + kTickGapChars) * kTickCharPx;
}

// At most max_x_tics / max_y_tics tick labels on a linear axis, and no more x labels than fit
// side by side in the panel's `plot_width_px`; the axis ends where the data end.
void WriteTickSteps(std::ostream& gp, const Plot& plot, double plot_width_px) {
  for (const bool y_axis : {false, true}) {
    const int most = y_axis ? plot.max_y_tics : plot.max_x_tics;
    const bool log = y_axis ? plot.log_y : plot.log_x;
    const bool fixed = y_axis ? plot.y_range.has_value() : plot.x_range.has_value();
    double lo = 0.0, hi = 0.0;
    if (most <= 1 || log || (y_axis && !plot.y_tics) || !DataExtent(plot, y_axis, &lo, &hi)) continue;
    if (fixed) {
      lo = (y_axis ? *plot.y_range : *plot.x_range)[0];
      hi = (y_axis ? *plot.y_range : *plot.x_range)[1];
    } else {
      // The axis ends where the data end (with the margins of the offsets above), not at the next
      // tick: a few labels on a small panel must not leave half of it empty.
      const double margin = (hi - lo) * (y_axis ? kYMargin : kXMargin);
      lo = y_axis && plot.y_from_zero ? 0.0 : lo - margin;
      hi += margin;
    }
    if (!fixed && !(hi > lo)) {  // one value (a run at one temperature): a unit either side
      const double half = std::max(1.0, 0.01 * std::abs(lo));
      lo -= half;
      hi += half;
    }
    double step = TickStep(lo, hi, most);
    // Fewer, wider steps until the x labels fit: "750 10001250" is not an axis.
    for (int fewer = most - 1;
         !y_axis && step > 0.0 && fewer >= 2 && TickLabelsWidthPx(lo, hi, step) > plot_width_px; --fewer) {
      step = TickStep(lo, hi, fewer);
    }
    if (!(step > 0.0)) continue;
    const char* axis = y_axis ? "y" : "x";
    gp << "set " << axis << "tics " << step << "\n";
    if (!fixed) gp << "set " << axis << "range [" << lo << ":" << hi << "]\n";
  }
}

// Markers, stacked labels and notes, numbered as gnuplot's arrows and labels from 1.
void WriteAnnotations(std::ostream& gp, const Plot& plot) {
  int object = 1;
  size_t right_label = 0;  // the longest label of a horizontal marker, right of the panel
  for (const PlotMarker& m : plot.markers) {
    if (!m.vertical) right_label = std::max(right_label, m.label.size());
  }
  if (right_label > 0 && !plot.key) gp << "set rmargin " << right_label + 3 << "\n";
  for (const PlotMarker& m : plot.markers) {
    if (m.vertical) {
      gp << "set arrow " << object << " from first " << m.value << ", graph 0 to first " << m.value
         << ", graph 1 nohead dt " << m.dash_type << " lw 1.5 lc rgb '" << m.color << "'\n";
      gp << "set label " << object << " " << Quote(m.label) << " at first " << m.value
         << ", graph 1.02 center textcolor rgb '" << m.color << "'\n";
    } else {
      gp << "set arrow " << object << " from graph 0, first " << m.value << " to graph 1, first " << m.value
         << " nohead dt " << m.dash_type << " lw 1.5 lc rgb '" << m.color << "'\n";
      gp << "set label " << object << " " << Quote(m.label) << " at graph 1.01, first "
         << m.label_at.value_or(m.value) << " left textcolor rgb '" << m.color << "'\n";
    }
    ++object;
  }
  constexpr double kLabelStep = 0.06;  // graph units between stacked labels
  for (size_t l = 0; l < plot.labels.size(); ++l) {
    const double y =
        plot.labels_at_bottom ? 0.05 + kLabelStep * (plot.labels.size() - 1 - l) : 0.94 - kLabelStep * l;
    gp << "set label " << object++ << " " << Quote(plot.labels[l].text) << " at graph 0.03, graph " << y
       << " left front\n";
  }
  gp << "set style textbox opaque noborder margins 0.5, 0.5\n";
  for (const PlotNote& n : plot.notes) {
    gp << "set label " << object++ << " " << Quote(n.text) << " at first " << n.x << ", first " << n.y
       << (n.align == PlotNote::Align::kLeft     ? " left"
           : n.align == PlotNote::Align::kCenter ? " center"
                                                 : " right")
       << (n.opaque ? " boxed" : "") << " front textcolor rgb '" << n.color << "' offset character "
       << n.dx_chars << ", " << n.dy_chars;
    if (n.point_type >= 0)
      gp << " point pt " << n.point_type << " ps " << n.point_size << " lc rgb '" << n.color << "'";
    gp << "\n";
  }
}

// The plot command over the panel's data blocks ($d<panel>_<series>).
void WritePlotCommand(std::ostream& gp, const Plot& plot, size_t p) {
  gp << "plot ";
  if (plot.series.empty()) gp << "NaN notitle";
  for (size_t s = 0; s < plot.series.size(); ++s) {
    gp << (s ? ", \\\n  " : "") << "$d" << p << "_" << s << " " << With(plot.series[s]);
  }
  gp << "\n";
}

// The terminal (text is UTF-8, drawn as it is: noenhanced; enhanced text's {/Symbol t} asks for the
// Symbol font, which pngcairo maps to a tau but the SVG names with a Latin t, which browsers and
// librsvg draw as "t"), and the output.
void WriteTerminal(std::ostream& gp, const PlotFigure& figure, const std::string& terminal,
                   const std::string& output) {
  gp << "set encoding utf8\n";
  const std::string size = std::to_string(figure.width_px) + "," + std::to_string(figure.height_px);
  if (terminal == "png") {
    gp << "set terminal pngcairo size " << size
       << " noenhanced font 'DejaVu Sans,10' background rgb 'white'\n";
  } else {
    gp << "set terminal svg size " << size
       << " dynamic noenhanced font 'DejaVu Sans,10' background rgb 'white'\n";
  }
  gp << "set output " << Quote(output) << "\n";
}

}  // namespace

AxisScale NiceAxis(double lo, double hi, int tics) {
  if (!(hi > lo)) {  // one value (or none): a small range around it
    const double pad = lo != 0.0 && std::isfinite(lo) ? 0.01 * std::abs(lo) : 1.0;
    if (!std::isfinite(lo)) lo = 0.0;
    hi = lo + pad;
    lo -= pad;
  }
  // A point on the frame is hard to see: 3 % of the range to spare on each side first.
  const double pad = 0.03 * (hi - lo);
  lo -= pad;
  hi += pad;
  // The step of about `tics` steps over the range, rounded up to 1, 2 or 5 times a power of 10.
  const double raw = (hi - lo) / std::max(tics, 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double fraction = raw / magnitude;
  const double step = (fraction <= 1.0   ? 1.0
                       : fraction <= 2.0 ? 2.0
                       : fraction <= 5.0 ? 5.0
                                         : 10.0) *
                      magnitude;
  AxisScale scale;
  scale.step = step;
  scale.lo = std::floor(lo / step) * step;
  scale.hi = std::ceil(hi / step) * step;
  // Decimals: as many as the step's first significant digit needs (0.05 -> 2, 20 -> 0).
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  scale.format = "%." + std::to_string(decimals) + "f";
  return scale;
}

CategoryAxis CategoryTics(const std::vector<std::string>& labels, int max_labels, int width_chars) {
  CategoryAxis axis;
  const size_t n = labels.size();
  axis.range = {-0.5, std::max<double>(n, 1) - 0.5};
  const size_t every =
      n <= static_cast<size_t>(std::max(max_labels, 1)) ? 1 : (n + max_labels - 1) / max_labels;
  size_t chars = 0;
  for (size_t i = 0; i < n; i += every) {
    axis.tics.push_back({static_cast<double>(i), labels[i]});
    chars += labels[i].size() + 2;  // two spaces between neighbours
  }
  if (chars > static_cast<size_t>(std::max(width_chars, 0))) axis.rotate_deg = 90;
  return axis;
}

double MarkerLabelGap(const Plot& plot, int height_px) {
  IMUFIT_CHECK(plot.y_range.has_value() && height_px > 0,
               "a marker label gap needs the y range and the height");
  return ((*plot.y_range)[1] - (*plot.y_range)[0]) * kLabelHeightPx / (kPlotAreaShare * height_px);
}

void SpreadMarkerLabels(int height_px, Plot* plot) {
  std::vector<PlotMarker*> labelled;
  for (PlotMarker& m : plot->markers) {
    if (!m.vertical && !m.label.empty()) labelled.push_back(&m);
  }
  if (labelled.size() < 2) return;
  const double gap = MarkerLabelGap(*plot, height_px);
  std::stable_sort(labelled.begin(), labelled.end(),
                   [](const PlotMarker* a, const PlotMarker* b) { return a->value < b->value; });
  std::vector<double> at;
  for (const PlotMarker* m : labelled)
    at.push_back(at.empty() ? m->value : std::max(m->value, at.back() + gap));
  // Pushed up beyond the axis: pushed back down from its end, keeping the gaps.
  const double top = std::max((*plot->y_range)[1], labelled.back()->value);
  if (at.back() > top) {
    at.back() = top;
    for (size_t i = at.size() - 1; i-- > 0;) at[i] = std::min(at[i], at[i + 1] - gap);
  }
  for (size_t i = 0; i < at.size(); ++i) labelled[i]->label_at = at[i];
}

const char* PlotColor(int index) {
  static const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                        "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  return kColors[((index % 10) + 10) % 10];
}

std::string GnuplotScript(const PlotFigure& figure, const std::string& terminal, const std::string& output) {
  std::ostringstream gp;
  gp.precision(12);
  WriteTerminal(gp, figure, terminal, output);
  for (size_t p = 0; p < figure.panels.size(); ++p) {
    for (size_t s = 0; s < figure.panels[p].series.size(); ++s) {
      WriteData(gp, "$d" + std::to_string(p) + "_" + std::to_string(s), figure.panels[p].series[s]);
    }
  }
  const bool multi = figure.rows * figure.cols > 1 || !figure.title.empty();
  if (multi) {
    gp << "set multiplot layout " << figure.rows << "," << figure.cols;
    if (!figure.title.empty()) gp << " title " << Quote(figure.title);
    gp << "\n";
  }
  for (size_t p = 0; p < figure.panels.size(); ++p) {
    const Plot& plot = figure.panels[p];
    WriteAxes(gp, plot);
    WriteRangesAndKey(gp, plot);
    WriteTickSteps(gp, plot, PlotWidthPx(figure));
    WriteAnnotations(gp, plot);
    WritePlotCommand(gp, plot, p);
  }
  if (multi) gp << "unset multiplot\n";
  gp << "unset output\n";
  return gp.str();
}

std::string WithoutTooltips(std::string svg) {
  for (const char* tag : {"title", "desc"}) {
    const std::string open = std::string("<") + tag + ">", close = std::string("</") + tag + ">";
    for (size_t at = svg.find(open); at != std::string::npos; at = svg.find(open, at)) {
      const size_t end = svg.find(close, at);
      if (end == std::string::npos) break;
      svg.erase(at, end + close.size() - at);
    }
  }
  return svg;
}

std::vector<Svg> DrawSvg(const std::vector<PlotFigure>& figures) {
  if (figures.empty()) return {};
  TempFolder folder("imufit-plot");
  std::string script;
  for (size_t i = 0; i < figures.size(); ++i) {
    script += GnuplotScript(figures[i], "svg", folder.path + "/" + std::to_string(i) + ".svg");
  }
  if (const std::string failure = RunGnuplot(script, folder.path); !failure.empty())
    throw std::runtime_error(failure);
  std::vector<Svg> svgs;
  for (size_t i = 0; i < figures.size(); ++i) {
    const std::string svg = ReadBytes(folder.path + "/" + std::to_string(i) + ".svg");
    const size_t start = svg.find("<svg");  // drop the XML prolog and doctype: inline SVG in HTML
    if (start == std::string::npos) throw std::runtime_error("gnuplot drew no SVG");
    svgs.push_back({WithoutTooltips(svg.substr(start))});
  }
  return svgs;
}

void DrawFile(const PlotFigure& figure, const std::string& path, OutputTransaction* transaction) {
  const bool png = HasSuffix(path, ".png");
  TempFolder folder("imufit-plot");
  const std::string image = folder.path + (png ? "/figure.png" : "/figure.svg");
  if (const std::string failure = RunGnuplot(GnuplotScript(figure, png ? "png" : "svg", image), folder.path);
      !failure.empty()) {
    throw std::runtime_error("gnuplot could not draw " + path + ": " + failure);
  }
  const std::string bytes = ReadBytes(image);
  if (bytes.empty()) throw std::runtime_error("gnuplot could not draw " + path);
  WriteFileAtomically(path, bytes, transaction);
}

bool GnuplotAvailable() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return false;
  std::stringstream folders(path);
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (!folder.empty() && ::access((folder + "/gnuplot").c_str(), X_OK) == 0) return true;
  }
  return false;
}

}  // namespace imufit
