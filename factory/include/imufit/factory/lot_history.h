// imufit — lot statistics: a key figure's acceptance interval, its process capability, and lots
// compared across the results store (the lot page's "across lots" section, `imufit history --lot
// --html`).
//
// Capability of a figure x over a lot of n units, against the interval [lower, upper] its limits
// allow (either side may be open):
//   Ppk = min(upper - mean, mean - lower) / (3 s),        s the sample standard deviation (n - 1)
//   Cpk = min(upper - mean, mean - lower) / (3 s_within), s_within = mean |x_i - x_(i-1)| / 1.128
// s_within is an individuals chart's short-term sigma: the mean moving range of consecutive units
// (the lot's order) over d2 = 1.128. A lot that drifts from unit to unit has Cpk > Ppk; one that
// does not, Cpk close to Ppk. A one-sided interval uses its one side.
//
// Across lots (MakeLotHistory): each lot's yield as ResultsStore::Yield() counts it (each unit by
// its latest fit), and per key figure the mean and sample standard deviation over the lot's fitted
// units (each by its latest fit). Lots in the order of their first fit.
#ifndef IMUFIT_FACTORY_LOT_HISTORY_H_
#define IMUFIT_FACTORY_LOT_HISTORY_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/io/limits.h"
#include "imufit/store/store.h"

namespace imufit {

// The values of a key figure its acceptance limits allow: lower < value < upper.
struct LimitInterval {
  std::optional<double> lower, upper;
  bool symmetric = false;  // |value| < upper (a max_abs criterion on the value itself)
};

// The interval the `value` criteria of `limits` allow a key figure (a Figure name such as
// "gyro_bias_dps.x", "gyro_scale_per_dps.y", "gyro_residual_rms_dps"): max_abs criteria on its
// quantity and axis, and scale-error criteria (ppm, %) around the limits' nominal scale for the
// scale figures. The tightest when several apply; nullopt when none does. Sigma and coverage
// criteria bound no value and are not counted.
std::optional<LimitInterval> FigureLimits(const std::string& figure, const Limits& limits);

// What a plot of a figure shows: its values' extent [lo, hi], widened to each side of the limits
// that lies within kLimitViewReach times (hi - lo) of it. A side farther off would squash the
// values into a line: the plot notes it instead.
inline constexpr double kLimitViewReach = 2.0;
struct FigureView {
  std::array<double, 2> range{0.0, 0.0};
  bool lower_in_view = false, upper_in_view = false;
};
FigureView ViewWithLimits(double lo, double hi, const std::optional<LimitInterval>& limits);

// Mean and sample standard deviation (0 below two values) of `values`.
struct MeanSigma {
  int count = 0;
  double mean = 0.0, sigma = 0.0;
};
MeanSigma MeanAndSigma(const std::vector<double>& values);

// s_within of the header: mean moving range / 1.128; 0 below two values.
double WithinSigma(const std::vector<double>& values);

// min(upper - mean, mean - lower) / (3 sigma); nullopt when sigma is 0 or the interval is open on
// both sides.
std::optional<double> Capability(double mean, double sigma, const LimitInterval& limits);

// The key figures whose lot means the lot page follows across lots.
extern const std::vector<std::string> kLotTrendFigures;

struct LotTrend {
  std::string name, unit;
  // Per lot of LotHistory::lots: units with the figure (0: none; then mean and sigma are NaN),
  // their mean and sample standard deviation.
  std::vector<int> count;
  std::vector<double> mean, sigma;
  std::optional<LimitInterval> limits;
  FigureView view;  // the lots' mean +- sigma and the limits in reach
};

struct LotHistory {
  std::string store_path;
  std::vector<LotYield> lots;     // oldest first
  std::vector<double> yield_pct;  // per lot: passed / units * 100
  int current = -1;               // the index of the lot the page is about; -1: not in the store
  std::vector<LotTrend> trends;   // one per figure asked for that any lot has
};

// Reads every lot of `store`. `current_lot` is highlighted (may be empty); `limits` (may be null)
// give each trend its interval.
LotHistory MakeLotHistory(ResultsStore* store, const std::string& current_lot, const Limits* limits,
                          const std::vector<std::string>& figures = kLotTrendFigures);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_LOT_HISTORY_H_
