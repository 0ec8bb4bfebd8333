// imufit — local gravity from latitude and height: the normal gravity of the WGS-84 ellipsoid
// (Somigliana's closed formula) with its second-order height correction (NIMA TR8350.2, 3rd ed.,
// eqs. 4-1 and 4-3). Normal gravity leaves out local anomalies (up to a few 1e-4 g in mountains): a
// measured value of the site's gravity, where known, is better.
#ifndef IMUFIT_MODEL_LOCAL_GRAVITY_H_
#define IMUFIT_MODEL_LOCAL_GRAVITY_H_

#include <cmath>

namespace imufit {

// g at geodetic latitude `latitude_rad` and ellipsoidal height `height_m`, m/s^2.
inline double NormalGravityMps2(double latitude_rad, double height_m) {
  constexpr double kEquatorMps2 = 9.7803253359;        // gamma_e
  constexpr double kSomiglianaK = 0.00193185265241;    // (b gamma_p - a gamma_e) / (a gamma_e)
  constexpr double kEccentricity2 = 0.00669437999013;  // e^2
  constexpr double kSemiMajorM = 6378137.0;            // a
  constexpr double kFlattening = 1.0 / 298.257223563;  // f
  constexpr double kM = 0.00344978650684;              // omega^2 a^2 b / GM
  const double s2 = std::sin(latitude_rad) * std::sin(latitude_rad);
  const double at_surface = kEquatorMps2 * (1.0 + kSomiglianaK * s2) / std::sqrt(1.0 - kEccentricity2 * s2);
  const double h = height_m / kSemiMajorM;
  return at_surface * (1.0 - 2.0 * (1.0 + kFlattening + kM - 2.0 * kFlattening * s2) * h + 3.0 * h * h);
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_LOCAL_GRAVITY_H_
