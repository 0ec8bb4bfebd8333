// imufit — what the field fit's Monte Carlo tests (field_test.cc, field_sessions_test.cc) judge:
// the coefficient classes whose z-scores are taken together, and the z-scores of a fit against
// its truth, at 25 degC and at the coldest and warmest pose.
#ifndef IMUFIT_TESTS_FIELD_TEST_CLASSES_H_
#define IMUFIT_TESTS_FIELD_TEST_CLASSES_H_

#include <array>
#include <vector>

#include "imufit/fit/field_fit.h"
#include "imufit/model/sensor_model.h"

namespace imufit::testing {

// The coefficient classes whose z-scores are judged together.
struct CoefficientClass {
  const char* name;
  bool gyro;
  int first;  // coefficient index
  int count;
};
inline constexpr CoefficientClass kClasses[] = {
    {"gyro bias", true, kBiasCoefficient, 3},
    {"gyro scale", true, kScaleCoefficient, 3},
    {"gyro misalignment", true, kMisalignmentCoefficient, 6},
    {"gyro g-sensitivity", true, kGSensitivityCoefficient, 9},
    {"accel bias", false, kBiasCoefficient, 3},
    {"accel scale", false, kScaleCoefficient, 3},
    {"accel misalignment", false, kMisalignmentCoefficient, 6},
};

// (fitted - true) / sigma of every fitted coefficient (held ones, sigma 0, skipped) of a class,
// at 25 degC (the c0 terms).
inline std::vector<double> ZScores(const FieldFitSummary& fit, const SensorModel& truth,
                                   const CoefficientClass& k) {
  std::vector<double> z;
  for (int c = k.first; c < k.first + k.count; ++c) {
    const int i = c * kPolynomialTerms;
    const double sigma = k.gyro ? fit.sigma.gyro[i] : fit.sigma.accel[i];
    if (sigma == 0.0) continue;
    z.push_back(
        ((k.gyro ? fit.model.gyro[i] : fit.model.accel[i]) - (k.gyro ? truth.gyro[i] : truth.accel[i])) /
        sigma);
  }
  return z;
}

// (fitted - true) / sigma of a coefficient's value at the coldest and the warmest pose.
inline std::array<double, 2> ZAtEnds(const FieldFitSummary& fit, const SensorModel& truth, bool gyro,
                                     int coefficient) {
  std::array<double, 2> z{};
  const int i = coefficient * kPolynomialTerms;
  for (int end = 0; end < 2; ++end) {
    const double x = fit.pose_temp_range_c[end] - kReferenceTempC;
    const double fitted =
        EvaluateTemperaturePolynomial((gyro ? fit.model.gyro.data() : fit.model.accel.data()) + i, x);
    const double true_value =
        EvaluateTemperaturePolynomial((gyro ? truth.gyro.data() : truth.accel.data()) + i, x);
    const SensorModel& sigma = end == 0 ? fit.sigma_at_low : fit.sigma_at_high;
    z[end] = (fitted - true_value) / (gyro ? sigma.gyro.data() : sigma.accel.data())[i];
  }
  return z;
}

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_FIELD_TEST_CLASSES_H_
