// Tests of the shared correction model: identity, exact inversion, exact polynomial rebasing,
// instantiation with ceres::Jet and autodiff Jacobians against central differences.
#include <random>

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "imufit/model/check.h"
#include "imufit/model/local_gravity.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sensor_model.h"
#include "imufit/model/temperature_polynomial.h"
#include "test_models.h"

namespace imufit {
namespace {

// Relative error allowed for correct(forward(x)) == x (worst case over all samples).
constexpr double kRoundTripRelTol = 1e-12;
// Central differences: relative step, and the worst-case relative agreement expected.
constexpr double kFiniteDifferenceStep = 1e-6;
constexpr double kJacobianRelTol = 1e-6;

// IMUFIT_CHECK is on in every build type (this suite runs in Release): a broken invariant aborts
// with its location and message instead of running on.
TEST(CheckDeathTest, AbortsInEveryBuildWithLocationAndMessage) {
  int evaluated = 0;
  IMUFIT_CHECK(++evaluated == 1, "evaluated once");
  EXPECT_EQ(evaluated, 1);
  EXPECT_DEATH(
      IMUFIT_CHECK(evaluated == 2, "one Jacobian column per free parameter"),
      "model_test.cc:[0-9]+: check failed: evaluated == 2 \\(one Jacobian column per free parameter\\)");
}

TEST(TemperaturePolynomial, RebaseIsExact) {
  const TemperatureBasis fit_basis{12.5, 62.5};
  const TemperatureBasis reference = TemperatureBasis::Reference();
  const Eigen::Vector4d c_fit(1.5, -0.3, 0.25, 0.7);
  const Eigen::Vector4d c_ref = RebaseTemperaturePolynomial(fit_basis, reference) * c_fit;
  for (double temp_c = -40.0; temp_c <= 85.0; temp_c += 5.0) {
    const double expected = EvaluateTemperaturePolynomial(c_fit.data(), fit_basis.Argument(temp_c));
    const double rebased = EvaluateTemperaturePolynomial(c_ref.data(), reference.Argument(temp_c));
    EXPECT_NEAR(rebased, expected, 1e-13 * (1.0 + std::abs(expected))) << temp_c;
  }
  // Back and forth is the identity.
  const Eigen::Matrix4d round_trip =
      RebaseTemperaturePolynomial(reference, fit_basis) * RebaseTemperaturePolynomial(fit_basis, reference);
  EXPECT_TRUE(round_trip.isIdentity(1e-12)) << round_trip;
}

TEST(SensorModel, IdentityCorrectsNothing) {
  const SensorModel identity = SensorModel::Identity();
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d gyro_m(u(engine), u(engine), u(engine));
    const Eigen::Vector3d accel_m(u(engine), u(engine), u(engine));
    Eigen::Vector3d omega_hat;
    Eigen::Vector3d a_hat;
    identity.Correct(u(engine), gyro_m, accel_m, &omega_hat, &a_hat);
    EXPECT_EQ(omega_hat, gyro_m);
    EXPECT_EQ(a_hat, accel_m);
  }
}

TEST(SensorModel, CorrectInvertsForwardAcrossTemperatures) {
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> temp(-40.0, 85.0);
  std::uniform_real_distribution<double> rate(-10.0, 10.0);   // rad/s
  std::uniform_real_distribution<double> force(-30.0, 30.0);  // m/s^2
  for (std::uint64_t unit = 0; unit < 5; ++unit) {
    const SensorModel model = testing::RandomMemsModel(unit);
    for (int i = 0; i < 200; ++i) {
      const double temp_c = temp(engine);
      const Eigen::Vector3d omega_true(rate(engine), rate(engine), rate(engine));
      const Eigen::Vector3d a_true(force(engine), force(engine), force(engine));
      Eigen::Vector3d gyro_m;
      Eigen::Vector3d accel_m;
      model.Forward(temp_c, omega_true, a_true, &gyro_m, &accel_m);
      Eigen::Vector3d omega_hat;
      Eigen::Vector3d a_hat;
      model.Correct(temp_c, gyro_m, accel_m, &omega_hat, &a_hat);
      EXPECT_LE((omega_hat - omega_true).norm(), kRoundTripRelTol * omega_true.norm())
          << unit << " " << temp_c;
      EXPECT_LE((a_hat - a_true).norm(), kRoundTripRelTol * a_true.norm()) << unit << " " << temp_c;
    }
  }
}

TEST(SensorModel, CoefficientsFollowTheLayout) {
  SensorModel model = SensorModel::Identity();
  model.gyro[(kMisalignmentCoefficient + 1) * 4] = 0.5;      // xz
  model.gyro[(kMisalignmentCoefficient + 4) * 4] = 0.25;     // zx
  model.gyro[(kGSensitivityCoefficient + 5) * 4 + 1] = 2.0;  // yz, c1
  const SensorCoefficients<double> c = CoefficientsAt(model.gyro.data(), kGyroCoefficients, 3.0);
  EXPECT_EQ(c.misalignment(0, 2), 0.5);
  EXPECT_EQ(c.misalignment(2, 0), 0.25);
  EXPECT_EQ(c.g_sensitivity(1, 2), 6.0);
  EXPECT_EQ(std::string(kCoefficientNames[kGSensitivityCoefficient + 5].group), "g_sensitivity");
  EXPECT_EQ(std::string(kCoefficientNames[kGSensitivityCoefficient + 5].axis), "yz");
}

// The correction, as a function of all parameters, evaluated with Jets (the fitter's scalar).
using Jet = ceres::Jet<double, kGyroParameters + kAccelParameters>;

void CorrectWithJets(const SensorModel& model, double temp_c, const Eigen::Vector3d& gyro_m,
                     const Eigen::Vector3d& accel_m, Eigen::Matrix<double, 6, 1>* value,
                     Eigen::Matrix<double, 6, kGyroParameters + kAccelParameters>* jacobian) {
  std::array<Jet, kGyroParameters> gyro;
  std::array<Jet, kAccelParameters> accel;
  for (int i = 0; i < kGyroParameters; ++i) gyro[i] = Jet(model.gyro[i], i);
  for (int i = 0; i < kAccelParameters; ++i) accel[i] = Jet(model.accel[i], kGyroParameters + i);
  Vector3<Jet> omega_hat;
  Vector3<Jet> a_hat;
  CorrectSample(gyro.data(), accel.data(), model.basis, Jet(temp_c), gyro_m.cast<Jet>().eval(),
                accel_m.cast<Jet>().eval(), &omega_hat, &a_hat);
  for (int r = 0; r < 3; ++r) {
    (*value)(r) = omega_hat(r).a;
    (*value)(3 + r) = a_hat(r).a;
    jacobian->row(r) = omega_hat(r).v.transpose();
    jacobian->row(3 + r) = a_hat(r).v.transpose();
  }
}

Eigen::Matrix<double, 6, 1> CorrectWithDoubles(const SensorModel& model, double temp_c,
                                               const Eigen::Vector3d& gyro_m,
                                               const Eigen::Vector3d& accel_m) {
  Eigen::Vector3d omega_hat;
  Eigen::Vector3d a_hat;
  model.Correct(temp_c, gyro_m, accel_m, &omega_hat, &a_hat);
  Eigen::Matrix<double, 6, 1> out;
  out << omega_hat, a_hat;
  return out;
}

void ExpectJacobianMatchesCentralDifferences(const SensorModel& model, double temp_c,
                                             const Eigen::Vector3d& gyro_m, const Eigen::Vector3d& accel_m) {
  Eigen::Matrix<double, 6, 1> value;
  Eigen::Matrix<double, 6, kGyroParameters + kAccelParameters> jacobian;
  CorrectWithJets(model, temp_c, gyro_m, accel_m, &value, &jacobian);
  EXPECT_TRUE(value.isApprox(CorrectWithDoubles(model, temp_c, gyro_m, accel_m), 1e-15));
  const double x = model.basis.Argument(temp_c);
  const double jacobian_scale = jacobian.cwiseAbs().maxCoeff();
  for (int p = 0; p < kGyroParameters + kAccelParameters; ++p) {
    SensorModel plus = model;
    SensorModel minus = model;
    double& parameter_plus = p < kGyroParameters ? plus.gyro[p] : plus.accel[p - kGyroParameters];
    double& parameter_minus = p < kGyroParameters ? minus.gyro[p] : minus.accel[p - kGyroParameters];
    // Step so that the coefficient itself, c_k x^k, moves by a relative kFiniteDifferenceStep.
    const double power = std::pow(std::abs(x), p % kPolynomialTerms);
    const double h = kFiniteDifferenceStep * std::max(1.0, std::abs(parameter_plus)) / std::max(1.0, power);
    parameter_plus += h;
    parameter_minus -= h;
    const Eigen::Matrix<double, 6, 1> numeric = (CorrectWithDoubles(plus, temp_c, gyro_m, accel_m) -
                                                 CorrectWithDoubles(minus, temp_c, gyro_m, accel_m)) /
                                                (2.0 * h);
    // Relative to the column, with a floor for the round-off of tiny columns.
    const double scale = std::max(jacobian.col(p).cwiseAbs().maxCoeff(), 1e-4 * jacobian_scale);
    EXPECT_LE((numeric - jacobian.col(p)).cwiseAbs().maxCoeff(), kJacobianRelTol * scale)
        << "parameter " << p << " at " << temp_c << " degC";
  }
}

TEST(SensorModel, AutodiffJacobianMatchesCentralDifferencesAtRandomPoints) {
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> temp(-40.0, 85.0);
  std::uniform_real_distribution<double> counts(-3000.0, 3000.0);
  for (std::uint64_t unit = 0; unit < 3; ++unit) {
    const SensorModel model = testing::RandomMemsModel(100 + unit);
    const Eigen::Vector3d gyro_m(counts(engine), counts(engine), counts(engine));
    const Eigen::Vector3d accel_m(counts(engine), counts(engine), counts(engine));
    ExpectJacobianMatchesCentralDifferences(model, temp(engine), gyro_m, accel_m);
  }
}

TEST(SensorModel, AutodiffJacobianMatchesCentralDifferencesAtIdentity) {
  // The identity is where a fit may start: derivatives there must be right too.
  ExpectJacobianMatchesCentralDifferences(SensorModel::Identity(), 60.0, Eigen::Vector3d(0.3, -0.2, 0.1),
                                          Eigen::Vector3d(0.5, 9.7, -1.0));
}

TEST(RateTable, TruthIncludesEarthRateAndLeverArm) {
  TableSite site;
  site.gravity_mps2 = 9.79285;
  site.latitude_rad = 30.27 * M_PI / 180.0;
  TableSegment still;
  still.up = Eigen::Vector3d::UnitZ();
  still.north = Eigen::Vector3d::UnitX();
  const SegmentTruth at_rest = TruthOf(site, still);
  EXPECT_NEAR(at_rest.omega_radps.z(), kEarthRateRadps * std::sin(*site.latitude_rad), 1e-18);
  EXPECT_NEAR(at_rest.omega_radps.x(), kEarthRateRadps * std::cos(*site.latitude_rad), 1e-18);
  EXPECT_EQ(at_rest.a_mps2, Eigen::Vector3d(0, 0, 9.79285));

  TableSegment spinning;
  spinning.up = Eigen::Vector3d::UnitX();
  spinning.rate_radps = -300.0 * M_PI / 180.0;
  spinning.north = Eigen::Vector3d::UnitY();  // ignored while spinning
  spinning.lever_arm_m = Eigen::Vector3d(0.01, 0.02, 0.0);
  const SegmentTruth turning = TruthOf(site, spinning);
  EXPECT_NEAR(turning.omega_radps.x(), spinning.rate_radps + kEarthRateRadps * std::sin(*site.latitude_rad),
              1e-15);
  EXPECT_EQ(turning.omega_radps.y(), 0.0);
  const double w2 = spinning.rate_radps * spinning.rate_radps;
  EXPECT_NEAR(turning.a_mps2.x(), 9.79285, 1e-15);  // the radial part excludes the axis component
  EXPECT_NEAR(turning.a_mps2.y(), -w2 * 0.02, 1e-15);
}

TEST(RateTable, RateAboutATiltedAxisAndTurns) {
  TableSite site;
  site.gravity_mps2 = 9.79285;
  site.latitude_rad = 30.27 * M_PI / 180.0;
  const double vertical_earth_rate = kEarthRateRadps * std::sin(*site.latitude_rad);
  // A two-axis table: z up, spinning about (y + z) / sqrt(2).
  TableSegment tilted;
  tilted.up = Eigen::Vector3d::UnitZ();
  tilted.rate_radps = 1.0;
  tilted.axis = Eigen::Vector3d(0, 1, 1).normalized();
  tilted.lever_arm_m = Eigen::Vector3d(0.02, 0.0, 0.0);
  EXPECT_FALSE(tilted.AxisIsVertical());
  EXPECT_FALSE(tilted.SpecificForceIsKnown());
  const SegmentTruth t = TruthOf(site, tilted);
  // Only the Earth rate along the axis: Omega sin(phi) (up . n) n, (up . n) = 1 / sqrt(2).
  const Eigen::Vector3d expected_omega = (1.0 + vertical_earth_rate / std::sqrt(2.0)) * *tilted.axis;
  EXPECT_LE((t.omega_radps - expected_omega).norm(), 1e-15);
  // The centripetal term about the axis: r is perpendicular to it here.
  EXPECT_NEAR(t.a_mps2.x(), -0.02, 1e-15);

  // A turn about the vertical: mean rate angle / duration along up, plus the vertical Earth rate.
  TableSegment turn;
  turn.up = -Eigen::Vector3d::UnitX();
  turn.angle_rad = 2.0 * M_PI;
  turn.axis = Eigen::Vector3d::UnitX();
  EXPECT_TRUE(turn.IsTurn());
  EXPECT_TRUE(turn.AxisIsVertical());
  EXPECT_TRUE(turn.SpecificForceIsKnown());
  const SegmentTruth mean = TurnTruth(site, turn, 8.0);
  EXPECT_NEAR(mean.omega_radps.x(), 2.0 * M_PI / 8.0 - vertical_earth_rate, 1e-15);
  EXPECT_EQ(mean.a_mps2, Eigen::Vector3d(-9.79285, 0, 0));
  turn.axis = Eigen::Vector3d::UnitY();  // horizontal: gravity turns in the body frame
  EXPECT_FALSE(turn.SpecificForceIsKnown());
  EXPECT_LE((TurnTruth(site, turn, 8.0).omega_radps - Eigen::Vector3d(0, 2.0 * M_PI / 8.0, 0)).norm(), 1e-15);
}

// WGS-84 normal gravity against the published values at the equator and the pole (NIMA TR8350.2,
// table 3.4: the pole's follows from the equator's through k and e^2), symmetric about the equator,
// growing towards the poles, and the free-air gradient of about -3.086e-6 m/s^2 per metre.
TEST(LocalGravity, NormalGravityOfWgs84) {
  constexpr double kPublishedDigitsMps2 = 1e-9;  // the published values' last digit
  EXPECT_NEAR(NormalGravityMps2(0.0, 0.0), 9.7803253359, kPublishedDigitsMps2);
  EXPECT_NEAR(NormalGravityMps2(M_PI / 2.0, 0.0), 9.8321849378, kPublishedDigitsMps2);
  EXPECT_NEAR(NormalGravityMps2(-M_PI / 2.0, 0.0), 9.8321849378, kPublishedDigitsMps2);
  EXPECT_EQ(NormalGravityMps2(M_PI / 4.0, 0.0), NormalGravityMps2(-M_PI / 4.0, 0.0));
  EXPECT_LT(NormalGravityMps2(M_PI / 6.0, 0.0), NormalGravityMps2(M_PI / 3.0, 0.0));
  const double per_metre =
      (NormalGravityMps2(M_PI / 4.0, 1000.0) - NormalGravityMps2(M_PI / 4.0, 0.0)) / 1000.0;
  EXPECT_NEAR(per_metre, -3.086e-6, 0.005e-6);
}

}  // namespace
}  // namespace imufit
