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
#include "imufit/io/samples.h"
#include "imufit/model/constants.h"
#include "imufit/pipeline/consistency.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/sim/simulator.h"
#include "test_util.h"

namespace imufit {
namespace {

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
  options.accel_bias_stability_mps2 = c.accel_bias_stability_ug * 1e-6 * kStandardGravityMps2;
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
        EXPECT_LE(std::abs(z), kTruthSigmas)
            << sensor << " " << name.group << " " << name.axis << " at 25 degC";
      }
    }
  };
  check("gyro", kGyroCoefficients, fit.model.gyro.data(), fit.sigma.gyro.data(), truth.model.gyro.data());
  check("accel", kAccelCoefficients, fit.model.accel.data(), fit.sigma.accel.data(),
        truth.model.accel.data());
  const double z_rms = std::sqrt(sum_z2 / count);
  EXPECT_GT(z_rms, kZRmsLow);
  EXPECT_LT(z_rms, kZRmsHigh);

  const Calibration golden = ReadCalibration(Fixture(std::string("golden/") + c.name + ".yaml"));
  ASSERT_TRUE(golden.sigma.has_value());
  for (int i = 0; i < kGyroParameters; ++i) {
    EXPECT_NEAR(fit.model.gyro[i], golden.model.gyro[i], kGoldenSigmaFraction * golden.sigma->gyro[i])
        << "gyro " << i;
    EXPECT_NEAR(fit.sigma.gyro[i], golden.sigma->gyro[i], 1e-6 * golden.sigma->gyro[i]) << "gyro sigma " << i;
  }
  for (int i = 0; i < kAccelParameters; ++i) {
    EXPECT_NEAR(fit.model.accel[i], golden.model.accel[i], kGoldenSigmaFraction * golden.sigma->accel[i])
        << "accel " << i;
    EXPECT_NEAR(fit.sigma.accel[i], golden.sigma->accel[i], 1e-6 * golden.sigma->accel[i])
        << "accel sigma " << i;
  }
  EXPECT_EQ(fit.temp_range_c, golden.fit_temp_range_c);
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, FixtureRegression,
    ::testing::Values(FixtureCase{"mems_6pos_soak", "plan_6pos.yaml", "mems_6pos_soak.csv.gz",
                                  "mems_truth.yaml", 7.5, 73.0, 100.0},
                      FixtureCase{"mems_6pos_ramp", "plan_6pos.yaml", "mems_6pos_ramp.csv.gz",
                                  "mems_truth.yaml", 7.5, 73.0, 100.0},
                      FixtureCase{"tactical_24pos_soak", "plan_24pos.yaml", "tactical_24pos_soak.csv.gz",
                                  "tactical_truth.yaml", 0.8, 3.2, 300.0}),
    [](const ::testing::TestParamInfo<FixtureCase>& info) { return std::string(info.param.name); });

// The record's fit options read back as written, through the one table (fit_run.cc): every
// combination of what a fit estimates, the temperature orders and the loss; a set of groups no fit
// estimates, or a loss no fit knows, is refused at its key.
TEST(FitOptionsOfRecord, ReadsBackWhatTheRecordWrites) {
  const Calibration golden = ReadCalibration(IMUFIT_FIXTURES_DIR "/golden/mems_6pos_soak.yaml");
  ASSERT_TRUE(golden.fit.has_value());
  const FitOptions read = FitOptionsOfRecord(*golden.fit);
  EXPECT_EQ(read.gyro_fit, SensorFit::kAll);
  EXPECT_EQ(read.accel_fit, SensorFit::kAll);
  EXPECT_TRUE(read.fit_g_sensitivity);
  EXPECT_EQ(read.loss, RobustLoss::kHuber);
  for (const SensorFit gyro : {SensorFit::kAll, SensorFit::kBias, SensorFit::kNone}) {
    for (const SensorFit accel : {SensorFit::kAll, SensorFit::kBias, SensorFit::kNone}) {
      for (const bool g_sensitivity : {true, false}) {
        FitOptions options;
        options.gyro_fit = gyro;
        options.accel_fit = accel;
        options.fit_g_sensitivity = g_sensitivity;
        options.gyro_temp_order = 2;
        options.accel_temp_order = 1;
        options.loss = RobustLoss::kCauchy;
        FitRecord record;  // as RecordOf() writes it
        record.fitted = options.Groups(true);
        record.held = options.Groups(false);
        record.g_sensitivity_fitted = options.Fits(true, kGSensitivityCoefficient);
        record.gyro_temp_order = options.gyro_temp_order;
        record.accel_temp_order = options.accel_temp_order;
        record.loss = RobustLossName(options.loss);
        const FitOptions back = FitOptionsOfRecord(record);
        EXPECT_EQ(back.Groups(true), options.Groups(true));
        EXPECT_EQ(back.gyro_fit, gyro);
        EXPECT_EQ(back.accel_fit, accel);
        EXPECT_EQ(back.gyro_temp_order, 2);
        EXPECT_EQ(back.accel_temp_order, 1);
        EXPECT_EQ(back.loss, RobustLoss::kCauchy);
      }
    }
  }
  FitRecord bad;
  bad.fitted = std::vector<std::string>{"gyro.scale"};  // a scale without its bias: no fit does that
  try {
    FitOptionsOfRecord(bad);
    ADD_FAILURE() << "gyro.scale alone";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "fit.fitted") << e.what();
  }
  bad = FitRecord();
  bad.loss = "tukey";
  try {
    FitOptionsOfRecord(bad);
    ADD_FAILURE() << "tukey";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fit.loss: \"tukey\" is not a robust loss"), std::string::npos)
        << e.what();
  }
}

TEST(ReadRunWindows, RefusesASegmentThePlanDoesNotHave) {
  const Plan plan = ReadPlan(Fixture("plan_6pos.yaml"));
  Plan smaller = plan;
  smaller.segments.erase(smaller.segments.begin() + 3);  // id 3 in the file
  try {
    ReadRunWindows(smaller, Fixture("mems_6pos_soak.csv.gz"), WindowOptions());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(
        e.message().find("segment: segment " + std::to_string(plan.segments[3].id) + " is not in the plan"),
        std::string::npos)
        << e.what();
    EXPECT_GT(e.line(), 1);
    EXPECT_GT(e.column(), 0);
  }
}

// Unlabelled logs: a run simulated from the fixture truth, written with and without its segment
// (and temp_c) column, with jittered time stamps, and fitted through FitRun as `imufit fit` does.
class UnlabelledRun : public testing::TempDirTest {
 protected:
  // Simulates the 6-position plan and writes it to `name` (in the test's folder) with the given
  // columns; returns the path.
  std::string Write(const std::string& name, const SimulationOptions& options, SampleColumns columns) {
    const std::string path = Path(name);
    SamplesWriter writer(path, columns);
    SimulateRun(options, plan_.site, plan_.segments, truth_.model,
                [&](const Sample& raw, const SegmentTruth&) { writer.Write(raw); });
    writer.Commit();
    return path;
  }
  static SimulationOptions Options() {
    SimulationOptions options;
    options.rate_hz = 50.0;
    options.dwell_s = 5.0;
    options.transition_s = 1.0;
    options.gyro_noise_density = 8.7e-5;
    options.accel_noise_density = 1.5e-3;
    options.quantize = true;
    options.time_jitter_s = 0.006;  // 30 % of the 20 ms interval
    options.seed = 12;
    return options;
  }
  // Every 25 degC coefficient of `fit` within kTruthSigmas of the truth; and, with `other`, within
  // kAgreementSigmas of it (the same samples, labelled differently).
  void ExpectTruth(const FitSummary& fit, const FitSummary* other = nullptr) {
    for (int c = 0; c < kGyroCoefficients + kAccelCoefficients; ++c) {
      const bool gyro = c < kGyroCoefficients;
      const int i = (gyro ? c : c - kGyroCoefficients) * kPolynomialTerms;
      const double estimate = gyro ? fit.model.gyro[i] : fit.model.accel[i];
      const double sigma = gyro ? fit.sigma.gyro[i] : fit.sigma.accel[i];
      const double true_value = gyro ? truth_.model.gyro[i] : truth_.model.accel[i];
      const CoefficientName& name = kCoefficientNames[gyro ? c : c - kGyroCoefficients];
      EXPECT_LE(std::abs(estimate - true_value), kTruthSigmas * sigma)
          << (gyro ? "gyro " : "accel ") << name.group << " " << name.axis;
      if (other == nullptr) continue;
      const double other_estimate = gyro ? other->model.gyro[i] : other->model.accel[i];
      EXPECT_LE(std::abs(estimate - other_estimate), kAgreementSigmas * sigma)
          << (gyro ? "gyro " : "accel ") << name.group << " " << name.axis << " against the labelled fit";
    }
  }

  // The labelled and the unlabelled fit use the same samples but not the same ones in each window
  // (the segmentation keeps about 80 %): they agree to well within one sigma.
  static constexpr double kAgreementSigmas = 1.0;
  const Plan plan_ = ReadPlan(Fixture("plan_6pos.yaml"));
  const Calibration truth_ = ReadCalibration(Fixture("mems_truth.yaml"));
};

TEST_F(UnlabelledRun, FitsLikeTheLabelledRunWithJitteredTimes) {
  SimulationOptions options = Options();
  options.soak_temps_c = {-40.0, -10.0, 25.0, 55.0, 85.0};
  const std::string labelled = Write("labelled.csv", options, SampleColumns{true, true});
  const std::string unlabelled = Write("unlabelled.csv", options, SampleColumns{false, true});
  FitRunOptions fit_options;
  const FitRunResult with_labels = FitRun(plan_.path, labelled, fit_options);
  const FitRunResult found = FitRun(plan_.path, unlabelled, fit_options);
  ASSERT_TRUE(with_labels.fit.IsSolutionUsable()) << with_labels.fit.FullReport();
  ASSERT_TRUE(found.fit.IsSolutionUsable()) << found.fit.FullReport();
  EXPECT_FALSE(with_labels.run.segmentation.has_value());
  ASSERT_TRUE(found.run.segmentation.has_value());
  EXPECT_EQ(found.run.segmentation->matches.size(), 5 * plan_.segments.size());
  EXPECT_EQ(found.run.windows.size(), with_labels.run.windows.size());
  ExpectTruth(with_labels.fit);
  ExpectTruth(found.fit, &with_labels.fit);
}

TEST_F(UnlabelledRun, OneTemperatureWithoutThermometer) {
  SimulationOptions options = Options();
  options.soak_temps_c = {25.0};
  options.dwell_s = 8.0;
  const std::string path = Write("no_temp.csv", options, SampleColumns{false, false});
  FitRunOptions fit_options;
  fit_options.fit.gyro_temp_order = 0;
  fit_options.fit.accel_temp_order = 0;
  EXPECT_THROW(FitRun(plan_.path, path, fit_options), InputError);  // no temp_c, no --temp-c
  fit_options.input.temp_c = 25.0;
  const FitRunResult result = FitRun(plan_.path, path, fit_options);
  ASSERT_TRUE(result.fit.IsSolutionUsable()) << result.fit.FullReport();
  ExpectTruth(result.fit);
  EXPECT_EQ(result.fit.temp_range_c[0], 25.0);
  EXPECT_EQ(result.fit.temp_range_c[1], 25.0);
}

TEST_F(UnlabelledRun, ALogThatDisagreesWithThePlanNamesFileAndTime) {
  SimulationOptions options = Options();
  const std::string path = Write("disagrees.csv", options, SampleColumns{false, true});
  Plan smaller = plan_;
  smaller.segments.erase(smaller.segments.begin() + 4);  // +y, 24 .. 29 s in the log
  try {
    ReadRunWindows(smaller, path, WindowOptions());
    FAIL() << "no error";
  } catch (const PlanMismatchError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find(path + ": the log does not match the plan " + plan_.path + ": at t = "), 0u)
        << message;
    EXPECT_NE(message.find("with the raw axes as they are: at t = 24."), std::string::npos) << message;
  }
}

// The run's temperatures against the plan's soak set-points: agreeing within kSoakToleranceC at the
// coldest and warmest (self-heating), refused beyond with "Fahrenheit?" when 9/5 T + 32 explains it;
// without set-points, a warning above kMaxRatedTempC only.
TEST(CheckRunTemperatures, NamesFahrenheitAgainstTheSoakSetPoints) {
  const auto windows_at = [](const std::vector<double>& temps_c) {
    std::vector<Window> windows;
    for (const double temp_c : temps_c) {
      Window w;
      w.temp_c = temp_c;
      windows.push_back(w);
    }
    return windows;
  };
  const std::vector<double> soaks = {-40.0, 25.0, 85.0};
  // A unit 8 degC warmer than the chamber (self-heating) agrees.
  EXPECT_EQ(CheckRunTemperatures(windows_at({-32.0, 33.0, 93.0}), soaks).refusal, "");
  const TemperatureFinding fahrenheit = CheckRunTemperatures(windows_at({-40.0, 77.0, 185.0}), soaks);
  EXPECT_NE(fahrenheit.refusal.find("Fahrenheit? (-40..185 degF is -40..85 degC"), std::string::npos)
      << fahrenheit.refusal;
  const TemperatureFinding stopped = CheckRunTemperatures(windows_at({-40.0, 25.0}), soaks);
  EXPECT_NE(stopped.refusal.find("a chamber run stopped early?"), std::string::npos) << stopped.refusal;
  EXPECT_EQ(CheckRunTemperatures(windows_at({-40.0, 185.0}), {}).refusal, "");
  EXPECT_NE(CheckRunTemperatures(windows_at({-40.0, 185.0}), {}).warning.find("Fahrenheit?"),
            std::string::npos);
  EXPECT_EQ(CheckRunTemperatures(windows_at({-40.0, 125.0}), {}).warning, "");
}

// The uncalibrated sensors of a record: its key, else (an older file) a sensor whose bias is held
// without a prior.
TEST(UncalibratedSensors, FromTheRecordOrItsHeldGroups) {
  Calibration calibration;
  EXPECT_TRUE(UncalibratedSensors(calibration).empty());
  FitRecord& record = calibration.fit.emplace();
  record.held =
      std::vector<std::string>{"gyro.bias", "gyro.scale", "gyro.misalignment", "gyro.g_sensitivity"};
  record.held_values = "scale 1, others 0";
  EXPECT_EQ(UncalibratedSensors(calibration), std::vector<std::string>{"gyro"});
  record.held_values = "prior";
  EXPECT_TRUE(UncalibratedSensors(calibration).empty());
  record.held = std::vector<std::string>{"gyro.scale", "gyro.misalignment"};  // a bias-only gyro
  record.held_values = "scale 1, others 0";
  EXPECT_TRUE(UncalibratedSensors(calibration).empty());
  record.uncalibrated_sensors = std::vector<std::string>{"accel"};
  EXPECT_EQ(UncalibratedSensors(calibration), std::vector<std::string>{"accel"});
}

}  // namespace
}  // namespace imufit
