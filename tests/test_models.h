// Test helpers: random but realistic calibrations, seeded, for property tests.
#ifndef IMUFIT_TESTS_TEST_MODELS_H_
#define IMUFIT_TESTS_TEST_MODELS_H_

#include <cmath>
#include <random>

#include <vector>

#include "imufit/model/constants.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sensor_model.h"

namespace imufit::testing {

// A MEMS-like unit in counts: ~16.4 LSB per deg/s and 2048 LSB per g with ~1 % scale errors,
// biases of tens of counts, misalignments of a few mrad, g-sensitivity of a few hundredths of a
// deg/s per g, and temperature terms that change each coefficient by a few per cent of its
// spread over -40..85 degC. The polynomial is in powers of dT = T - 25 degC.
inline SensorModel RandomMemsModel(std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr double kGyroLsbPerRadps = 16.4 * 180.0 / M_PI;
  constexpr double kAccelLsbPerMps2 = 2048.0 / 9.80665;
  SensorModel model;
  const auto fill = [&](double* c, double value, double spread) {
    // spread: change over 60 degC; split among the powers of dT.
    c[0] = value;
    c[1] = spread * u(engine) / 60.0;
    c[2] = spread * u(engine) / (60.0 * 60.0);
    c[3] = spread * u(engine) / (60.0 * 60.0 * 60.0);
  };
  for (int axis = 0; axis < 3; ++axis) {
    fill(&model.gyro[(kBiasCoefficient + axis) * 4], 20.0 * u(engine), 10.0);
    fill(&model.gyro[(kScaleCoefficient + axis) * 4], kGyroLsbPerRadps * (1.0 + 0.01 * u(engine)),
         kGyroLsbPerRadps * 0.003);
    fill(&model.accel[(kBiasCoefficient + axis) * 4], 30.0 * u(engine), 8.0);
    fill(&model.accel[(kScaleCoefficient + axis) * 4], kAccelLsbPerMps2 * (1.0 + 0.01 * u(engine)),
         kAccelLsbPerMps2 * 0.002);
  }
  for (int m = 0; m < 6; ++m) {
    fill(&model.gyro[(kMisalignmentCoefficient + m) * 4], 0.004 * u(engine), 0.0005);
    fill(&model.accel[(kMisalignmentCoefficient + m) * 4], 0.003 * u(engine), 0.0004);
  }
  // 0.03 deg/s per g in counts per m/s^2.
  const double gsens = 0.03 * 16.4 / 9.80665;
  for (int h = 0; h < 9; ++h) {
    fill(&model.gyro[(kGSensitivityCoefficient + h) * 4], gsens * u(engine), 0.2 * gsens);
  }
  return model;
}

// Six static faces (with north) and +-100, +-300 deg/s about each axis (with a lever arm).
inline std::vector<TableSegment> SixPositionPlan(bool with_rates = true) {
  std::vector<TableSegment> segments;
  int id = 0;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      TableSegment s;
      s.id = id++;
      s.up = sign * Eigen::Vector3d::Unit(axis);
      s.north = Eigen::Vector3d::Unit((axis + 1) % 3);
      segments.push_back(s);
    }
  }
  if (!with_rates) return segments;
  for (int axis = 0; axis < 3; ++axis) {
    for (double rate_dps : {100.0, -100.0, 300.0, -300.0}) {
      TableSegment s;
      s.id = id++;
      s.up = Eigen::Vector3d::Unit(axis);
      s.rate_radps = rate_dps * kDegToRad;
      s.lever_arm_m = Eigen::Vector3d(0.01, 0.02, 0.005);
      segments.push_back(s);
    }
  }
  return segments;
}

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_TEST_MODELS_H_
