// The history page: the lots of a results store (`imufit history DB --lot --html`), whose
// "across lots" section the lot page shows too.
#include "imufit/factory/history_page.h"

#include "imufit/io/output_file.h"
#include "page.h"

namespace imufit {
namespace {

using internal::CategoryX;
using internal::Count;
using internal::Fmt;
using internal::kHalfWidthChars;
using internal::kHighlight;
using internal::kStripHeightPx;
using internal::kStripUprightHeightPx;
using internal::Num;
using internal::Panel;
using internal::Plots;
using internal::Row;
using internal::Series;

constexpr size_t kMaxBarNotes = 12;         // yields printed on their bars up to this many lots (they fit)
constexpr double kNoteInsideBarPct = 15.0;  // a yield note goes inside its bar from this yield up

std::vector<std::string> LotNames(const LotHistory& history) {
  std::vector<std::string> names;
  for (const LotYield& y : history.lots) names.push_back(y.lot);
  return names;
}

// The yield per lot: bars, this lot highlighted, each with its yield written on it while they fit.
PlotFigure YieldFigure(const LotHistory& history) {
  Plot yield = Panel("Yield per lot (units that passed their limits)", "lot", "yield, %");
  yield.key = false;
  CategoryX(LotNames(history), internal::kFullWidthChars, &yield);
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
      note.text = internal::YieldText(history.yield_pct[i]);  // as the table prints it
      const bool inside = history.yield_pct[i] >= kNoteInsideBarPct;
      note.dy_chars = inside ? -0.9 : 0.7;
      note.color = inside ? "#ffffff" : note.color;
      note.align = PlotNote::Align::kCenter;
      yield.notes.push_back(note);
    }
  }
  yield.series = {others, current};
  return internal::OnePanel(yield, internal::kFullWidthPx, yield.x_tic_rotate_deg ? 260 : 210);
}

// One trend figure: the lots' means with their sigma, this lot highlighted, the limits.
PlotFigure TrendFigure(const LotHistory& history, const LotTrend& t) {
  Plot plot = Panel(t.name + ": lot mean \xc2\xb1 1\xcf\x83", "lot", t.unit);
  plot.key = false;
  CategoryX(LotNames(history), kHalfWidthChars, &plot);
  internal::NiceY(t.view, &plot);
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
  internal::LimitLines(t.limits, t.view, &plot);
  return internal::OnePanel(plot, internal::kHalfWidthPx,
                            plot.x_tic_rotate_deg ? kStripUprightHeightPx : kStripHeightPx);
}

}  // namespace

LotHistoryFigures MakeLotHistoryFigures(const LotHistory& history) {
  LotHistoryFigures figures;
  figures.yield = YieldFigure(history);
  if (history.lots.size() < 2) return figures;  // one lot: no trend to draw (AcrossLots says so)
  for (const LotTrend& t : history.trends) figures.trends.push_back(TrendFigure(history, t));
  return figures;
}

std::vector<PlotFigure> LotHistoryPlots(const LotHistory& history) {
  LotHistoryFigures figures = MakeLotHistoryFigures(history);
  std::vector<PlotFigure> in_page_order = {std::move(figures.yield)};
  for (PlotFigure& trend : figures.trends) in_page_order.push_back(std::move(trend));
  return in_page_order;
}

namespace internal {

void AddSlots(const LotHistoryFigures& figures, LotHistorySvgs* svgs, std::vector<DrawSlot>* slots) {
  slots->push_back({&figures.yield, &svgs->yield});
  svgs->trends.resize(figures.trends.size());
  for (size_t i = 0; i < figures.trends.size(); ++i) slots->push_back({&figures.trends[i], &svgs->trends[i]});
}

void AcrossLots(Html* h, const LotHistory& history, const LotHistorySvgs& svgs, const std::string& failure) {
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
    Num(h, YieldText(history.yield_pct[i]), {{"data-yield", FormatDouble(history.yield_pct[i])}});
    h->Close("tr");
  }
  h->Close("tbody").Close("table");
  Plots(h, {svgs.yield}, failure);
  h->Close("div");
  h->Element("h3", "Key figures across lots");
  if (history.lots.size() < 2) {
    h->Element("p", "Only this lot is in the results store: there is no other lot to compare it with yet.",
               {{"class", "note"}});
    return;
  }
  Plots(h, svgs.trends, failure, "plots2");
}

}  // namespace internal

std::string LotHistoryHtml(const LotHistory& history) {
  const std::string title = "Lots in " + history.store_path;
  const LotHistoryFigures figures = MakeLotHistoryFigures(history);
  internal::LotHistorySvgs svgs;
  std::vector<internal::DrawSlot> slots;
  internal::AddSlots(figures, &svgs, &slots);
  const std::string failure = internal::DrawInto(slots);
  Html h;
  internal::OpenPage(&h, title, title, "");
  h.Element("h1", title);
  internal::AcrossLots(&h, history, svgs, failure);
  return internal::ClosePage(&h);
}

}  // namespace imufit
