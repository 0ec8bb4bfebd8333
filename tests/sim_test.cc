// Tests of sim/: the simulator's samples against the shared model it claims to invert (noise-free
// raw outputs corrected by the truth give the truth back), its noise against the densities asked
// for, its determinism, and the station effects it adds (lost samples, jitter, quantisation,
// saturation, a temperature ramp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "imufit/model/constants.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"
#include "imufit/model/sensor_model.h"
#include "imufit/sim/simulator.h"
#include "test_models.h"

namespace imufit {
namespace {

// Absolute, worst case: a noise-free sample corrected by its own truth (rad/s and m/s^2); the
// round trip through counts of order 1e4 keeps about 12 digits.
constexpr double kRoundTripTolerance = 1e-9;
// Relative, worst case: a sample standard deviation over 20,000 samples is within about 1 % (1
// sigma) of the true one; 5 % is a 5-sigma bound.
constexpr double kNoiseSigmaTolerance = 0.05;

struct Recorded {
  std::vector<Sample> raw;
  std::vector<SegmentTruth> truth;
};

TableSite Site() {
  TableSite site;
  site.gravity_mps2 = 9.81274;
  site.latitude_rad = 52.0 * kDegToRad;
  return site;
}

// The cube's six faces, then a spin of 100 deg/s about each axis pointing up.
std::vector<TableSegment> FacesAndRates() {
  std::vector<TableSegment> plan;
  int id = 1;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      TableSegment segment;
      segment.id = id++;
      segment.up = sign * Eigen::Vector3d::Unit(axis);
      plan.push_back(segment);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    TableSegment segment;
    segment.id = id++;
    segment.up = Eigen::Vector3d::Unit(axis);
    segment.rate_radps = 100.0 * kDegToRad;
    plan.push_back(segment);
  }
  return plan;
}

Recorded Simulate(const SimulationOptions& options, const SensorModel& truth) {
  Recorded run;
  SimulateRun(options, Site(), FacesAndRates(), truth, [&](const Sample& raw, const SegmentTruth& t) {
    run.raw.push_back(raw);
    run.truth.push_back(t);
  });
  return run;
}

TEST(Simulator, NoiseFreeSamplesCorrectBackToTheirTruthThroughTheSharedModel) {
  const SensorModel model = testing::RandomMemsModel(21);
  SimulationOptions options;
  options.soak_temps_c = {-40.0, 25.0, 85.0};
  options.dwell_s = 1.0;
  options.transition_s = 0.5;
  options.rate_hz = 50.0;
  const Recorded run = Simulate(options, model);
  ASSERT_EQ(static_cast<long long>(run.raw.size()), options.SampleCount(FacesAndRates().size()));
  double worst_gyro = 0.0, worst_accel = 0.0;
  for (size_t i = 0; i < run.raw.size(); ++i) {
    Eigen::Vector3d omega_hat, a_hat;
    model.Correct(run.raw[i].temp_c, run.raw[i].gyro, run.raw[i].accel, &omega_hat, &a_hat);
    worst_gyro = std::max(worst_gyro, (omega_hat - run.truth[i].omega_radps).cwiseAbs().maxCoeff());
    worst_accel = std::max(worst_accel, (a_hat - run.truth[i].a_mps2).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst_gyro, kRoundTripTolerance);
  EXPECT_LT(worst_accel, kRoundTripTolerance);
  // Static faces feel the site's gravity
  EXPECT_NEAR(run.truth.front().a_mps2.norm(), Site().gravity_mps2, 1e-12);
  // and the Earth's rate: at least its vertical part, at most all of it.
  EXPECT_GE(run.truth.front().omega_radps.norm(),
            kEarthRateRadps * std::sin(Site().latitude_rad.value()) - 1e-15);
  EXPECT_LE(run.truth.front().omega_radps.norm(), kEarthRateRadps + 1e-15);
}

TEST(Simulator, WhiteNoiseHasTheDensityAskedForAndTheSameSeedGivesTheSameBits) {
  SimulationOptions options;
  options.dwell_s = 400.0;
  options.transition_s = 1.0;
  options.rate_hz = 50.0;
  options.gyro_noise_density = 1e-3;   // rad/s/sqrt(Hz)
  options.accel_noise_density = 2e-3;  // m/s^2/sqrt(Hz)
  options.seed = 7;
  const SensorModel identity = SensorModel::Identity();
  const Recorded run = Simulate(options, identity);
  // The first face: raw == truth + noise under the identity model.
  std::vector<double> gyro_x, accel_y;
  for (size_t i = 0; i < run.raw.size() && run.raw[i].segment == 1; ++i) {
    gyro_x.push_back(run.raw[i].gyro.x() - run.truth[i].omega_radps.x());
    accel_y.push_back(run.raw[i].accel.y() - run.truth[i].a_mps2.y());
  }
  ASSERT_GT(gyro_x.size(), 19000u);
  const auto sigma = [](const std::vector<double>& v) {
    double mean = 0.0, sum2 = 0.0;
    for (const double x : v) mean += x / v.size();
    for (const double x : v) sum2 += (x - mean) * (x - mean);
    return std::sqrt(sum2 / (v.size() - 1));
  };
  const double gyro_sigma = options.gyro_noise_density * std::sqrt(options.rate_hz);
  const double accel_sigma = options.accel_noise_density * std::sqrt(options.rate_hz);
  EXPECT_NEAR(sigma(gyro_x) / gyro_sigma, 1.0, kNoiseSigmaTolerance);
  EXPECT_NEAR(sigma(accel_y) / accel_sigma, 1.0, kNoiseSigmaTolerance);

  const Recorded again = Simulate(options, identity);
  ASSERT_EQ(again.raw.size(), run.raw.size());
  for (size_t i = 0; i < run.raw.size(); ++i) {
    ASSERT_EQ(again.raw[i].gyro, run.raw[i].gyro) << "sample " << i;
    ASSERT_EQ(again.raw[i].accel, run.raw[i].accel) << "sample " << i;
  }
  options.seed = 8;
  const Recorded other = Simulate(options, identity);
  EXPECT_NE(other.raw[10].gyro, run.raw[10].gyro);
}

TEST(Simulator, LostSamplesJitterQuantisationAndSaturationAsAStationHasThem) {
  const SensorModel model = testing::RandomMemsModel(22);
  SimulationOptions options;
  options.dwell_s = 20.0;
  options.transition_s = 1.0;
  options.rate_hz = 100.0;
  options.quantize = true;
  options.time_jitter_s = 0.002;
  options.drop_probability = 0.01;
  options.drop_burst = 3;
  options.gyro_full_scale_raw = 2000.0;
  const Recorded run = Simulate(options, model);
  const long long nominal = options.SampleCount(FacesAndRates().size());
  // About 1 % of the samples start a burst of 3 lost ones: 3 % lost, give or take.
  const double lost = 1.0 - static_cast<double>(run.raw.size()) / nominal;
  EXPECT_GT(lost, 0.02);
  EXPECT_LT(lost, 0.04);
  double worst_jitter = 0.0, worst_gyro = 0.0;
  for (size_t i = 0; i < run.raw.size(); ++i) {
    const Sample& s = run.raw[i];
    const double nominal_time = std::round(s.time_s * options.rate_hz) / options.rate_hz;
    worst_jitter = std::max(worst_jitter, std::abs(s.time_s - nominal_time));
    if (i > 0) {
      ASSERT_GT(s.time_s, run.raw[i - 1].time_s) << "sample " << i;
    }
    for (int axis = 0; axis < 3; ++axis) {
      ASSERT_EQ(s.gyro[axis], std::round(s.gyro[axis])) << "sample " << i;
      ASSERT_EQ(s.accel[axis], std::round(s.accel[axis])) << "sample " << i;
      worst_gyro = std::max(worst_gyro, std::abs(s.gyro[axis]));
    }
  }
  EXPECT_LE(worst_jitter, options.time_jitter_s + 1e-12);
  EXPECT_GT(worst_jitter, 0.5 * options.time_jitter_s);
  // 100 deg/s at about 16.5 counts per deg/s would reach 1650 counts plus bias: clipped at 2000 at most.
  EXPECT_LE(worst_gyro, options.gyro_full_scale_raw);
}

TEST(Simulator, ARampCrossesItsRangeOnceAcrossThePasses) {
  SimulationOptions options;
  options.ramp = true;
  options.ramp_from_c = -20.0;
  options.ramp_to_c = 60.0;
  options.passes = 3;
  options.dwell_s = 2.0;
  options.transition_s = 0.5;
  options.rate_hz = 20.0;
  const Recorded run = Simulate(options, SensorModel::Identity());
  ASSERT_FALSE(run.raw.empty());
  EXPECT_NEAR(run.raw.front().temp_c, options.ramp_from_c, 0.5);
  EXPECT_NEAR(run.raw.back().temp_c, options.ramp_to_c, 0.5);
  for (size_t i = 1; i < run.raw.size(); ++i) ASSERT_GE(run.raw[i].temp_c, run.raw[i - 1].temp_c);
}

TEST(Simulator, OptionsOutsideTheirRangeAreNamed) {
  SimulationOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.rate_hz = -1.0;
  EXPECT_NE(options.Validate().find("rate"), std::string::npos) << options.Validate();
}

}  // namespace
}  // namespace imufit
