// imufit — the robust losses of the fit and their names, shared by fit/ (which applies them:
// fit/thermal_fit.h, FitOptions::loss) and io/ (whose reader of a calibration's `fit:` record
// refuses a loss it does not name, at the key's line and column).
#ifndef IMUFIT_BASE_ROBUST_LOSS_H_
#define IMUFIT_BASE_ROBUST_LOSS_H_

#include <string>

#include "imufit/base/enum_names.h"

namespace imufit {

enum class RobustLoss { kNone, kHuber, kCauchy };

inline constexpr EnumName<RobustLoss> kRobustLossNames[] = {
    {RobustLoss::kNone, "none"}, {RobustLoss::kHuber, "huber"}, {RobustLoss::kCauchy, "cauchy"}};

// "none", "huber", "cauchy".
inline std::string RobustLossName(RobustLoss loss) { return NameOf(kRobustLossNames, loss); }

// Parses a name; on failure returns false and sets `error` to a message listing the names.
inline bool ParseRobustLoss(const std::string& name, RobustLoss* loss, std::string* error) {
  if (ValueOf(kRobustLossNames, name, loss)) return true;
  *error = "\"" + name + "\" is not a robust loss (" + AllNames(kRobustLossNames) + ")";
  return false;
}

}  // namespace imufit

#endif  // IMUFIT_BASE_ROBUST_LOSS_H_
