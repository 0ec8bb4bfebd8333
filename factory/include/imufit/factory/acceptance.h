// imufit — a unit's key figures and its acceptance verdict against a limits file.
//
// Key figures are the calibration's coefficients at 25 degC (term c0 of each cubic in
// dT = T - 25 degC) in the units a test engineer reads, each with its 1-sigma from the `sigma` tree:
//   gyro bias deg/s       = V_g / S_g * 180/pi           accel bias mg = V_a / S_a / g0 * 1e3
//   gyro scale raw/(deg/s) = S_g * pi/180                  accel scale raw/g = S_a * g0
//   misalignment mrad     = M_ij * 1e3
//   g-sensitivity deg/s/g = H_ij / S_g,i * 180/pi * g0     (g0 = 9.80665 m/s^2 per g)
// plus the fit's residual RMS (deg/s, mg) from the calibration's `fit:` block.
#ifndef IMUFIT_FACTORY_ACCEPTANCE_H_
#define IMUFIT_FACTORY_ACCEPTANCE_H_

#include <string>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/limits.h"

namespace imufit {

inline constexpr double kStandardGravityMps2 = 9.80665;  // m/s^2 per g, for mg and deg/s/g

struct Figure {
  std::string name;         // quantity.axis, e.g. "gyro_bias_dps.x", "gyro_residual_rms_dps"
  std::string coefficient;  // the calibration's path, e.g. "gyro.bias.x"; "fit.gyro_residual_rms"
  std::string unit;         // "deg/s", "mg", ...
  double value = 0.0;
  double sigma = -1.0;  // 1-sigma; < 0 when the calibration has none
};

// Every coefficient at 25 degC and the residual RMS values, in a fixed order.
std::vector<Figure> KeyFigures(const Calibration& calibration);
// The figure called `name` (or with that `coefficient` path); nullptr when there is none.
const Figure* FindFigure(const std::vector<Figure>& figures, const std::string& name);

struct CriterionResult {
  std::string name;  // e.g. "|gyro_bias_dps.x|", "sigma(gyro_bias_dps.x)", "fit_temp_range_c"
  std::string unit;
  double measured = 0.0;  // for coverage: the margin's side that binds
  double limit = 0.0;
  double margin = 0.0;  // limit - |measured| (coverage: degC to spare at the tighter end); >= 0 passes
  std::string measured_text;
  std::string limit_text;
  bool pass = false;
};

struct Verdict {
  std::string limits_name;
  std::vector<CriterionResult> criteria;
  bool pass = true;

  int Failed() const;
  // "|gyro_g_sensitivity_dpsg.xx| 0.0712 > 0.05 deg/s/g; ..." — the failed criteria, one line.
  std::string FailedSummary() const;
  // The table `imufit fit --limits` prints: criterion, measured, limit, margin, PASS/FAIL.
  std::string Table() const;
};

Verdict EvaluateLimits(const Limits& limits, const Calibration& calibration);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_ACCEPTANCE_H_
