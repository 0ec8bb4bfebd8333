// imufit — what a batch's lot page says, computed in one place: MakeLotSummary() turns a batch's
// outcomes (and, with a results store, every lot's history) into a LotSummary of every number the
// page shows; the renderer (lot_page.h) only formats and draws it, and tests assert on this struct.
// Key figures are the units' figures at 25 degC (acceptance.h), every one the units have; outliers
// are judged robustly. LotSummaryCsv() is OUT_DIR/lot_summary.csv: every key figure with its
// 1-sigma and U, and each unit's calibration date.
#ifndef IMUFIT_FACTORY_LOT_SUMMARY_H_
#define IMUFIT_FACTORY_LOT_SUMMARY_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/batch.h"
#include "imufit/factory/lot_history.h"
#include "imufit/io/limits.h"

namespace imufit {

// Outliers: robust z = 0.6745 (x - median) / MAD beyond kOutlierRobustZ, and (when the unit's own
// 1-sigma is known) more than kOutlierOwnSigmas of its own sigmas from the median, so that noise
// between identical units is not flagged.
inline constexpr double kOutlierRobustZ = 3.5;
inline constexpr double kOutlierOwnSigmas = 3.0;
struct RobustZ {
  double z = 0.0;
  bool outlier = false;
};
// Robust z-scores of `values` (all 0 and no outliers with fewer than 3 values or a zero MAD);
// `sigmas` (each unit's own 1-sigma, < 0 unknown) may be empty.
std::vector<RobustZ> RobustZScores(const std::vector<double>& values, const std::vector<double>& sigmas = {});

struct LotUnitRow {
  std::string unit, serial, status, verdict, message;
  bool has_report = false;
  std::string label;  // the unit without the prefix all units share ("unit-07" -> "07"): axis labels
};

// Capability from fewer units than this is printed with its confidence interval and a caveat: Ppk's
// interval at kCapabilityConfidence (Bissell's normal approximation, z = kCapabilityZ).
inline constexpr int kCapabilityMinUnits = 30;
inline constexpr double kCapabilityConfidence = 0.95;
inline constexpr double kCapabilityZ = 1.959964;
// Ppk -+ z sqrt(1 / (9 n) + Ppk^2 / (2 (n - 1))); nullopt below two units.
std::optional<std::array<double, 2>> CapabilityInterval(double ppk, int n);

struct LotFigure {
  std::string name, unit;
  std::vector<std::string> units;  // per point: the unit folder
  std::vector<int> row;            // per point: the unit's index in LotSummary::rows (a strip plot's x)
  std::vector<double> value, sigma;
  std::vector<RobustZ> z;
  std::vector<bool> failed;          // the unit failed its limits (any criterion)
  std::vector<bool> outside_limits;  // this value itself lies outside this figure's limits
  double mean = 0.0, stdev = 0.0;
  std::array<double, 2> three_sigma{0.0, 0.0};  // mean -+ 3 stdev: where the lot's units fall
  double stdev_within = 0.0;                    // mean moving range / 1.128 (lot_history.h)
  std::optional<LimitInterval> limits;          // what the limits allow this figure; nullopt: no limit on it
  std::optional<double> ppk, cpk;               // against `limits` (lot_history.h)
  std::optional<std::array<double, 2>> ppk_interval;  // kCapabilityConfidence; with `ppk`
  bool few_units = false;  // fewer than kCapabilityMinUnits values: capability only indicative
  // A strip plot is drawn: a figure of kSummaryFigures, or one on which a unit failed (its value
  // outside this figure's limits, or a failed criterion of the unit naming it).
  bool plotted = false;
  FigureView view;  // what a strip plot shows: the values, mean +- 3 sigma, the limits in reach
};

struct LotOutlier {
  std::string unit, serial, figure, figure_unit;
  double value = 0.0, z = 0.0;
};

struct LotSummary {
  std::string lot, written_utc, software, git_revision;
  std::string limits_name;    // the limits file's name, or its path; empty without limits
  std::string decision_rule;  // the limits' decision rule in words (DecisionRuleText); empty without
  int units = 0, passed = 0, failed = 0, not_fitted = 0, errors = 0;
  // Units judged on a criterion within U of its limit (conditional pass or fail; also counted in
  // passed or failed as the decision rule decided).
  int conditional = 0;
  double yield_pct = 0.0;  // nan without limits: not judged
  std::vector<LotUnitRow> rows;
  std::vector<std::string> figure_names;  // every key figure a unit has, in KeyFigures() order
  std::string unit_prefix;                // what every unit's name starts with and the labels leave out
  std::vector<LotFigure> figures;
  std::vector<LotOutlier> outliers;
  std::optional<LotHistory> history;  // every lot of the results store, when the batch had one
};

// The key figures the units have (union, in the order of the first unit that has each).
std::vector<std::string> LotFigureNames(const BatchResult& batch);

// lot_summary.csv: `unit,serial,status,verdict,message,calibrated_utc`, then per key figure of
// LotFigureNames() `NAME,NAME.sigma,NAME.U` (1-sigma and k = 2; empty when the unit has none), one
// row per unit. Cells are the shortest decimal that reads back exactly; never non-finite.
std::string LotSummaryCsv(const BatchResult& batch);

LotSummary MakeLotSummary(const std::string& lot, const BatchResult& batch, const std::string& software,
                          const std::optional<Limits>& limits);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_LOT_SUMMARY_H_
