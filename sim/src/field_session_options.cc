// FieldSessionOptions: its option table (base/option_table.h) and its checks.
#include "imufit/sim/field_session.h"

#include <string>

namespace imufit {
namespace {

OptionTable<FieldSessionOptions> MakeFieldSessionOptionTable() {
  using O = FieldSessionOptions;
  OptionTable<O> t;
  t.Number("poses", "--poses", "static poses of the hand session (at least 9)", "", &O::poses, AtLeast(9));
  t.Number("turn_s", "--turn-s", "mean duration of a turn between two poses", "s", &O::turn_s,
           PositiveFinite());
  t.Number("min_tilt_deg", "--min-tilt-deg", "least tilt of gravity off the nominal face or corner", "deg",
           &O::min_tilt_deg, Between(0.0, 45.0));
  t.Number("max_tilt_deg", "--max-tilt-deg", "largest tilt of gravity off the nominal face or corner", "deg",
           &O::max_tilt_deg, Between(0.0, 45.0));
  t.Number("gravity_mps2", "--gravity-mps2", "local gravity of the session", "m/s^2", &O::gravity_mps2,
           Between(9.7, 9.9));
  t.Number("warmup_c", "--warmup-c",
           "a warm-up: the unit starts this much below the first --temps and approaches it exponentially "
           "(0: none)",
           "degC", &O::warmup_c, Between(0.0, 200.0));
  t.Number("warmup_tau_s", "--warmup-tau-s", "time constant of the warm-up", "s", &O::warmup_tau_s,
           PositiveFinite());
  return t;
}

}  // namespace

const OptionTable<FieldSessionOptions>& FieldSessionOptionTable() {
  static const OptionTable<FieldSessionOptions> table = MakeFieldSessionOptionTable();
  return table;
}

std::string FieldSessionOptions::Validate() const {
  if (std::string problem = ValidateOptions(FieldSessionOptionTable(), *this); !problem.empty())
    return problem;
  if (min_tilt_deg > max_tilt_deg) {
    return "min_tilt_deg = " + OptionNumberText(min_tilt_deg) +
           ": more than max_tilt_deg = " + OptionNumberText(max_tilt_deg);
  }
  if (!(min_twist_deg >= 0.0 && min_twist_deg <= max_twist_deg && max_twist_deg <= 180.0)) {
    return "twist angles " + OptionNumberText(min_twist_deg) + ".." + OptionNumberText(max_twist_deg) +
           " deg: give 0 <= least <= largest <= 180";
  }
  for (int axis : twist_axes) {
    if (axis < 0 || axis > 2) return "twist axis " + std::to_string(axis) + ": give 0 (x), 1 (y) or 2 (z)";
  }
  for (const Eigen::Vector3d& d : directions) {
    if (!(d.norm() > 0.0) || !d.allFinite()) return "a pose direction must be a finite non-zero vector";
  }
  return "";
}

}  // namespace imufit
