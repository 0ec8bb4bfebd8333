// Fit regression tests on the fixtures: each simulated run in fixtures/ is read from its file and
// fitted exactly as `imufit fit` does; the result must (1) recover the truth the run was simulated
// from, within the uncertainty the fit reports, and (2) equal the golden calibration in
// fixtures/golden/ (made by fixtures/make_golden.sh), so that any change of results is seen.
#include <cmath>

#include <gtest/gtest.h>

#include "imufit/fit/thermal_fit.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/plan.h"
#include "imufit/pipeline/run_windows.h"

namespace imufit {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kStandardGravity = 9.80665;
// Truth: every 25 degC coefficient within this many reported sigmas (worst case). 3.5 rather than
// 3: the three runs have 99 coefficients at 25 degC between them, and one of 99 unit normals
// exceeds 3 with probability 0.23, but 3.5 only with 0.045. And the RMS of (estimate - truth) /
// sigma over all 132 coefficients of a run within the band (132 correlated estimates: the band
// is wide, but catches sigmas off by a factor of two).
constexpr double kTruthSigmas = 3.5;
constexpr double kZRmsLow = 0.5;
constexpr double kZRmsHigh = 1.6;
// Golden: agreement with the committed calibration, in units of each coefficient's sigma (allows
// for floating-point differences between platforms, catches any real change).
constexpr double kGoldenSigmaFraction = 1e-4;

struct FixtureCase {
  const char* name;
  const char* plan;
  const char* run;
  const char* truth;
  double gyro_bias_stability_dph;  // as fixtures/make_golden.sh passes them
  double accel_bias_stability_ug;
  double bias_correlation_s;
};

// gtest prints the case by name, not as bytes.
void PrintTo(const FixtureCase& c, std::ostream* os) { *os << c.name; }

std::string Fixture(const std::string& name) { return std::string(IMUFIT_FIXTURES_DIR) + "/" + name; }

class FixtureRegression : public ::testing::TestWithParam<FixtureCase> {};

TEST_P(FixtureRegression, RecoversTruthAndMatchesGolden) {
  const FixtureCase& c = GetParam();
  const Plan plan = ReadPlan(Fixture(c.plan));
  const RunWindows run = ReadRunWindows(plan, Fixture(c.run), WindowOptions());
  FitOptions options;
  options.gyro_bias_stability_radps = c.gyro_bias_stability_dph / kRadToDeg / 3600.0;
  options.accel_bias_stability_mps2 = c.accel_bias_stability_ug * 1e-6 * kStandardGravity;
  options.bias_correlation_s = c.bias_correlation_s;
  const FitSummary fit = FitThermalModel(run.windows, plan.site, plan.segments, options);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();

  const Calibration truth = ReadCalibration(Fixture(c.truth));
  double sum_z2 = 0.0;
  int count = 0;
  const auto check = [&](const char* sensor, int coefficients, const double* estimate, const double* sigma,
                         const double* true_value) {
    for (int i = 0; i < coefficients * kPolynomialTerms; ++i) {
      const double z = (estimate[i] - true_value[i]) / sigma[i];
      sum_z2 += z * z;
      ++count;
      if (i % kPolynomialTerms == 0) {
        const CoefficientName& name = kCoefficientNames[i / kPolynomialTerms];
        EXPECT_LE(std::abs(z), kTruthSigmas) << sensor << " " << name.group << " " << name.axis << " at 25 degC";
      }
    }
  };
  check("gyro", kGyroCoefficients, fit.model.gyro.data(), fit.sigma.gyro.data(), truth.model.gyro.data());
  check("accel", kAccelCoefficients, fit.model.accel.data(), fit.sigma.accel.data(), truth.model.accel.data());
  const double z_rms = std::sqrt(sum_z2 / count);
  EXPECT_GT(z_rms, kZRmsLow);
  EXPECT_LT(z_rms, kZRmsHigh);

  const Calibration golden = ReadCalibration(Fixture(std::string("golden/") + c.name + ".yaml"));
  ASSERT_TRUE(golden.sigma.has_value());
  for (int i = 0; i < kGyroParameters; ++i) {
    EXPECT_NEAR(fit.model.gyro[i], golden.model.gyro[i], kGoldenSigmaFraction * golden.sigma->gyro[i]) << "gyro " << i;
    EXPECT_NEAR(fit.sigma.gyro[i], golden.sigma->gyro[i], 1e-6 * golden.sigma->gyro[i]) << "gyro sigma " << i;
  }
  for (int i = 0; i < kAccelParameters; ++i) {
    EXPECT_NEAR(fit.model.accel[i], golden.model.accel[i], kGoldenSigmaFraction * golden.sigma->accel[i]) << "accel " << i;
    EXPECT_NEAR(fit.sigma.accel[i], golden.sigma->accel[i], 1e-6 * golden.sigma->accel[i]) << "accel sigma " << i;
  }
  EXPECT_EQ(fit.temp_range_c, golden.fit_temp_range_c);
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, FixtureRegression,
    ::testing::Values(FixtureCase{"mems_6pos_soak", "plan_6pos.yaml", "mems_6pos_soak.csv.gz", "mems_truth.yaml", 7.5, 73.0, 100.0},
                      FixtureCase{"mems_6pos_ramp", "plan_6pos.yaml", "mems_6pos_ramp.csv.gz", "mems_truth.yaml", 7.5, 73.0, 100.0},
                      FixtureCase{"tactical_24pos_soak", "plan_24pos.yaml", "tactical_24pos_soak.csv.gz",
                                  "tactical_truth.yaml", 0.8, 3.2, 300.0}),
    [](const ::testing::TestParamInfo<FixtureCase>& info) { return std::string(info.param.name); });

TEST(ReadRunWindows, RefusesASegmentThePlanDoesNotHave) {
  const Plan plan = ReadPlan(Fixture("plan_6pos.yaml"));
  Plan smaller = plan;
  smaller.segments.erase(smaller.segments.begin() + 3);  // id 3 in the file
  try {
    ReadRunWindows(smaller, Fixture("mems_6pos_soak.csv.gz"), WindowOptions());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(e.message().find("segment: segment " + std::to_string(plan.segments[3].id) + " is not in the plan"),
              std::string::npos)
        << e.what();
    EXPECT_GT(e.line(), 1);
    EXPECT_GT(e.column(), 0);
  }
}

}  // namespace
}  // namespace imufit
