// imufit — the hand procedure file (docs/spec.md section 2, "hand procedure"): a calibration
// session by hand described before anyone records it, for `imufit plan check` (plan/hand_check.h).
//
//   format: imufit-hand-procedure
//   version: 1
//   poses: 12                 # rests (at least 9)
//   dwell_s: 10               # each rest, s
//   turn_s: 2                 # each turn between two rests, s
//   rate_hz: 100              # the logger's sample rate
//   up: any                   # the axes pointing up at the rests, in turn: any (faces, then corners),
//                             #   or a list of +x, -x, +y, -y, +z, -z, corners, or [x, y, z] vectors
//   tilt_deg: [10, 30]        # how far a hand holds a rest off the nominal direction
//   twist_axes: any           # what a turn twists about besides bringing gravity to the next rest:
//                             #   any (a random direction), none, or a list of x, y, z
//   twist_deg: [20, 90]       # the twist's angle
//   temp_c: 25                # the unit's temperature (at the end of a warm-up)
//   warmup_c: 0               # a warm-up: the session starts this much colder, degC
//   warmup_tau_s: 300
//   bias_temp_order: 0        # the field fit's orders in temperature (fit --field --bias-temp-order)
//   scale_temp_order: 0
//   gravity_mps2: 9.81274     # or latitude_deg (and height_m): local gravity; else standard gravity
//
// Every key but format and version is optional (the defaults above). The reader converts nothing:
// degrees stay degrees (the names say so); it refuses unknown keys, values out of range and
// gravity given twice, with the file, line and column.
#ifndef IMUFIT_IO_HAND_PROCEDURE_H_
#define IMUFIT_IO_HAND_PROCEDURE_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace imufit {

inline constexpr int kHandProcedureFormatVersion = 1;
inline constexpr const char* kHandProcedureFormat = "imufit-hand-procedure";

struct HandProcedure {
  std::string path;
  int poses = 12;
  double dwell_s = 10.0;
  double turn_s = 2.0;
  double rate_hz = 100.0;
  std::vector<Eigen::Vector3d> up;  // the nominal up directions, body frame; empty: any
  std::array<double, 2> tilt_deg{10.0, 30.0};
  std::vector<int> twist_axes;                  // 0 x, 1 y, 2 z; empty: any direction
  std::array<double, 2> twist_deg{20.0, 90.0};  // {0, 0}: no twist (twist_axes: none)
  double temp_c = 25.0;
  double warmup_c = 0.0;
  double warmup_tau_s = 300.0;
  int bias_temp_order = 0;
  int scale_temp_order = 0;
  std::optional<double> gravity_mps2;
  std::optional<double> latitude_deg;
  double height_m = 0.0;
};

// Whether `path` holds a YAML mapping whose `format` is kHandProcedureFormat (false for anything else,
// unreadable files included: their reader says what is wrong).
bool IsHandProcedureFile(const std::string& path);
HandProcedure ReadHandProcedure(const std::string& path);
// The same from `text`, which messages name `name`.
HandProcedure ReadHandProcedureText(const std::string& text, const std::string& name);

}  // namespace imufit

#endif  // IMUFIT_IO_HAND_PROCEDURE_H_
