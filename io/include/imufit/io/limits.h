// imufit — the acceptance limits file (docs/factory.md): what a unit must meet to pass.
//
//   format: imufit-limits
//   version: 1
//   name: "MEMS-A acceptance, rev B"       # optional, printed with the verdict
//   nominal:                                # needed by the *_scale_error_* quantities
//     gyro_scale: 939.65                    #   raw per rad/s
//     accel_scale: 208.838                  #   raw per m/s^2
//   criteria:
//     - {quantity: gyro_bias_dps, max_abs: 0.5}                  # every axis
//     - {quantity: gyro_g_sensitivity_dpsg, max_abs: 0.05, axes: [xx, yy, zz]}
//     - {quantity: gyro_bias_dps, statistic: sigma, max_abs: 0.01}   # the 1-sigma, not the value
//     - {quantity: fit_temp_range_c, covers: [-20, 60]}    # within kDefaultCoversToleranceC
//     - {quantity: accel_bias_mg, min: -20, max: 35}      # the signed value, either side optional
//     - {quantity: gyro_bias_dps, statistic: largest, over: [-40, 85], max_abs: 0.5}  # worst |value|
//     - {quantity: gyro_bias_dps, statistic: variation, max_abs: 0.1}  # max - min over the fitted range
//     - {quantity: gyro_residual_max_dps, max_abs: 0.02}  # the worst window error at any temperature
//   decision_rule: guarded                  # simple (the default) or guarded (ILAC-G8)
//   guard_band: 1.0                         # guarded: w as a multiple of the figure's U (default 1)
//
// The decision rule (ILAC-G8:09/2019): a value whose interval +-U reaches over its limit is a
// "conditional pass" (inside the limit) or a "conditional fail" (outside). Simple acceptance passes
// the value inside its limit; guarded acceptance passes it only inside the limit less w = guard_band x U.
//
// Quantities are the key figures of kKeyFigures (key_figures.h) a limits file may name: the 25 degC
// values of coefficients in familiar units, fit residual RMS values, the noise figures, the
// certificate's largest window errors, and the fitted temperature range. The reader checks every name, axis
// and number and throws InputError at file:line:column; evaluation is imufit::factory's.
#ifndef IMUFIT_IO_LIMITS_H_
#define IMUFIT_IO_LIMITS_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/io/key_figures.h"

namespace imufit {

inline constexpr int kLimitsFormatVersion = 1;

// k of an expanded uncertainty U = k sigma (GUM; about 95 % for a normal distribution): the U that
// limits are judged with, that certificates print and that the results store keeps.
inline constexpr double kCoverageFactor = 2.0;

// The quantities a limits file may name: the key figures with `in_limits` (key_figures.h); nullptr
// for any other name.
const KeyFigure* FindLimitQuantity(const std::string& quantity);
// Their names, comma-separated, in table order: what a message about an unknown one lists.
std::string LimitQuantityNames();

// What of a coefficient is judged: its value at 25 degC, its 1-sigma there, or over a temperature
// range (`over:`, else the calibration's fitted range) the largest |value| (with min/max: the
// lowest and the highest value) or the variation, largest - smallest.
enum class LimitStatistic { kValue, kSigma, kLargest, kVariation };
// Temperatures a statistic over a range evaluates the polynomial at, ends included.
inline constexpr int kRangeStatisticPoints = 251;

enum class DecisionRule { kSimple, kGuarded };
// "simple", "guarded".
const char* DecisionRuleName(DecisionRule rule);

// How far the fitted range may fall short of a `covers` range, degC: a chamber that reads -40.2 ..
// 84.9 degC ran the -40..85 profile (its own reading tolerance). `covers_tolerance` overrides it.
inline constexpr double kDefaultCoversToleranceC = 0.5;

struct LimitCriterion {
  std::string quantity;  // a kKeyFigures name with in_limits
  LimitKind kind = LimitKind::kCoefficient;
  std::string unit;
  std::vector<std::string> axes;  // the axes checked (all of the quantity's when not given)
  LimitStatistic statistic = LimitStatistic::kValue;
  double max_abs = 0.0;  // kCoefficient, kFigure: the limit, > 0; 0 when min/max are given instead
  // kCoefficient, kFigure: the signed value must lie within [min, max] (either may be absent).
  std::optional<double> min, max;
  std::array<double, 2> covers_c{0.0, 0.0};  // kCoverage: lo < hi
  double covers_tolerance_c = kDefaultCoversToleranceC;
  // kLargest, kVariation: the range, degC; nullopt: the calibration's fitted range.
  std::optional<std::array<double, 2>> over_c;
};

struct Limits {
  std::string path;
  std::string name;
  double nominal_gyro_scale = 0.0;   // raw per rad/s; 0: not given
  double nominal_accel_scale = 0.0;  // raw per m/s^2; 0: not given
  std::vector<LimitCriterion> criteria;
  DecisionRule decision_rule = DecisionRule::kSimple;
  double guard_band_u = 1.0;  // guarded acceptance: w = guard_band_u x U

  // The nominal scale in the unit of the scale figures (key_figures.h): raw/(deg/s) for the gyro,
  // raw/g for the accelerometer; 0: not given.
  double NominalScaleFigure(bool gyro) const {
    return gyro ? nominal_gyro_scale / kRadToDeg : nominal_accel_scale * kStandardGravityMps2;
  }
};

Limits ReadLimits(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_LIMITS_H_
