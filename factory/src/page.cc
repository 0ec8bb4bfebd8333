// The frame, cells and plots every document of factory shares (page.h), and FormatNumber().
#include "page.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "imufit/base/text.h"
#include "imufit/factory/report.h"

namespace imufit {
namespace {}  // namespace

std::string FormatNumber(const char* format, double value) {
  const std::string text = NumberText(format, value);
  if (text != NumberText(format, -0.0) && text != NumberText(format, 0.0)) return text;
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
  return NumberText(unsigned_format.c_str(), 0.0);
}

std::string AtDecimals(double value, int decimals, bool sign) {
  if (decimals >= 0) {
    const std::string format = std::string(sign ? "%+." : "%.") + std::to_string(decimals) + "f";
    return FormatNumber(format.c_str(), value);
  }
  const double unit = std::pow(10.0, -decimals);
  return FormatNumber(sign ? "%+.0f" : "%.0f", std::round(value / unit) * unit);
}

RoundedValue RoundToUncertainty(double value, double uncertainty, bool sign) {
  RoundedValue r;
  if (!(uncertainty > 0.0) || !std::isfinite(uncertainty)) {
    r.value = FormatNumber(sign ? "%+.6g" : "%.6g", value);
    r.decimals = 6;
    return r;
  }
  int exponent = static_cast<int>(std::floor(std::log10(uncertainty)));
  // Two significant digits; 0.0996 rounds to 0.10, one place fewer.
  if (std::round(uncertainty * std::pow(10.0, 1 - exponent)) >= 100.0) ++exponent;
  r.decimals = 1 - exponent;
  r.value = AtDecimals(value, r.decimals, sign);
  r.uncertainty = AtDecimals(uncertainty, r.decimals);
  return r;
}

namespace internal {
namespace {

// Screen and print: fluid width (fits A4 and Letter), no heading left alone at a page's foot, no
// table row split, small sections kept whole.
const char* kStyle = R"css(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; font-size: 12px; color: #111; margin: 20px auto; max-width: 980px; }
h1 { font-size: 20px; margin: 0 0 6px 0; } h2 { font-size: 15px; border-bottom: 1px solid #999; margin: 16px 0 6px 0; }
h3 { font-size: 13px; margin: 10px 0 4px 0; }
table { border-collapse: collapse; margin: 4px 0; } td, th { border: 1px solid #bbb; padding: 1px 6px; text-align: left; vertical-align: top; }
th { background: #eee; } .path { overflow-wrap: normal; } td.num { text-align: right; font-variant-numeric: tabular-nums; font-family: "DejaVu Sans Mono", monospace; white-space: nowrap; }
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

}  // namespace

std::string Fmt(const char* format, double value) { return FormatNumber(format, value); }

std::string Count(long long value) { return std::to_string(value); }

std::string ShortPath(const std::string& path) {
  if (path.size() <= kMostPathChars) return path;
  const std::string ellipsis = "\xe2\x80\xa6/";
  size_t cut = path.find('/');
  // The shortest cut at a '/' whose tail, after the ellipsis (one character on the page), fits.
  while (cut != std::string::npos && path.size() - cut - 1 + 2 > kMostPathChars)
    cut = path.find('/', cut + 1);
  if (cut == std::string::npos) {
    const size_t name = path.rfind('/');
    return name == std::string::npos ? path : ellipsis + path.substr(name + 1);
  }
  return ellipsis + path.substr(cut + 1);
}

void PathCell(Html* h, const std::string& path) {
  // A zero-width space after each '/': the line may break there, and nowhere inside a name.
  std::string text;
  for (char c : ShortPath(path)) text += c == '/' ? std::string("/\xe2\x80\x8b") : std::string(1, c);
  h->Element("td", text, {{"class", "path"}, {"data-path", path}});
}

std::string YieldText(double pct) { return Fmt("%.1f %%", pct); }

void OpenPage(Html* h, const std::string& title, const std::string& header_left,
              const std::string& header_right) {
  h->Open("html", {{"lang", "en"}}).Open("head").Void("meta", {{"charset", "utf-8"}});
  h->Element("title", title).Style(kStyle).PageStyle(header_left, header_right, "auto");
  h->Close("head").Open("body");
}

std::string ClosePage(Html* h) {
  h->Close("body").Close("html");
  return h->Finish();
}

void Row(Html* h, std::initializer_list<std::string> cells, const char* tag) {
  h->Open("tr");
  for (const std::string& c : cells) h->Element(tag, c);
  h->Close("tr");
}

void Num(Html* h, const std::string& text, const HtmlAttributes& attributes) {
  HtmlAttributes all = {{"class", "num"}};
  all.insert(all.end(), attributes.begin(), attributes.end());
  h->Element("td", text, all);
}

PlotFigure Figure(int rows, int cols, int width_px, int height_px) {
  PlotFigure figure;
  figure.rows = rows;
  figure.cols = cols;
  figure.width_px = width_px;
  figure.height_px = height_px;
  return figure;
}

PlotFigure OnePanel(const Plot& plot, int width_px, int height_px) {
  PlotFigure figure = Figure(1, 1, width_px, height_px);
  figure.panels.push_back(plot);
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

std::string DrawInto(const std::vector<DrawSlot>& slots) {
  std::vector<PlotFigure> figures;
  for (const DrawSlot& slot : slots) figures.push_back(*slot.figure);
  std::vector<Svg> svgs;
  try {
    svgs = DrawSvg(figures);
  } catch (const std::runtime_error& e) {  // gnuplot missing or failing: the page says so
    return e.what();
  }
  for (size_t i = 0; i < slots.size(); ++i) *slots[i].svg = std::move(svgs[i]);
  return "";
}

void Plots(Html* h, const std::vector<Svg>& svgs, const std::string& failure, const char* layout) {
  if (!failure.empty()) {
    h->Element("p", "Plots not drawn: " + failure, {{"class", "note"}});
    return;
  }
  if (layout != nullptr) h->Open("div", {{"class", layout}});
  for (const Svg& svg : svgs) h->Open("div", {{"class", "plot"}}).Figure(svg).Close("div");
  if (layout != nullptr) h->Close("div");
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

}  // namespace internal
}  // namespace imufit
