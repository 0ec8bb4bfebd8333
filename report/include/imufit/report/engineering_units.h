// imufit — a calibration's coefficients as a test engineer reads them: the report side of the
// engineering units (the SI conversions themselves are io/units.h's), for key figures,
// acceptance limits, certificates and lot pages. Everything inside model/, fit/ and noise/ stays SI.
//
// A calibration coefficient C(T) (docs/conventions.md) is shown at a temperature T as
//   gyro bias       deg/s        = V_g(T) / S_g(T) * 180/pi
//   accel bias      mg           = V_a(T) / S_a(T) / g0 * 1e3
//   gyro scale      raw/(deg/s)  = S_g(T) * pi/180
//   accel scale     raw/g        = S_a(T) * g0
//   misalignment    mrad         = M_ij(T) * 1e3
//   g-sensitivity   deg/s/g      = H_ij(T) / S_g,i(T) * 180/pi * g0          (g0 = 9.80665 m/s^2)
// always through the model's own polynomial and temperature basis (a calibration whose
// reference_temp_c is not 25 degC gives the same figures as its 25 degC twin). The 1-sigma at T
// takes the terms as independent, sqrt(sum_k (sigma_k x^k)^2) times the same factor (exact at the
// reference temperature, where x = 0; indicative elsewhere: the file holds no correlations).
#ifndef IMUFIT_REPORT_ENGINEERING_UNITS_H_
#define IMUFIT_REPORT_ENGINEERING_UNITS_H_

#include <cmath>

#include "imufit/io/units.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

// The temperature at which key figures are quoted, degC (whatever the calibration's reference).
inline constexpr double kFigureTempC = 25.0;

enum class Sensor { kGyro, kAccel };

// A value in engineering units with its 1-sigma (< 0: none known).
struct EngineeringValue {
  double value = 0.0;
  double sigma = -1.0;
};

// The unit in which EngineeringCoefficient() states a coefficient ("deg/s", "mg", "raw/(deg/s)",
// "raw/g", "mrad", "deg/s/g").
inline const char* EngineeringUnit(Sensor sensor, int coefficient) {
  const bool gyro = sensor == Sensor::kGyro;
  if (coefficient < kScaleCoefficient) return gyro ? "deg/s" : "mg";
  if (coefficient < kMisalignmentCoefficient) return gyro ? "raw/(deg/s)" : "raw/g";
  if (coefficient < kGSensitivityCoefficient) return "mrad";
  return "deg/s/g";
}

// The factor f(T) that states coefficient `coefficient` (layout of sensor_model.h) of `sensor` at
// `temp_c` in the unit of EngineeringUnit(): value = f(T) * C(T) (the table above). It depends on
// the scale factors only, so it also states any other value of that coefficient at T (a window's
// own estimate) and its 1-sigma.
inline double EngineeringFactor(const SensorModel& model, Sensor sensor, int coefficient, double temp_c) {
  const bool gyro = sensor == Sensor::kGyro;
  const double* params = gyro ? model.gyro.data() : model.accel.data();
  const double x = model.basis.Argument(temp_c);
  const auto scale = [&](int axis) {
    return EvaluateTemperaturePolynomial(params + (kScaleCoefficient + axis) * kPolynomialTerms, x);
  };
  if (coefficient < kScaleCoefficient) {  // bias over the same axis' scale
    return gyro ? kRadToDeg / scale(coefficient) : 1e3 / (scale(coefficient) * kStandardGravityMps2);
  }
  if (coefficient < kMisalignmentCoefficient) return gyro ? kDegToRad : kStandardGravityMps2;
  if (coefficient < kGSensitivityCoefficient) return 1e3;
  return kRadToDeg * kStandardGravityMps2 /
         scale((coefficient - kGSensitivityCoefficient) / 3);  // row i over S_g,i
}

// Coefficient `coefficient` (layout of sensor_model.h) of `sensor` at `temp_c`, in the unit of
// EngineeringUnit(); `sigma` (same layout as `model`, its basis unused) may be null.
inline EngineeringValue EngineeringCoefficient(const SensorModel& model, const SensorModel* sigma,
                                               Sensor sensor, int coefficient, double temp_c) {
  const bool gyro = sensor == Sensor::kGyro;
  const double* params = gyro ? model.gyro.data() : model.accel.data();
  const double* sigmas = sigma == nullptr ? nullptr : gyro ? sigma->gyro.data() : sigma->accel.data();
  const double x = model.basis.Argument(temp_c);
  const double factor = EngineeringFactor(model, sensor, coefficient, temp_c);
  EngineeringValue result;
  result.value = EvaluateTemperaturePolynomial(params + coefficient * kPolynomialTerms, x) * factor;
  if (sigmas != nullptr) {
    double variance = 0.0, power = 1.0;
    for (int k = 0; k < kPolynomialTerms; ++k, power *= x) {
      const double term = sigmas[coefficient * kPolynomialTerms + k] * power;
      variance += term * term;
    }
    result.sigma = std::sqrt(variance) * std::abs(factor);
  }
  return result;
}

// ppm of ScaleChangePpm() per raw unit of scale factor: 1e6 / S(kFigureTempC). The change of any
// value S of that scale factor is (S / S(kFigureTempC) - 1) * 1e6.
inline double ScaleChangePpmPerRaw(const SensorModel& model, Sensor sensor, int axis) {
  const double* params = (sensor == Sensor::kGyro ? model.gyro.data() : model.accel.data()) +
                         (kScaleCoefficient + axis) * kPolynomialTerms;
  return 1e6 / EvaluateTemperaturePolynomial(params, model.basis.Argument(kFigureTempC));
}

// The relative change of a scale factor from its kFigureTempC value, ppm, with the 1-sigma of the
// change (the terms beyond the one at kFigureTempC; exact for a 25 degC reference).
inline EngineeringValue ScaleChangePpm(const SensorModel& model, const SensorModel* sigma, Sensor sensor,
                                       int axis, double temp_c) {
  const bool gyro = sensor == Sensor::kGyro;
  const double* params =
      (gyro ? model.gyro.data() : model.accel.data()) + (kScaleCoefficient + axis) * kPolynomialTerms;
  const double* sigmas = sigma == nullptr ? nullptr
                                          : (gyro ? sigma->gyro.data() : sigma->accel.data()) +
                                                (kScaleCoefficient + axis) * kPolynomialTerms;
  const double x = model.basis.Argument(temp_c), x0 = model.basis.Argument(kFigureTempC);
  const double ppm_per_raw = ScaleChangePpmPerRaw(model, sensor, axis);
  EngineeringValue result;
  result.value = EvaluateTemperaturePolynomial(params, x) * ppm_per_raw - 1e6;
  if (sigmas != nullptr) {
    double variance = 0.0, power = 1.0, power0 = 1.0;
    for (int k = 0; k < kPolynomialTerms; ++k, power *= x, power0 *= x0) {
      const double term = sigmas[k] * (power - power0);  // the change's sensitivity to term k
      variance += term * term;
    }
    result.sigma = std::sqrt(variance) * std::abs(ppm_per_raw);
  }
  return result;
}

}  // namespace imufit

#endif  // IMUFIT_REPORT_ENGINEERING_UNITS_H_
