// The pages of `imufit history` across stations (store_history.h).
#include "imufit/factory/store_history.h"

#include <cmath>
#include <ctime>
#include <map>

#include "imufit/factory/batch.h"
#include "imufit/factory/lot_history.h"
#include "imufit/io/output_file.h"
#include "page.h"

namespace imufit {
namespace {

using internal::Count;
using internal::Num;
using internal::Panel;
using internal::Row;
using internal::Series;

constexpr double kSecondsPerDay = 86400.0;

// Days since the Unix epoch of "YYYY-MM-DDTHH:MM:SSZ"; NaN when the text is not one.
double DaysOf(const std::string& utc) {
  std::tm t{};
  if (std::sscanf(utc.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d", &t.tm_year, &t.tm_mon, &t.tm_mday, &t.tm_hour,
                  &t.tm_min, &t.tm_sec) != 6)
    return NAN;
  t.tm_year -= 1900;
  t.tm_mon -= 1;
  return static_cast<double>(timegm(&t)) / kSecondsPerDay;
}

std::string GroupLabel(YieldGroup by, const std::string& group) {
  if (!group.empty()) return group;
  return by == YieldGroup::kStation ? "(no station)" : "(none)";
}

std::string YieldCell(const GroupYield& y) {
  const double pct = YieldPct(y);
  return std::isnan(pct) ? "not judged" : internal::YieldText(pct);
}

PlotFigure YieldBars(YieldGroup by, const std::vector<GroupYield>& yields) {
  const std::string group = NameOf(kYieldGroupNames, by);
  Plot plot = Panel("Yield per " + group + " (units that passed their limits)", group, "yield, %");
  plot.key = false;
  std::vector<std::string> labels;
  for (const GroupYield& y : yields) labels.push_back(GroupLabel(by, y.group));
  internal::CategoryX(labels, internal::kFullWidthChars, &plot);
  plot.y_range = std::array<double, 2>{0.0, 100.0};
  plot.y_tic_step = 20.0;
  plot.y_format = "%.0f";
  PlotSeries bars = Series(PlotSeries::Style::kBoxes, "", 0, {}, {});
  for (size_t i = 0; i < yields.size(); ++i) {
    const double pct = YieldPct(yields[i]);
    if (std::isnan(pct)) continue;
    bars.x.push_back(i);
    bars.y.push_back(pct);
  }
  plot.series = {bars};
  return internal::OnePanel(plot, internal::kFullWidthPx, plot.x_tic_rotate_deg ? 260 : 210);
}

// A point per fit against days since the first, a colour per station.
PlotFigure TrendPlot(const std::string& figure, const std::vector<TrendPoint>& points) {
  const double first = DaysOf(points.front().time_utc);
  Plot plot = Panel(figure + " over time", "days since " + points.front().time_utc, points.front().unit);
  plot.key_above = true;
  std::map<std::string, size_t> by_station;
  for (const TrendPoint& p : points) {
    const auto [at, added] = by_station.emplace(p.station, plot.series.size());
    if (added) {
      plot.series.push_back(Series(PlotSeries::Style::kPoints, p.station.empty() ? "(no station)" : p.station,
                                   static_cast<int>(plot.series.size()), {}, {}));
    }
    const double days = DaysOf(p.time_utc) - first;
    if (!std::isfinite(days)) continue;
    plot.series[at->second].x.push_back(days);
    plot.series[at->second].y.push_back(p.value);
  }
  return internal::OnePanel(plot, internal::kFullWidthPx, 260);
}

// The page's frame: title, the store, then `body`, with the plots drawn first.
std::string Page(const std::string& title, const std::string& store, const std::vector<PlotFigure>& figures,
                 const std::function<void(Html*, const std::vector<Svg>&, const std::string&)>& body) {
  std::vector<Svg> svgs(figures.size());
  std::vector<internal::DrawSlot> slots;
  for (size_t i = 0; i < figures.size(); ++i) slots.push_back({&figures[i], &svgs[i]});
  const std::string failure = slots.empty() ? "" : internal::DrawInto(slots);
  Html h;
  internal::OpenPage(&h, title, title, store);
  h.Element("h1", title);
  h.Element("p", "From the results store " + store + ".", {{"class", "note"}});
  body(&h, svgs, failure);
  return internal::ClosePage(&h);
}

}  // namespace

double YieldPct(const GroupYield& y) {
  return y.passed + y.failed > 0 && y.units > 0 ? 100.0 * y.passed / y.units : NAN;
}

std::vector<MonthlyMean> MonthlyMeans(const std::vector<TrendPoint>& points) {
  std::map<std::pair<std::string, std::string>, std::vector<double>> values;
  std::map<std::pair<std::string, std::string>, std::string> units;
  for (const TrendPoint& p : points) {
    const auto key = std::make_pair(p.station, p.time_utc.substr(0, 7));
    values[key].push_back(p.value);
    units[key] = p.unit;
  }
  std::vector<MonthlyMean> means;
  for (const auto& [key, v] : values) {
    const MeanSigma m = MeanAndSigma(v);
    means.push_back({key.first, key.second, m.count, m.mean, m.sigma, units[key]});
  }
  return means;
}

BatchResult StoredLot(ResultsStore* store, const std::string& lot) {
  BatchResult result;
  for (StoredFit& f : store->LatestOfLot(lot)) {
    UnitOutcome u;
    u.unit = f.unit;
    u.serial = f.serial;
    ValueOf(kUnitStatusNames, f.status, &u.status);
    bool pass = false;
    if (ValueOf(kVerdictNames, f.verdict, &pass)) u.verdict.emplace().pass = pass;
    u.message = f.message;
    u.plan_sha256 = f.plan_sha256;
    u.samples_sha256 = f.samples_sha256;
    if (u.status == UnitStatus::kFitted)
      u.calibrated_utc = f.time_utc;  // a batch's: the calibration's created_utc
    u.calibration_yaml = std::move(f.calibration_yaml);
    for (const StoredFigure& g : f.figures) {
      u.figures.push_back(MakeFigure(g.name, g.coefficient, g.unit, g.value, g.sigma));
      u.figures.back().expanded = g.expanded_u;  // the U the fit was stated with, not re-derived
      bool accepted = false;
      if (!u.verdict || !ValueOf(kCriterionAcceptanceNames, g.outcome, &accepted)) continue;
      CriterionResult c;
      c.name = "|" + g.name + "|";
      c.unit = g.unit;
      c.measured = std::abs(g.value);
      c.limit = g.limit_abs;
      c.margin = g.limit_abs - c.measured;
      c.expanded = g.expanded_u;
      c.pass = accepted;
      c.outcome = c.pass ? Outcome::kPass : Outcome::kFail;  // a store of version 3 knows no more
      ValueOf(kOutcomeNames, g.judgement, &c.outcome);
      u.verdict->criteria.push_back(c);
    }
    result.Add(std::move(u));
  }
  return result;
}

std::string YieldPageHtml(const std::string& store, YieldGroup by, const std::vector<GroupYield>& yields) {
  const std::string group = NameOf(kYieldGroupNames, by);
  return Page("Yield by " + group, store, {YieldBars(by, yields)},
              [&](Html* h, const std::vector<Svg>& svgs, const std::string& failure) {
                h->Element("p", "Each unit counted once, by its latest fit, in that fit's " + group + ".",
                           {{"class", "note"}});
                h->Open("table").Open("thead");
                Row(h, {group, "units", "passed", "failed", "not fitted", "yield"}, "th");
                h->Close("thead").Open("tbody");
                for (const GroupYield& y : yields) {
                  h->Open("tr", {{"data-group", y.group}}).Element("td", GroupLabel(by, y.group));
                  Num(h, Count(y.units));
                  Num(h, Count(y.passed));
                  Num(h, Count(y.failed));
                  Num(h, Count(y.not_fitted));
                  const double pct = YieldPct(y);
                  Num(h, YieldCell(y), {{"data-yield", std::isnan(pct) ? "" : FormatDouble(pct)}});
                  h->Close("tr");
                }
                h->Close("tbody").Close("table");
                internal::Plots(h, svgs, failure);
              });
}

std::string TrendPageHtml(const std::string& store, const std::string& figure,
                          const std::vector<TrendPoint>& points) {
  std::vector<PlotFigure> figures;
  if (!points.empty()) figures.push_back(TrendPlot(figure, points));
  return Page(figure + " over time", store, figures,
              [&](Html* h, const std::vector<Svg>& svgs, const std::string& failure) {
                internal::Plots(h, svgs, failure);
                h->Element("h2", "Drift per station: the mean of each month");
                h->Open("table").Open("thead");
                Row(h, {"station", "month", "fits", "mean", "1-sigma", "unit"}, "th");
                h->Close("thead").Open("tbody");
                for (const MonthlyMean& m : MonthlyMeans(points)) {
                  h->Open("tr", {{"data-station", m.station}, {"data-month", m.month}})
                      .Element("td", m.station.empty() ? "(no station)" : m.station)
                      .Element("td", m.month);
                  Num(h, Count(m.count));
                  Num(h, FormatDouble(m.mean), {{"data-mean", FormatDouble(m.mean)}});
                  Num(h, FormatDouble(m.sigma));
                  h->Element("td", m.unit);
                  h->Close("tr");
                }
                h->Close("tbody").Close("table");
                h->Element("h2", "Every fit");
                h->Open("table").Open("thead");
                Row(h, {"time (UTC)", "station", "serial", "lot", "value", "1-sigma", "U (k = 2)"}, "th");
                h->Close("thead").Open("tbody");
                for (const TrendPoint& p : points) {
                  h->Open("tr", {{"data-serial", p.serial}})
                      .Element("td", p.time_utc)
                      .Element("td", p.station)
                      .Element("td", p.serial)
                      .Element("td", p.lot);
                  Num(h, FormatDouble(p.value));
                  Num(h, p.sigma >= 0 ? FormatDouble(p.sigma) : "");
                  Num(h, p.expanded_u >= 0 ? FormatDouble(p.expanded_u) : "",
                      {{"data-u", FormatDouble(p.expanded_u)}});
                  h->Close("tr");
                }
                h->Close("tbody").Close("table");
              });
}

std::string SerialPageHtml(const std::string& store, const std::string& serial,
                           const std::vector<StoredFit>& fits) {
  return Page(
      "Calibrations of " + serial, store, {}, [&](Html* h, const std::vector<Svg>&, const std::string&) {
        h->Open("table").Open("thead");
        h->Open("tr");
        for (const char* heading :
             {"fitted (UTC)", "station", "lot", "unit", "status", "verdict", "software", "message"})
          h->Element("th", heading);
        for (const std::string& name : kSummaryFigures) h->Element("th", name);
        h->Close("tr").Close("thead").Open("tbody");
        for (const StoredFit& f : fits) {
          h->Open("tr", {{"data-fit", FitKey(f)}});
          for (const std::string* text :
               {&f.time_utc, &f.station, &f.lot, &f.unit, &f.status, &f.verdict, &f.software, &f.message})
            h->Element("td", *text);
          for (const std::string& name : kSummaryFigures) {
            const StoredFigure* g = FindFigure(f.figures, name);
            Num(h, g ? FormatDouble(g->value) : "");
          }
          h->Close("tr");
        }
        h->Close("tbody").Close("table");
      });
}

}  // namespace imufit
