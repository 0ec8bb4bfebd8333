// imufit — mathematical and physical constants, each defined once (SI units). Earth's rotation
// rate lives with the truth that uses it (rate_table.h).
//
// Plain double constexprs. Inside a function template on the scalar T (the model with a
// ceres::Jet), lift them as every stored double is lifted: T(kPi), never a double temporary.
#ifndef IMUFIT_MODEL_CONSTANTS_H_
#define IMUFIT_MODEL_CONSTANTS_H_

namespace imufit {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;  // rad per degree
inline constexpr double kRadToDeg = 180.0 / kPi;  // degrees per rad

// Standard gravity g0, m/s^2: the g of "mg", "micro-g" and "deg/s/g". A site's local gravity is
// TableSite::gravity_mps2.
inline constexpr double kStandardGravityMps2 = 9.80665;

}  // namespace imufit

#endif  // IMUFIT_MODEL_CONSTANTS_H_
