#include "imufit/factory/lot_history.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "imufit/io/key_figures.h"

namespace imufit {
namespace {

// d2 of a moving range of two: E|x_i - x_(i-1)| = 1.128 sigma for normal x.
constexpr double kMovingRangeD2 = 1.128;

// The intersection of two intervals (each side the tighter one).
LimitInterval Intersect(const LimitInterval& a, const LimitInterval& b) {
  LimitInterval both;
  both.lower = !a.lower ? b.lower : !b.lower ? a.lower : std::max(*a.lower, *b.lower);
  both.upper = !a.upper ? b.upper : !b.upper ? a.upper : std::min(*a.upper, *b.upper);
  both.symmetric = a.symmetric && b.symmetric;
  return both;
}

}  // namespace

const std::vector<std::string> kLotTrendFigures = {
    "gyro_bias_dps.x", "gyro_bias_dps.y", "gyro_bias_dps.z",       "accel_bias_mg.x",
    "accel_bias_mg.y", "accel_bias_mg.z", "gyro_residual_rms_dps", "accel_residual_rms_mg"};

std::optional<LimitInterval> FigureLimits(const std::string& figure, const Limits& limits) {
  const size_t dot = figure.find('.');
  const std::string quantity = figure.substr(0, dot);
  const std::string axis = dot == std::string::npos ? "" : figure.substr(dot + 1);
  // A scale figure ("gyro_scale_per_dps") is judged by the scale errors of its group
  // ("gyro_scale_error_ppm", "_pct"): |S / nominal - 1| < limit.
  const KeyFigure* figure_quantity = FindKeyFigure(quantity);
  const bool coefficient =
      figure_quantity != nullptr && figure_quantity->source == FigureSource::kCoefficient;
  std::optional<LimitInterval> interval;
  for (const LimitCriterion& criterion : limits.criteria) {
    if (criterion.kind == LimitKind::kCoverage || criterion.statistic == LimitStatistic::kSigma) continue;
    if (!axis.empty() &&
        std::find(criterion.axes.begin(), criterion.axes.end(), axis) == criterion.axes.end())
      continue;
    LimitInterval allowed;
    if (criterion.quantity == quantity && criterion.kind == LimitKind::kFigure) {
      allowed.upper = criterion.max_abs;  // a residual RMS: one-sided
    } else if (criterion.quantity == quantity) {
      allowed = {-criterion.max_abs, criterion.max_abs, true};
    } else if (const KeyFigure* error = FindLimitQuantity(criterion.quantity);
               coefficient && error != nullptr && error->source == FigureSource::kScaleError &&
               std::string(error->path) == figure_quantity->path) {
      const double nominal = limits.NominalScaleFigure(IsGyroFigure(*error));
      if (!(nominal > 0.0)) continue;
      const double fraction = criterion.max_abs * (1.0 / error->per_unit);  // 1e-6 per ppm, 1e-2 per %
      allowed = {nominal * (1.0 - fraction), nominal * (1.0 + fraction), false};
    } else {
      continue;
    }
    interval = interval ? Intersect(*interval, allowed) : allowed;
  }
  return interval;
}

FigureView ViewWithLimits(double lo, double hi, const std::optional<LimitInterval>& limits) {
  FigureView view;
  view.range = {lo, hi};
  if (!limits) return view;
  const double reach = kLimitViewReach * (hi - lo);
  if (limits->lower && *limits->lower >= lo - reach) {
    view.lower_in_view = true;
    view.range[0] = std::min(lo, *limits->lower);
  }
  if (limits->upper && *limits->upper <= hi + reach) {
    view.upper_in_view = true;
    view.range[1] = std::max(hi, *limits->upper);
  }
  return view;
}

MeanSigma MeanAndSigma(const std::vector<double>& values) {
  MeanSigma m;
  m.count = static_cast<int>(values.size());
  if (values.empty()) return m;
  double sum = 0.0;
  for (double v : values) sum += v;
  m.mean = sum / m.count;
  double squares = 0.0;
  for (double v : values) squares += (v - m.mean) * (v - m.mean);
  m.sigma = m.count > 1 ? std::sqrt(squares / (m.count - 1)) : 0.0;
  return m;
}

double WithinSigma(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  double ranges = 0.0;
  for (size_t i = 1; i < values.size(); ++i) ranges += std::abs(values[i] - values[i - 1]);
  return ranges / (values.size() - 1) / kMovingRangeD2;
}

std::optional<double> Capability(double mean, double sigma, const LimitInterval& limits) {
  if (!(sigma > 0.0) || (!limits.lower && !limits.upper)) return std::nullopt;
  double margin = INFINITY;
  if (limits.upper) margin = std::min(margin, *limits.upper - mean);
  if (limits.lower) margin = std::min(margin, mean - *limits.lower);
  return margin / (3.0 * sigma);
}

LotHistory MakeLotHistory(ResultsStore* store, const std::string& current_lot, const Limits* limits,
                          const std::vector<std::string>& figures) {
  LotHistory h;
  h.store_path = store->path();
  h.lots = store->Yield("");
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < h.lots.size(); ++i) {
    const LotYield& y = h.lots[i];
    index[y.lot] = i;
    h.yield_pct.push_back(y.units > 0 ? 100.0 * y.passed / y.units : 0.0);
    if (y.lot == current_lot) h.current = static_cast<int>(i);
  }
  // Per figure, per lot: count, mean and sigma, computed by the store.
  std::vector<LotTrend> trends(figures.size());
  std::map<std::string, size_t> figure_index;
  for (size_t f = 0; f < figures.size(); ++f) {
    figure_index.emplace(figures[f], f);
    trends[f].name = figures[f];
    trends[f].count.assign(h.lots.size(), 0);
    trends[f].mean.assign(h.lots.size(), NAN);
    trends[f].sigma.assign(h.lots.size(), NAN);
  }
  for (const LotFigureStats& s : store->LotStats(figures)) {
    const auto lot = index.find(s.lot);
    if (lot == index.end()) continue;
    LotTrend& trend = trends[figure_index.at(s.figure)];
    trend.unit = s.figure_unit;
    trend.count[lot->second] = s.count;
    trend.mean[lot->second] = s.mean;
    trend.sigma[lot->second] = s.sigma;
  }
  for (size_t f = 0; f < figures.size(); ++f) {
    LotTrend& trend = trends[f];
    const std::string& name = figures[f];
    if (trend.unit.empty()) continue;  // no lot has it
    if (limits != nullptr) trend.limits = FigureLimits(name, *limits);
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < trend.mean.size(); ++i) {
      if (trend.count[i] == 0) continue;
      lo = std::min(lo, trend.mean[i] - trend.sigma[i]);
      hi = std::max(hi, trend.mean[i] + trend.sigma[i]);
    }
    trend.view = ViewWithLimits(lo, hi, trend.limits);
    h.trends.push_back(std::move(trend));
  }
  return h;
}

}  // namespace imufit
