// FieldFitOptions: its option table (base/option_table.h) and its checks.
#include <cmath>

#include "imufit/fit/field_fit.h"
#include "imufit/model/local_gravity.h"

namespace imufit {
namespace {

OptionTable<FieldFitOptions> MakeFieldFitOptionTable() {
  using O = FieldFitOptions;
  OptionTable<O> t;
  t.Number("gravity_mps2", "--gravity-mps2", "local gravity: the length of every pose's specific force",
           "m/s^2", &O::gravity_mps2, Between(9.7, 9.9));
  t.OptionalNumber("latitude_deg", "--latitude",
                   "local gravity from the site instead: geodetic latitude (WGS-84 normal gravity)", "deg",
                   &O::latitude_deg, Between(-90.0, 90.0), "--gravity-mps2");
  t.Number("height_m", "--height-m", "with --latitude: height above the WGS-84 ellipsoid", "m", &O::height_m,
           Between(-500.0, 9000.0));
  t.Number("min_pose_s", "--min-pose-s", "a rest shorter than this is not a pose", "s", &O::min_pose_s,
           PositiveFinite());
  t.Number(
      "bias_temp_order", "--bias-temp-order",
      "over temperature (a warm-up, or several sessions): order of the biases' polynomials in temperature",
      "", &O::bias_temp_order, Between(0, 3));
  t.Number("scale_temp_order", "--scale-temp-order",
           "over temperature: order of the scale factors' polynomials in temperature (needs a wider spread)",
           "", &O::scale_temp_order, Between(0, 3));
  return t;
}

}  // namespace

const OptionTable<FieldFitOptions>& FieldFitOptionTable() {
  static const OptionTable<FieldFitOptions> table = MakeFieldFitOptionTable();
  return table;
}

std::string FieldFitOptions::Validate() const {
  if (std::string problem = ValidateOptions(FieldFitOptionTable(), *this); !problem.empty()) return problem;
  if (std::string problem = detection.Validate(); !problem.empty()) return problem;
  if (latitude_deg && gravity_mps2 != kStandardGravityMps2)
    return "gravity_mps2 and latitude_deg both given: local gravity is one or the other";
  if (!latitude_deg && height_m != 0.0) return "height_m needs latitude_deg (local gravity from the site)";
  if (min_poses < 9)
    return "min_poses = " + std::to_string(min_poses) + ": the accelerometer alone has 9 unknowns";
  if (!(near_direction_deg > 0.0 && near_direction_deg < 90.0))
    return "near_direction_deg must lie in (0, 90)";
  if (!(min_turn_about_axis_rad >= 0.0 && max_relative_scale_sigma > 0.0 &&
        max_misalignment_sigma_rad > 0.0)) {
    return "the observability thresholds must be > 0";
  }
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!(min_bias_temp_span_c > 0.0 && min_scale_temp_span_c > 0.0))
    return "the temperature spans must be > 0";
  return "";
}

double FieldFitOptions::GravityMps2() const {
  return latitude_deg ? NormalGravityMps2(*latitude_deg * kDegToRad, height_m) : gravity_mps2;
}

}  // namespace imufit
