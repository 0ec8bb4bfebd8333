// imufit — engineering units at the edge: the SI conversions through which files and options
// in the units a test engineer reads (deg/s, mg, deg/h, ...) meet the SI values inside model/,
// fit/ and noise/ (noise files, limits, command-line options). How a calibration's coefficients are
// presented in those units, with their 1-sigma, is the report side's
// (factory/engineering_units.h).
//
// Noise terms (IEEE Std 952, noise/noise_model.h) in engineer units:
//   gyro   ARW deg/sqrt(h) = N * (180/pi) * 60 (sqrt(h) = 60 sqrt(s)); bias instability deg/h =
//          B * (180/pi) * 3600; RRW deg/h/sqrt(h) = K * (180/pi) * 3600 * 60
//   accel  VRW m/s/sqrt(h) = N * 60; bias instability micro-g = B / g0 * 1e6;
//          acceleration random walk m/s/h/sqrt(h) = K * 3600 * 60
#ifndef IMUFIT_IO_UNITS_H_
#define IMUFIT_IO_UNITS_H_

#include <cmath>

#include "imufit/model/constants.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

inline constexpr double kSecondsPerHour = 3600.0;
inline constexpr double kSqrtSecondsPerSqrtHour = 60.0;

inline double DpsFromRadps(double radps) { return radps * kRadToDeg; }
inline double DphFromRadps(double radps) { return radps * kRadToDeg * kSecondsPerHour; }
inline double MgFromMps2(double mps2) { return mps2 / kStandardGravityMps2 * 1e3; }
inline double UgFromMps2(double mps2) { return mps2 / kStandardGravityMps2 * 1e6; }
inline double RadpsFromDph(double dph) { return dph * kDegToRad / kSecondsPerHour; }
inline double Mps2FromUg(double ug) { return ug * 1e-6 * kStandardGravityMps2; }
// Angle random walk: rad/sqrt(s) (= rad/s/sqrt(Hz)) to deg/sqrt(h).
inline double DegPerSqrtHrFromRadPerSqrtS(double value) {
  return value * kRadToDeg * kSqrtSecondsPerSqrtHour;
}

}  // namespace imufit

#endif  // IMUFIT_IO_UNITS_H_
