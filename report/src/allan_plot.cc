#include "imufit/report/allan_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "imufit/base/enum_names.h"
#include "imufit/io/noise_file.h"
#include "imufit/io/units.h"

namespace imufit {
namespace {

// "rad/s" is the native unit of a gyro column: an alias.
constexpr EnumName<AllanPlotUnits> kAllanPlotUnitsNames[] = {{AllanPlotUnits::kNative, "native"},
                                                             {AllanPlotUnits::kNative, "rad/s"},
                                                             {AllanPlotUnits::kDegPerSecond, "deg/s"},
                                                             {AllanPlotUnits::kDegPerHour, "deg/h"}};

constexpr int kModelPoints = 120;  // taus at which the model and its terms are drawn
// A term is drawn where its deviation is at least this share of the model's (a hundredth of the
// variance): beyond, its line only stretches the axis.
constexpr double kTermShownShare = 0.1;
// The deviation axis reaches whole decades, at least this factor below the lowest point (room for
// the bias-instability labels under the floor) and above the highest.
constexpr double kRoomBelow = 4.0, kRoomAbove = 1.5;
// The tau axis starts at the whole decade below the shortest tau and ends this factor beyond the
// longest: room for its confidence bar, not a decade of nothing (gnuplot's own range reaches the
// next decade, a third of the panel empty).
constexpr double kRoomRight = 1.6;
const char* kKeyGrey = "#555555";

// A unit as a plot shows it: "deg/sqrt(h)" -> "°/√h", "micro-g" -> "µg", "m/s^2" -> "m/s²".
std::string Pretty(std::string unit) {
  const std::array<std::array<const char*, 2>, 4> replacements = {
      {{"sqrt(h)", "\xe2\x88\x9ah"}, {"deg", "\xc2\xb0"}, {"micro-g", "\xc2\xb5g"}, {"^2", "\xc2\xb2"}}};
  for (const auto& [from, to] : replacements) {
    for (size_t at = unit.find(from); at != std::string::npos; at = unit.find(from, at + 1))
      unit.replace(at, std::string(from).size(), to);
  }
  return unit;
}

const char* LongName(AllanEstimator estimator) {
  switch (estimator) {
    case AllanEstimator::kAdev:
      return "Allan deviation";
    case AllanEstimator::kOadev:
      return "overlapping Allan deviation";
    case AllanEstimator::kMdev:
      return "modified Allan deviation";
    case AllanEstimator::kTdev:
      return "time deviation";
    case AllanEstimator::kHdev:
      return "Hadamard deviation";
    case AllanEstimator::kOhdev:
      return "overlapping Hadamard deviation";
    case AllanEstimator::kTotdev:
      return "total deviation";
  }
  return "deviation";
}

// Plot units per SI unit, and their name, for a panel of `kind`. In engineer units (deg/s, deg/h)
// an accelerometer panel is in the unit its bias instability is printed in (micro-g).
double Scale(ColumnKind kind, AllanPlotUnits units) {
  if (kind == ColumnKind::kOther || units == AllanPlotUnits::kNative) return 1.0;
  if (kind == ColumnKind::kAccel) return UnitsOf(kind, kBiasInstability).engineer_per_si;
  return units == AllanPlotUnits::kDegPerHour ? DphFromRadps(1.0) : DpsFromRadps(1.0);
}
std::string UnitName(ColumnKind kind, AllanPlotUnits units) {
  if (kind == ColumnKind::kOther || units == AllanPlotUnits::kNative) return Pretty(SiUnit(kind));
  if (kind == ColumnKind::kAccel) return Pretty(UnitsOf(kind, kBiasInstability).engineer_unit);
  return units == AllanPlotUnits::kDegPerHour ? "\xc2\xb0/h" : "\xc2\xb0/s";
}

// "ARW 0.299 ± 0.0004 °/√h" in the term's engineer units (SI for other columns).
std::string TermText(const ColumnAnalysis& r, int term, const char* name) {
  const NoiseTermUnits& u = UnitsOf(r.kind, term);
  const bool engineer = *u.engineer_key != '\0';
  const double scale = engineer ? u.engineer_per_si : 1.0;
  char text[160];
  std::snprintf(text, sizeof text, "%s %.3g \xc2\xb1 %.2g %s", name, r.fit.value[term] * scale,
                r.fit.sigma[term] * scale, Pretty(engineer ? u.engineer_unit : u.si_unit).c_str());
  return text;
}

// ---------------------------------------------------------------- one panel, by stages

// What one panel draws (the columns of one kind) and what it has learnt of its extent so far.
struct Panel {
  Plot plot;
  ColumnKind kind = ColumnKind::kOther;
  double scale = 1.0;            // plot units per SI unit
  const char* random_walk = "";  // "ARW" or "VRW"
  int columns = 0;               // columns of this kind in the panel
  double lowest = INFINITY, highest = 0.0, shortest = INFINITY, longest = 0.0;
  std::vector<PlotNote> floor_words;  // the bias instabilities in words, placed at the end
  std::vector<PlotNote> walk_words;   // the random walks in words, placed at the end
};

// The axes and titles of the panel of `kind`, for the curves of `estimator`.
Panel OpenPanel(const std::vector<ColumnAnalysis>& results, ColumnKind kind, AllanEstimator estimator,
                AllanPlotUnits units) {
  Panel panel;
  panel.kind = kind;
  panel.scale = Scale(kind, units);
  panel.random_walk = kind == ColumnKind::kAccel ? "VRW" : "ARW";
  Plot& plot = panel.plot;
  plot.log_x = plot.log_y = true;
  plot.x_label = "averaging time \xcf\x84 (s)";
  plot.y_label = std::string(LongName(estimator)) + " (" + UnitName(kind, units) +
                 (estimator == AllanEstimator::kTdev ? "\xc2\xb7s" : "") + ")";
  plot.title = kind == ColumnKind::kGyro    ? "Gyro"
               : kind == ColumnKind::kAccel ? "Accelerometer"
                                            : "Other columns";
  plot.labels_at_bottom = true;
  for (const ColumnAnalysis& r : results) panel.columns += r.kind == kind ? 1 : 0;
  return panel;
}

// The measured curve with its confidence bars (points where the deviation is 0 are left out: a
// constant column has nothing to show on a log scale).
PlotSeries Curve(const ColumnAnalysis& r, int color, Panel* panel) {
  PlotSeries curve;
  curve.style = PlotSeries::Style::kErrorBars;
  curve.title = r.name;
  curve.color = PlotColor(color);
  curve.point_size = 0.7;
  const double scale = panel->scale;
  for (const AllanPoint& p : r.curve.points) {
    if (!(p.dev > 0.0)) continue;
    curve.x.push_back(p.tau_s);
    curve.y.push_back(p.dev * scale);
    curve.lo.push_back((std::isfinite(p.dev_lo) && p.dev_lo > 0.0 ? p.dev_lo : p.dev) * scale);
    curve.hi.push_back((std::isfinite(p.dev_hi) ? p.dev_hi : p.dev) * scale);
    panel->lowest = std::min(panel->lowest, curve.lo.back());
    panel->highest = std::max(panel->highest, curve.hi.back());
    panel->shortest = std::min(panel->shortest, p.tau_s);
    panel->longest = std::max(panel->longest, p.tau_s);
  }
  return curve;
}

// The fitted model (solid) over the curve's taus and its resolved terms (dashed, where they carry
// at least kTermShownShare of the model's deviation); returns the tau of the model's minimum.
double DrawModel(const ColumnAnalysis& r, const PlotSeries& curve, Panel* panel) {
  PlotSeries model;
  model.color = curve.color;
  model.line_width = 2;
  std::array<PlotSeries, kNoiseTerms> terms;
  const double first = curve.x.front(), last = curve.x.back();
  double floor_tau = first, floor_dev = INFINITY;
  for (int i = 0; i <= kModelPoints; ++i) {
    const double tau = first * std::pow(last / first, static_cast<double>(i) / kModelPoints);
    const double dev = r.fit.ModelDeviation(tau);
    model.x.push_back(tau);
    model.y.push_back(dev * panel->scale);
    if (dev < floor_dev) floor_tau = tau, floor_dev = dev;
    for (int k = 0; k < kNoiseTerms; ++k) {
      const double term = r.fit.TermDeviation(k, tau);
      terms[k].x.push_back(tau);
      terms[k].y.push_back(term >= kTermShownShare * dev ? term * panel->scale : NAN);  // NaN: a gap
    }
  }
  panel->plot.series.push_back(model);
  for (int k = 0; k < kNoiseTerms; ++k) {
    if (!IsResolved(r.fit, k)) continue;  // a term within its noise is no line to read
    terms[k].color = curve.color;
    terms[k].dashed = true;
    terms[k].line_width = 1;
    panel->plot.series.push_back(terms[k]);
  }
  return floor_tau;
}

// N where it is read: the -1/2 line at tau = 1 s (at the curve's end when 1 s is beyond it); the
// first column's note on top.
void MarkRandomWalk(const ColumnAnalysis& r, const PlotSeries& curve, const std::string& who, Panel* panel) {
  if (!IsResolved(r.fit, kRandomWalk)) {
    panel->plot.labels.push_back({r.name + ": " + panel->random_walk + " not resolved"});
    return;
  }
  PlotNote n;
  n.x = std::clamp(1.0, curve.x.front(), curve.x.back());
  n.y = r.fit.TermDeviation(kRandomWalk, n.x) * panel->scale;
  n.color = curve.color;
  n.point_type = 7;
  n.point_size = 1.3;
  panel->plot.notes.push_back(n);  // the mark where it is read; its words are stacked later
  n.point_type = -1;
  n.text = who + TermText(r, kRandomWalk, panel->random_walk);
  n.opaque = true;
  panel->walk_words.push_back(n);
}

// The random walks in words: anchored above the highest of their marks, one above the other in
// column order, so that neighbouring axes' words never overlap (each anchored at its own mark,
// two marks a line apart put one label on the other: issue 33, accel_y under accel_z).
void PlaceWalkWords(Panel* panel) {
  if (panel->walk_words.empty()) return;
  double x = 0.0, y = 0.0;
  for (const PlotNote& n : panel->walk_words) x = std::max(x, n.x), y = std::max(y, n.y);
  const size_t count = panel->walk_words.size();
  for (size_t i = 0; i < count; ++i) {
    PlotNote& n = panel->walk_words[i];
    n.x = x;
    n.y = y;
    n.dx_chars = 1.5;
    n.dy_chars = 1.2 + 1.4 * static_cast<double>(count - 1 - i);
    panel->plot.notes.push_back(n);
  }
}

// The bias-instability floor, 0.664 B, marked at the model's minimum; its words are stacked below
// the panel's lowest floor later (PlaceFloorWords), so that they cross no floor line.
void MarkBiasInstability(const ColumnAnalysis& r, const PlotSeries& curve, const std::string& who,
                         double floor_tau, Panel* panel) {
  if (!IsResolved(r.fit, kBiasInstability)) {
    panel->plot.labels.push_back({r.name + ": bias instability not resolved"});
    return;
  }
  PlotNote b;
  b.x = floor_tau;
  b.y = r.fit.TermDeviation(kBiasInstability, floor_tau) * panel->scale;
  b.color = curve.color;
  b.point_type = 13;
  b.point_size = 1.6;
  panel->plot.notes.push_back(b);
  b.point_type = -1;
  b.text = who + TermText(r, kBiasInstability, "bias instability");
  b.opaque = true;
  panel->floor_words.push_back(b);
  panel->lowest = std::min(panel->lowest, b.y);
}

// A number for a label: 3 significant digits.
std::string ShortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// One column of the panel: its curve, and over an Allan-variance curve its noise fit drawn and
// annotated (otherwise said in words).

void AddColumn(const ColumnAnalysis& r, int color, bool draw_model, Panel* panel) {
  const PlotSeries curve = Curve(r, color, panel);
  panel->plot.series.push_back(curve);
  if (!r.fit.fitted) {
    panel->plot.labels.push_back({r.name + ": no noise fit (" + r.fit.message + ")"});
    return;
  }
  if (!draw_model || curve.x.empty()) {
    // The terms belong to the overlapping Allan deviation, not to this curve: words only.
    const bool arw = IsResolved(r.fit, kRandomWalk), bias = IsResolved(r.fit, kBiasInstability);
    panel->plot.labels.push_back(
        {r.name + ": " + (arw ? TermText(r, kRandomWalk, panel->random_walk) : "ARW not resolved") + ", " +
         (bias ? TermText(r, kBiasInstability, "bias instability") : "bias instability not resolved") +
         " (IEEE 952 fit to oadev)"});
    return;
  }
  const double floor_tau = DrawModel(r, curve, panel);
  const std::string who = panel->columns > 1 ? r.name + " " : "";
  MarkRandomWalk(r, curve, who, panel);
  if (!r.fit.describes_curve) {
    panel->plot.labels.push_back({r.name + ": fit does not describe the curve (reduced chi-sq. " +
                                  ShortNumber(r.fit.reduced_chi_square) + ")"});
  }
  MarkBiasInstability(r, curve, who, floor_tau, panel);
}

// The bias instabilities in words: anchored at the lowest floor, under the rightmost mark, towards
// the middle of the panel, one under the other.
void PlaceFloorWords(Panel* panel) {
  if (panel->floor_words.empty()) return;
  double x = 0.0, y = INFINITY, taus_lo = INFINITY, taus_hi = 0.0;
  for (const PlotNote& b : panel->floor_words) x = std::max(x, b.x), y = std::min(y, b.y);
  for (const PlotSeries& s : panel->plot.series) {
    if (!s.x.empty()) taus_lo = std::min(taus_lo, s.x.front()), taus_hi = std::max(taus_hi, s.x.back());
  }
  const bool right_half = x > std::sqrt(taus_lo * taus_hi);
  for (size_t i = 0; i < panel->floor_words.size(); ++i) {
    PlotNote& b = panel->floor_words[i];
    b.x = x;
    b.y = y;
    b.align = right_half ? PlotNote::Align::kRight : PlotNote::Align::kLeft;
    b.dx_chars = right_half ? 1.0 : -1.0;
    b.dy_chars = -1.4 - 1.4 * i;
    panel->plot.notes.push_back(b);
  }
}

// Key entries for what the lines are (series without points draw nothing but their key).
void KeyTheLines(Plot* plot) {
  PlotSeries fit_key, term_key;
  fit_key.title = "IEEE 952 fit";
  term_key.title = "its terms";
  fit_key.color = term_key.color = kKeyGrey;
  fit_key.line_width = 2;
  term_key.dashed = true;
  term_key.line_width = 1;
  plot->series.push_back(fit_key);
  plot->series.push_back(term_key);
}

// Axes of whole decades around what the panel shows (kRoomBelow, kRoomAbove, kRoomRight).
void FrameTheAxes(Panel* panel) {
  if (panel->highest > 0.0 && std::isfinite(panel->lowest) && panel->lowest > 0.0) {
    panel->plot.y_range =
        std::array<double, 2>{std::pow(10.0, std::floor(std::log10(panel->lowest / kRoomBelow))),
                              std::pow(10.0, std::ceil(std::log10(panel->highest * kRoomAbove)))};
  }
  if (panel->longest > 0.0 && std::isfinite(panel->shortest)) {
    panel->plot.x_range = std::array<double, 2>{std::pow(10.0, std::floor(std::log10(panel->shortest))),
                                                panel->longest * kRoomRight};
  }
}

}  // namespace

bool ParseAllanPlotUnits(const std::string& text, AllanPlotUnits* units) {
  return ValueOf(kAllanPlotUnitsNames, text, units);
}

const char* AllanPlotUnitsNames() {
  static const std::string names = AllNames(kAllanPlotUnitsNames);
  return names.c_str();
}

PlotFigure AllanPlot(const std::vector<ColumnAnalysis>& results, const std::string& title,
                     AllanPlotUnits units) {
  std::vector<ColumnKind> kinds;
  for (const ColumnAnalysis& r : results) {
    if (std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) kinds.push_back(r.kind);
  }
  PlotFigure figure;
  figure.title = title;
  figure.cols = static_cast<int>(kinds.size());
  figure.width_px = kinds.size() > 1 ? 1400 : 900;
  figure.height_px = 620;
  const AllanEstimator estimator = results.empty() ? AllanEstimator::kOadev : results.front().curve.estimator;
  // The IEEE 952 model is the Allan variance's: drawn (and read off) over Allan-variance curves only.
  const bool draw_model = estimator == AllanEstimator::kOadev || estimator == AllanEstimator::kAdev ||
                          estimator == AllanEstimator::kTotdev;
  for (ColumnKind kind : kinds) {
    Panel panel = OpenPanel(results, kind, estimator, units);
    for (size_t c = 0; c < results.size(); ++c) {  // labels stack in column order
      if (results[c].kind == kind) AddColumn(results[c], static_cast<int>(c), draw_model, &panel);
    }
    PlaceFloorWords(&panel);
    PlaceWalkWords(&panel);
    if (draw_model) KeyTheLines(&panel.plot);
    FrameTheAxes(&panel);
    figure.panels.push_back(std::move(panel.plot));
  }
  return figure;
}

}  // namespace imufit
