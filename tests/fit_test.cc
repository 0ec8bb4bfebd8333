// Tests of fit/: the residual's identity with the correction `imufit apply` runs, gradients,
// known-truth recovery within the reported uncertainty, a Monte-Carlo check of that uncertainty, the
// fit of a saturated run, and every way a run can fail to determine the model (windows: run_test).
#include <cmath>
#include <random>

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include "imufit/fit/thermal_fit.h"
#include "imufit/fit/validation.h"
#include "imufit/model/constants.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"
#include "sim_runs.h"
#include "test_models.h"
#include "window_cost.h"

namespace imufit {
namespace {

using testing::FastRateWindows;
using testing::kGyroFullScaleCounts;
using testing::MemsNoise;
using testing::Simulate;
using testing::Site;
using testing::SixPositionPlan;

// Recovery: every 25 degC coefficient within this many of its reported sigmas (worst case).
constexpr double kRecoverySigmas = 3.0;
// Monte-Carlo: the RMS of (estimate - truth) / reported sigma over seeds and coefficients must lie
// in this band. With 8 seeds x 33 coefficients the RMS of unit normals is within +-0.15 of 1
// with ~99 % probability if the estimates were independent; they are correlated, so the band is
// wider, and its lower edge still catches sigmas that are twice too large.
constexpr double kMonteCarloZRmsLow = 0.6;
constexpr double kMonteCarloZRmsHigh = 1.4;
// Held-out run: RMS prediction error at most this multiple of the noise of a window mean plus
// the calibration's own uncertainty (RMS).
constexpr double kHeldOutNoiseMultiple = 3.0;

// (estimate - truth) / sigma for every 25 degC coefficient (c0 in powers of dT).
std::vector<double> ZScoresAt25(const FitSummary& fit, const SensorModel& truth) {
  std::vector<double> z;
  for (int c = 0; c < kGyroCoefficients; ++c) {
    const int i = c * kPolynomialTerms;
    z.push_back((fit.model.gyro[i] - truth.gyro[i]) / fit.sigma.gyro[i]);
  }
  for (int c = 0; c < kAccelCoefficients; ++c) {
    const int i = c * kPolynomialTerms;
    z.push_back((fit.model.accel[i] - truth.accel[i]) / fit.sigma.accel[i]);
  }
  return z;
}

TEST(Saturation, AnOutputPinnedAtTheRunsExtremeIsLeftOutAndTheFitKeepsTheRest) {
  const SensorModel truth = testing::RandomMemsModel(2026);
  const std::vector<TableSegment> plan = SixPositionPlan();
  const std::vector<Window> all = Simulate(MemsNoise(17), plan, truth);
  SimulationOptions clipped = MemsNoise(17);
  clipped.gyro_full_scale_raw = kGyroFullScaleCounts;
  WindowBuilder builder(WindowOptions(), plan);
  SimulateRun(clipped, Site(), plan, truth,
              [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
  const std::vector<Window> windows = builder.Finish();
  // Every 300 deg/s window has its rate axis pinned at +-3000: all of them are left out.
  EXPECT_EQ(builder.stats().saturated_windows, FastRateWindows(all, plan));
  EXPECT_EQ(windows.size() + builder.stats().saturated_windows, all.size());
  EXPECT_EQ(FastRateWindows(windows, plan), 0);
  const std::string note = SaturationNote(builder.stats());
  EXPECT_NE(note.find("windows left out with an output at full scale"), std::string::npos) << note;
  EXPECT_NE(note.find(" at 3000"), std::string::npos) << note;
  // The 100 deg/s rates still determine the model: recovered within the sigmas.
  const FitSummary fit = FitThermalModel(windows, Site(), plan, FitOptions());
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  for (double z : ZScoresAt25(fit, truth)) EXPECT_LT(std::abs(z), kRecoverySigmas + 1.0);
}

TEST(Windows, DistinctTemperaturesCluster) {
  const std::vector<double> centres = DistinctTemperatures({25.2, -40.0, 24.8, 85.0, 85.4, -39.9}, 1.0);
  ASSERT_EQ(centres.size(), 3u);
  EXPECT_NEAR(centres[0], -39.95, 1e-12);
  EXPECT_NEAR(centres[1], 25.0, 1e-12);
  EXPECT_NEAR(centres[2], 85.2, 1e-12);
}

// ---------------------------------------------------------------- the shared function

TEST(WindowCost, IsTheCorrectionImufitApplyRuns) {
  // With p0 = the calibration, unit steps, q = 0, zero truth and unit sigma, the fit's residual
  // is the corrected output itself: it must equal SensorModel::Correct bit for bit.
  const SensorModel model = testing::RandomMemsModel(9);
  std::mt19937_64 engine(1);
  std::uniform_real_distribution<double> counts(-4000.0, 4000.0);
  std::uniform_real_distribution<double> temp(-40.0, 85.0);
  const std::vector<double> unit_steps(kGyroParameters, 1.0);
  for (int i = 0; i < 50; ++i) {
    const double temp_c = temp(engine);
    const Eigen::Vector3d gyro_m(counts(engine), counts(engine), counts(engine));
    const Eigen::Vector3d accel_m(counts(engine), counts(engine), counts(engine));
    Eigen::Vector3d omega_hat;
    Eigen::Vector3d a_hat;
    model.Correct(temp_c, gyro_m, accel_m, &omega_hat, &a_hat);

    const double x = model.basis.Argument(temp_c);
    const WindowCost<kGyroParameters> gyro_cost(gyro_m, Eigen::Vector3d::Zero(), a_hat, x,
                                                Eigen::Vector3d::Ones(), model.gyro.data(),
                                                unit_steps.data());
    const WindowCost<kAccelParameters> accel_cost(accel_m, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                  x, Eigen::Vector3d::Ones(), model.accel.data(),
                                                  unit_steps.data());
    const std::vector<double> q(kGyroParameters, 0.0);
    Eigen::Vector3d gyro_hat;
    Eigen::Vector3d accel_hat;
    Eigen::Vector3d gyro_residual;
    Eigen::Vector3d accel_residual;
    gyro_cost.Evaluate(q.data(), &gyro_hat, gyro_residual.data());
    accel_cost.Evaluate(q.data(), &accel_hat, accel_residual.data());
    EXPECT_EQ(gyro_hat, omega_hat);
    EXPECT_EQ(accel_hat, a_hat);
    // The residual is that error in raw units: diag(S) inv(M) (corrected - truth) / sigma_raw,
    // here raw - V - H a (gyro) and raw - V (accel).
    const SensorCoefficients<double> g = CoefficientsAt(model.gyro.data(), kGyroCoefficients, x);
    const SensorCoefficients<double> a = CoefficientsAt(model.accel.data(), kAccelCoefficients, x);
    constexpr double kRawAgreementRelative = 1e-12;
    EXPECT_LE((gyro_residual - (gyro_m - g.bias - g.g_sensitivity * a_hat)).norm(),
              kRawAgreementRelative * gyro_m.norm());
    EXPECT_LE((accel_residual - (accel_m - a.bias)).norm(), kRawAgreementRelative * accel_m.norm());
  }
}

// Autodiff Jacobian of the fit's residual against central differences, at a random point and at
// the closed-form start's typical neighbourhood (q = 0).
TEST(WindowCost, AutodiffJacobianMatchesCentralDifferences) {
  constexpr double kRelTol = 1e-6;
  const SensorModel model = testing::RandomMemsModel(21);
  std::vector<double> step(kGyroParameters);
  for (int i = 0; i < kGyroParameters; ++i) step[i] = 1e-3 * (1.0 + std::abs(model.gyro[i]));
  auto* functor = new WindowCost<kGyroParameters>(
      Eigen::Vector3d(120.0, -3000.0, 45.0), Eigen::Vector3d(0.1, -3.0, 0.05),
      Eigen::Vector3d(0.3, 9.7, -0.2), 0.4, Eigen::Vector3d(1.0, 2.0, 1.0), model.gyro.data(), step.data());
  ceres::AutoDiffCostFunction<WindowCost<kGyroParameters>, 3, kGyroParameters> cost(functor);
  std::mt19937_64 engine(4);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int point = 0; point < 2; ++point) {
    std::vector<double> q(kGyroParameters, 0.0);
    if (point == 1) {
      for (double& v : q) v = n(engine);
    }
    const double* parameters[] = {q.data()};
    Eigen::Matrix<double, 3, kGyroParameters, Eigen::RowMajor> jacobian;
    double* jacobians[] = {jacobian.data()};
    Eigen::Vector3d residual;
    ASSERT_TRUE(cost.Evaluate(parameters, residual.data(), jacobians));
    for (int p = 0; p < kGyroParameters; ++p) {
      constexpr double kStep = 1e-5;
      std::vector<double> plus = q;
      std::vector<double> minus = q;
      plus[p] += kStep;
      minus[p] -= kStep;
      Eigen::Vector3d r_plus;
      Eigen::Vector3d r_minus;
      (*functor)(plus.data(), r_plus.data());
      (*functor)(minus.data(), r_minus.data());
      const Eigen::Vector3d numeric = (r_plus - r_minus) / (2.0 * kStep);
      const double scale = std::max(1.0, jacobian.col(p).cwiseAbs().maxCoeff());
      EXPECT_LE((numeric - jacobian.col(p)).cwiseAbs().maxCoeff(), kRelTol * scale) << "parameter " << p;
    }
  }
}

// ---------------------------------------------------------------- known truth

class KnownTruth : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    truth_ = new SensorModel(testing::RandomMemsModel(2026));
    windows_ = new std::vector<Window>(Simulate(MemsNoise(17), SixPositionPlan(), *truth_));
    fit_ = new FitSummary(FitThermalModel(*windows_, Site(), SixPositionPlan(), FitOptions()));
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete windows_;
    delete fit_;
  }
  static SensorModel* truth_;
  static std::vector<Window>* windows_;
  static FitSummary* fit_;
};
SensorModel* KnownTruth::truth_ = nullptr;
std::vector<Window>* KnownTruth::windows_ = nullptr;
FitSummary* KnownTruth::fit_ = nullptr;

TEST_F(KnownTruth, ConvergesQuicklyWithSensibleDiagnostics) {
  ASSERT_TRUE(fit_->IsSolutionUsable()) << fit_->FullReport();
  EXPECT_LE(fit_->iterations, 10);
  EXPECT_EQ(fit_->windows_used, 90);
  EXPECT_EQ(fit_->distinct_temps_c.size(), 5u);
  EXPECT_NEAR(fit_->temp_range_c[0], -40.0, 1e-9);
  EXPECT_NEAR(fit_->temp_range_c[1], 85.0, 1e-9);
  // The weights are the measured noise: the reduced chi-square is about one.
  EXPECT_GT(fit_->gyro_reduced_chi2, 0.5);
  EXPECT_LT(fit_->gyro_reduced_chi2, 2.0);
  EXPECT_GT(fit_->accel_reduced_chi2, 0.5);
  EXPECT_LT(fit_->accel_reduced_chi2, 2.0);
  EXPECT_NE(fit_->BriefReport().find("converged"), std::string::npos);
}

TEST_F(KnownTruth, RecoversCoefficientsAt25CWithinReportedSigmas) {
  ASSERT_TRUE(fit_->IsSolutionUsable());
  const std::vector<double> z = ZScoresAt25(*fit_, *truth_);
  for (size_t i = 0; i < z.size(); ++i) {
    const bool gyro = i < kGyroCoefficients;
    const CoefficientName& name = kCoefficientNames[gyro ? i : i - kGyroCoefficients];
    EXPECT_LE(std::abs(z[i]), kRecoverySigmas)
        << (gyro ? "gyro " : "accel ") << name.group << " " << name.axis;
  }
}

TEST_F(KnownTruth, PredictsAHeldOutRunWithinTheNoiseFloor) {
  ASSERT_TRUE(fit_->IsSolutionUsable());
  // Other temperatures, tilted positions, other rates.
  std::vector<TableSegment> segments;
  int id = 100;
  for (const Eigen::Vector3d& up :
       {Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, -1, 1), Eigen::Vector3d(1, -1, -1)}) {
    TableSegment still;
    still.id = id++;
    still.up = up.normalized();
    segments.push_back(still);
    TableSegment spin = still;
    spin.id = id++;
    spin.rate_radps = 200.0 * kDegToRad;
    segments.push_back(spin);
  }
  SimulationOptions options = MemsNoise(99);
  options.soak_temps_c = {-25.0, 5.0, 40.0, 70.0};
  const std::vector<Window> held_out = Simulate(options, segments, *truth_);
  const std::vector<WindowError> errors = PredictWindows(fit_->model, held_out, Site(), segments);
  ASSERT_EQ(errors.size(), held_out.size());
  const ErrorStats stats = SummariseErrors(errors);
  // The noise of a window mean, SI: white noise density / sqrt(window duration).
  const double window_s = options.dwell_s - WindowOptions().trim_s;
  const double gyro_floor = options.gyro_noise_density / std::sqrt(window_s);
  const double accel_floor = options.accel_noise_density / std::sqrt(window_s);
  // The calibration's own uncertainty adds about as much again (it is fitted on similar windows).
  EXPECT_LT(stats.gyro_rms_radps, kHeldOutNoiseMultiple * std::sqrt(2.0) * gyro_floor)
      << stats.gyro_rms_radps / kDegToRad << " deg/s";
  EXPECT_LT(stats.accel_rms_mps2, kHeldOutNoiseMultiple * std::sqrt(2.0) * accel_floor)
      << stats.accel_rms_mps2 << " m/s^2";
}

TEST_F(KnownTruth, LeaveOneTemperatureOutReportsInteriorTemperatures) {
  const std::vector<HeldOutGroup> folds =
      LeaveOneTemperatureOut(*windows_, Site(), SixPositionPlan(), FitOptions());
  ASSERT_EQ(folds.size(), 3u);  // -10, 25, 55: the ends are not left out
  EXPECT_NEAR(folds[1].temp_c, 25.0, 1e-9);
  for (const HeldOutGroup& g : folds) {
    ASSERT_TRUE(g.fitted) << g.why_not;
    EXPECT_EQ(g.errors.windows, 18);
    EXPECT_LT(g.errors.gyro_rms_radps, 0.01 * kDegToRad);
  }
}

// Four temperatures: each interior fold keeps three, too few for a cubic, so it is fitted at
// order 2 (and says so) instead of not at all.
TEST_F(KnownTruth, LeaveOneTemperatureOutLowersTheOrderTheFoldCannotDetermine) {
  std::vector<Window> four_temps;
  for (const Window& w : *windows_) {
    if (std::abs(w.temp_c - (-10.0)) > 5.0) four_temps.push_back(w);
  }
  const std::vector<HeldOutGroup> folds =
      LeaveOneTemperatureOut(four_temps, Site(), SixPositionPlan(), FitOptions());
  ASSERT_EQ(folds.size(), 2u);  // 25 and 55 degC
  for (const HeldOutGroup& g : folds) {
    ASSERT_TRUE(g.fitted) << g.temp_c << ": " << g.why_not;
    EXPECT_TRUE(g.order_lowered);
    EXPECT_EQ(g.gyro_temp_order, 2);
    EXPECT_EQ(g.accel_temp_order, 2);
    EXPECT_EQ(g.errors.windows, 18);
  }
  // With all five temperatures every fold keeps four: the cubic stays.
  for (const HeldOutGroup& g : LeaveOneTemperatureOut(*windows_, Site(), SixPositionPlan(), FitOptions())) {
    EXPECT_FALSE(g.order_lowered);
    EXPECT_EQ(g.gyro_temp_order, 3);
  }
}

TEST(Fit, ExactOnANoiseFreeRampWithEarthRateAndLeverArms) {
  // Without noise the fit must reproduce the truth to round-off: any modelling error (Earth
  // rate, centripetal term, temperature inside a window) would show here.
  const SensorModel truth = testing::RandomMemsModel(5);
  SimulationOptions options;
  options.ramp = true;
  options.ramp_from_c = -40.0;
  options.ramp_to_c = 85.0;
  options.passes = 4;
  options.dwell_s = 4.0;
  options.rate_hz = 50.0;
  WindowOptions window_options;
  window_options.max_temp_span_c = 0.05;
  window_options.min_samples = 2;
  const std::vector<Window> windows = Simulate(options, SixPositionPlan(), truth, window_options);
  const FitSummary fit = FitThermalModel(windows, Site(), SixPositionPlan(), FitOptions());
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  EXPECT_LT(fit.gyro_rms_radps, 1e-6 * kDegToRad);
  EXPECT_LT(fit.accel_rms_mps2, 1e-6);
  for (int i = 0; i < kGyroParameters; i += kPolynomialTerms) {
    EXPECT_NEAR(fit.model.gyro[i], truth.gyro[i], 1e-5 * (1e-3 + std::abs(truth.gyro[i]))) << i;
  }
}

TEST(Fit, ConvergesFromAPoorStartAndReportsNonConvergence) {
  const SensorModel truth = testing::RandomMemsModel(8);
  const std::vector<Window> windows = Simulate(MemsNoise(3), SixPositionPlan(), truth);
  FitOptions options;
  options.closed_form_start = false;
  const FitSummary slow = FitThermalModel(windows, Site(), SixPositionPlan(), options);
  ASSERT_TRUE(slow.IsSolutionUsable()) << slow.FullReport();
  const FitSummary fast = FitThermalModel(windows, Site(), SixPositionPlan(), FitOptions());
  EXPECT_NEAR(slow.model.gyro[0], fast.model.gyro[0], 1e-3 * fast.sigma.gyro[0]);
  options.max_iterations = 1;
  const FitSummary stopped = FitThermalModel(windows, Site(), SixPositionPlan(), options);
  EXPECT_EQ(stopped.status, FitStatus::kNotConverged);
  EXPECT_FALSE(stopped.IsSolutionUsable());
  EXPECT_NE(stopped.BriefReport().find("did not converge"), std::string::npos) << stopped.BriefReport();
}

TEST(Fit, RobustLossDownWeightsAnOutlierWindow) {
  const SensorModel truth = testing::RandomMemsModel(12);
  std::vector<Window> windows = Simulate(MemsNoise(5), SixPositionPlan(), truth);
  windows[40].gyro_mean.y() += 50.0;  // a bump of ~3 deg/s in one window
  const FitSummary robust = FitThermalModel(windows, Site(), SixPositionPlan(), FitOptions());
  ASSERT_TRUE(robust.IsSolutionUsable());
  EXPECT_TRUE(robust.residuals[40].downweighted);
  EXPECT_LE(robust.windows_downweighted, 3);
  FitOptions plain;
  plain.loss = RobustLoss::kNone;
  const FitSummary least_squares = FitThermalModel(windows, Site(), SixPositionPlan(), plain);
  ASSERT_TRUE(least_squares.IsSolutionUsable());
  EXPECT_EQ(least_squares.windows_downweighted, 0);
  // The outlier pulls least squares further from the truth than the robust fit.
  const int bias_y = (kBiasCoefficient + 1) * kPolynomialTerms;
  EXPECT_LT(std::abs(robust.model.gyro[bias_y] - truth.gyro[bias_y]),
            std::abs(least_squares.model.gyro[bias_y] - truth.gyro[bias_y]));
}

TEST(Fit, MonteCarloSigmasMatchTheSpread) {
  const SensorModel truth = testing::RandomMemsModel(77);
  double sum_z2 = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const FitSummary fit = FitThermalModel(Simulate(MemsNoise(1000 + seed), SixPositionPlan(), truth), Site(),
                                           SixPositionPlan(), FitOptions());
    ASSERT_TRUE(fit.IsSolutionUsable());
    for (double z : ZScoresAt25(fit, truth)) {
      sum_z2 += z * z;
      ++count;
    }
  }
  const double z_rms = std::sqrt(sum_z2 / count);
  EXPECT_GT(z_rms, kMonteCarloZRmsLow);
  EXPECT_LT(z_rms, kMonteCarloZRmsHigh);
}

// ---------------------------------------------------------------- turns and tilted rate axes

// A hand-rotated cube: six static faces, then one turn through `angle_deg` about each body axis,
// all starting with z up (about z the axis is vertical; about x and y gravity turns in the body
// frame). Only the turns set the gyro scale and misalignment: three windows against six faces.
std::vector<TableSegment> FacesAndTurns(double angle_deg = 360.0) {
  std::vector<TableSegment> segments = SixPositionPlan(/*with_rates=*/false);
  for (TableSegment& s : segments) s.north.reset();  // a hand-held run knows no north
  for (int axis = 0; axis < 3; ++axis) {
    TableSegment s;
    s.id = 10 + axis;
    s.up = Eigen::Vector3d::UnitZ();
    s.angle_rad = angle_deg * kDegToRad;
    s.axis = Eigen::Vector3d::Unit(axis);
    segments.push_back(s);
  }
  return segments;
}

// A two-axis table: six static faces and +-100 deg/s about each body axis with z up (about x
// and y the axis is horizontal: gravity turns in the body frame), with a lever arm.
std::vector<TableSegment> FacesAndTiltedRates() {
  std::vector<TableSegment> segments = SixPositionPlan(/*with_rates=*/false);
  for (TableSegment& s : segments) s.north.reset();
  int id = 10;
  for (int axis = 0; axis < 3; ++axis) {
    for (double rate_dps : {100.0, -100.0}) {
      TableSegment s;
      s.id = id++;
      s.up = Eigen::Vector3d::UnitZ();
      s.rate_radps = rate_dps * kDegToRad;
      s.axis = Eigen::Vector3d::Unit(axis);
      s.lever_arm_m = Eigen::Vector3d(0.01, 0.02, 0.005);
      segments.push_back(s);
    }
  }
  return segments;
}

// A run at one temperature (order 0), 10 s dwells, no latitude: the Earth rate across a turn's
// axis turns with the unit and is not part of a turn's truth (docs/spec.md section 2).
TableSite NoLatitude() {
  TableSite site = Site();
  site.latitude_rad.reset();
  return site;
}
SimulationOptions OneTemperature(std::uint64_t seed) {
  SimulationOptions o = MemsNoise(seed);
  o.soak_temps_c = {25.0};
  o.dwell_s = 10.0;
  return o;
}
FitOptions OrderZero() {
  FitOptions o;
  o.gyro_temp_order = 0;
  o.accel_temp_order = 0;
  return o;
}
// Simulates `plan` at one temperature without latitude (noise-free on request) and fits order 0.
FitSummary FitOneTemperature(const std::vector<TableSegment>& plan, const SensorModel& truth,
                             std::uint64_t seed, bool noise_free = false,
                             const FitOptions& options = OrderZero()) {
  SimulationOptions simulation = OneTemperature(seed);
  if (noise_free) {
    simulation.gyro_noise_density = 0.0;
    simulation.accel_noise_density = 0.0;
    simulation.quantize = false;
  }
  return FitThermalModel(Simulate(simulation, plan, truth, WindowOptions(), NoLatitude()), NoLatitude(), plan,
                         options);
}

// (estimate - truth) / sigma of the gyro scale x, y, z at 25 degC.
std::vector<double> GyroScaleZ(const FitSummary& fit, const SensorModel& truth) {
  std::vector<double> z;
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (kScaleCoefficient + axis) * kPolynomialTerms;
    z.push_back((fit.model.gyro[i] - truth.gyro[i]) / fit.sigma.gyro[i]);
  }
  return z;
}

TEST(Turns, ThreeTurnsAgainstSixFacesRecoverTheGyroScaleWithinItsSigma) {
  const SensorModel truth = testing::RandomMemsModel(2026);
  const std::vector<TableSegment> plan = FacesAndTurns();
  const std::vector<Window> windows = Simulate(OneTemperature(5), plan, truth, WindowOptions(), NoLatitude());
  ASSERT_EQ(windows.size(), 9u);
  const FitSummary fit = FitThermalModel(windows, NoLatitude(), plan, OrderZero());
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (kScaleCoefficient + axis) * kPolynomialTerms;
    // The scale's sigma is about 5e-5 relative: a turn's mean rate over its 1000 samples.
    EXPECT_LT(fit.sigma.gyro[i] / truth.gyro[i], 2e-4) << "axis " << axis;
    std::printf("turns: gyro scale %c error %+.2e relative, sigma %.2e (z %+.2f)\n", "xyz"[axis],
                fit.model.gyro[i] / truth.gyro[i] - 1.0, fit.sigma.gyro[i] / truth.gyro[i],
                (fit.model.gyro[i] - truth.gyro[i]) / fit.sigma.gyro[i]);
    EXPECT_LT(std::abs(fit.model.gyro[i] - truth.gyro[i]), kRecoverySigmas * fit.sigma.gyro[i])
        << "gyro scale " << axis << ": " << fit.model.gyro[i] << " vs " << truth.gyro[i] << " +- "
        << fit.sigma.gyro[i];
  }
  for (double z : ZScoresAt25(fit, truth)) EXPECT_LT(std::abs(z), kRecoverySigmas + 1.0);
}

TEST(Turns, MonteCarloGyroScaleZScoresAreUnitNormal) {
  const SensorModel truth = testing::RandomMemsModel(77);
  const std::vector<TableSegment> plan = FacesAndTurns();
  double sum_z2 = 0.0;
  double sum_z2_all = 0.0;
  int count = 0;
  int count_all = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const FitSummary fit = FitOneTemperature(plan, truth, 300 + seed);
    ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
    for (double z : GyroScaleZ(fit, truth)) {
      sum_z2 += z * z;
      ++count;
    }
    for (double z : ZScoresAt25(fit, truth)) {
      sum_z2_all += z * z;
      ++count_all;
    }
  }
  const double z_rms = std::sqrt(sum_z2 / count);
  const double z_rms_all = std::sqrt(sum_z2_all / count_all);
  std::printf("turns: gyro scale z RMS %.3f over %d, all coefficients %.3f over %d\n", z_rms, count,
              z_rms_all, count_all);
  // 24 scale z-scores: RMS within about +-0.3 of 1 for unit normals (99 %).
  EXPECT_GT(z_rms, 0.5);
  EXPECT_LT(z_rms, 1.5);
  EXPECT_GT(z_rms_all, kMonteCarloZRmsLow);
  EXPECT_LT(z_rms_all, kMonteCarloZRmsHigh);
}

TEST(Turns, LostSamplesAndJitteredStampsLeaveTheGyroScaleWithinItsSigma) {
  // A serial link that loses 1 % of the frames, three in a row, and a host that stamps them with
  // 3 ms of jitter: before the time grid this cost the gyro scale about 0.3 % (tens of sigmas).
  const SensorModel truth = testing::RandomMemsModel(77);
  const std::vector<TableSegment> plan = FacesAndTurns();
  double sum_z2 = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    SimulationOptions simulation = OneTemperature(500 + seed);
    simulation.drop_probability = 0.01 / 3.0;
    simulation.drop_burst = 3;
    simulation.time_jitter_s = 0.003;
    // Losses can follow each other: allow gaps of up to 8 samples, which on these 10 s turns
    // cost no more than 1e-6 of the angle (the default 0.05 s would drop such a turn, and with it
    // the scale of its axis).
    WindowOptions window_options;
    window_options.max_turn_gap_s = 0.085;
    WindowBuilder builder(window_options, plan);
    SimulateRun(simulation, NoLatitude(), plan, truth,
                [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
    const std::vector<Window> windows = builder.Finish();
    EXPECT_GT(builder.stats().lost_samples, 50) << "seed " << seed;
    EXPECT_TRUE(builder.stats().StampsOnGrid());
    const FitSummary fit = FitThermalModel(windows, NoLatitude(), plan, OrderZero());
    ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
    for (double z : GyroScaleZ(fit, truth)) {
      EXPECT_LT(std::abs(z), kRecoverySigmas + 1.0) << "seed " << seed;
      sum_z2 += z * z;
      ++count;
    }
  }
  const double z_rms = std::sqrt(sum_z2 / count);
  std::printf("turns with lost samples: gyro scale z RMS %.3f over %d\n", z_rms, count);
  // 36 z-scores: their RMS within about +-0.25 of 1 for unit normals (99 %).
  EXPECT_LT(z_rms, 1.3);
}

TEST(Turns, AQuarterTurnAboutAHorizontalAxisIsExactWithoutNoise) {
  // Noise-free: a 90 degree turn ends with another face up; the truth is still angle / duration.
  const SensorModel truth = testing::RandomMemsModel(8);
  const std::vector<TableSegment> plan = FacesAndTurns(90.0);
  const FitSummary fit = FitOneTemperature(plan, truth, 1, /*noise_free=*/true);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  constexpr double kNoiseFreeScaleRelative = 1e-6;  // the sum of rates times dt against the angle
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (kScaleCoefficient + axis) * kPolynomialTerms;
    EXPECT_NEAR(fit.model.gyro[i] / truth.gyro[i], 1.0, kNoiseFreeScaleRelative) << "axis " << axis;
  }
}

// PredictWindows takes a turn's truth as the fit does (its mean rate over the whole occurrence),
// so the truth calibration predicts a noise-free turn's window to rounding, not by the turn's rate.
TEST(Turns, PredictWindowsTakesATurnsMeanRateAsItsTruth) {
  const SensorModel truth = testing::RandomMemsModel(8);
  const std::vector<TableSegment> plan = FacesAndTurns();
  SimulationOptions simulation = OneTemperature(1);
  simulation.gyro_noise_density = 0.0;
  simulation.accel_noise_density = 0.0;
  simulation.quantize = false;
  const std::vector<Window> windows = Simulate(simulation, plan, truth, WindowOptions(), NoLatitude());
  const std::vector<WindowError> errors = PredictWindows(truth, windows, NoLatitude(), plan);
  ASSERT_EQ(errors.size(), windows.size());
  constexpr double kNoiseFreeRateErrorRadps = 1e-6;  // a turn's summed rate x dt against its angle
  int turns = 0;
  for (const WindowError& e : errors) {
    const bool turn = e.segment >= 10;
    turns += turn ? 1 : 0;
    EXPECT_LT(e.gyro_radps.norm(), kNoiseFreeRateErrorRadps) << "segment " << e.segment;
    EXPECT_EQ(e.specific_force_known, !turn || e.segment == 12)
        << "segment " << e.segment;  // 12: about z (up)
    if (turn) {
      EXPECT_GT(e.omega_true_radps.norm(), 0.1) << "segment " << e.segment;
    }
  }
  EXPECT_EQ(turns, 3);
  // The accelerometer's figures leave out the turns about x and y, where gravity turns in the body
  // frame: what is left is exact.
  const ErrorStats all = SummariseErrors(errors);
  EXPECT_EQ(all.windows, 9);
  EXPECT_EQ(all.accel_windows, 7);
  constexpr double kNoiseFreeAccelErrorMps2 = 1e-9;
  EXPECT_LT(all.accel_max_mps2, kNoiseFreeAccelErrorMps2);
}

TEST(ScaleSign, ASignFlippedTurnIsRefusedWithTheConventionToCheck) {
  // The unit turned +360 degrees about x, the plan says -360: the fitted gyro x scale is negative.
  const SensorModel truth = testing::RandomMemsModel(2026);
  const std::vector<TableSegment> run = FacesAndTurns();
  WindowBuilder builder(WindowOptions(), run);
  SimulateRun(OneTemperature(5), NoLatitude(), run, truth,
              [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
  std::vector<TableSegment> flipped = run;
  flipped[6].angle_rad = -*flipped[6].angle_rad;
  const FitSummary fit = FitThermalModel(builder.Finish(), NoLatitude(), flipped, OrderZero());
  ASSERT_EQ(fit.status, FitStatus::kRefused) << fit.FullReport();
  EXPECT_FALSE(fit.IsSolutionUsable());
  ASSERT_EQ(fit.refusals.size(), 1u);
  EXPECT_NE(fit.refusals[0].find("gyro scale x is negative"), std::string::npos) << fit.refusals[0];
  EXPECT_NE(fit.refusals[0].find("right-hand rule"), std::string::npos) << fit.refusals[0];
  EXPECT_NE(fit.BriefReport().find("fit refused: gyro scale x is negative"), std::string::npos)
      << fit.BriefReport();
}

TEST(TiltedRates, TwoAxisTableRecoversTheModelWithinSigmas) {
  const SensorModel truth = testing::RandomMemsModel(31);
  const std::vector<TableSegment> plan = FacesAndTiltedRates();
  const FitSummary fit = FitOneTemperature(plan, truth, 9);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  for (double z : ZScoresAt25(fit, truth)) EXPECT_LT(std::abs(z), kRecoverySigmas + 1.0);
  for (double z : GyroScaleZ(fit, truth)) EXPECT_LT(std::abs(z), kRecoverySigmas);
}

TEST(TiltedRates, NoiseFreeIsExact) {
  const SensorModel truth = testing::RandomMemsModel(32);
  const std::vector<TableSegment> plan = FacesAndTiltedRates();
  const FitSummary fit = FitOneTemperature(plan, truth, 1, /*noise_free=*/true);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  constexpr double kNoiseFreeRelative = 1e-7;
  for (int i = 0; i < kGyroParameters; i += kPolynomialTerms) {
    EXPECT_NEAR(fit.model.gyro[i], truth.gyro[i], kNoiseFreeRelative * (1.0 + std::abs(truth.gyro[i])))
        << "gyro " << i;
  }
}

// ---------------------------------------------------------------- runs that cannot determine the model

std::vector<std::string> Findings(const std::vector<TableSegment>& segments,
                                  const SimulationOptions& simulation,
                                  const FitOptions& options = FitOptions()) {
  const std::vector<Window> windows = Simulate(simulation, segments, testing::RandomMemsModel(1));
  const FitSummary fit = FitThermalModel(windows, Site(), segments, options);
  EXPECT_EQ(fit.status, FitStatus::kUndetermined);
  EXPECT_FALSE(fit.IsSolutionUsable());
  return fit.undetermined;
}

bool Mentions(const std::vector<std::string>& findings, const std::string& text) {
  for (const std::string& f : findings) {
    if (f.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(Undetermined, SingleTemperature) {
  SimulationOptions o = MemsNoise(1);
  o.soak_temps_c = {25.0};
  const auto findings = Findings(SixPositionPlan(), o);
  ASSERT_EQ(findings.size(), 1u) << findings[0];
  EXPECT_NE(findings[0].find(
                "too few temperatures for a cubic temperature model: 1 distinct temperature (25.0 degC), "
                "at least 4 needed"),
            std::string::npos)
      << findings[0];
  // A constant model is determined by the same run.
  FitOptions constant;
  constant.gyro_temp_order = 0;
  constant.accel_temp_order = 0;
  const FitSummary fit = FitThermalModel(Simulate(o, SixPositionPlan(), testing::RandomMemsModel(1)), Site(),
                                         SixPositionPlan(), constant);
  EXPECT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
}

TEST(Undetermined, NoRatesAboutAnAxis) {
  std::vector<TableSegment> segments = SixPositionPlan();
  segments.erase(std::remove_if(segments.begin(), segments.end(),
                                [](const TableSegment& s) { return !s.IsStatic() && s.up.z() != 0.0; }),
                 segments.end());
  const auto findings = Findings(segments, MemsNoise(1));
  EXPECT_TRUE(Mentions(
      findings,
      "gyro scale z and misalignment xz, yz are undetermined: no rate segments or turns about the z axis"))
      << findings[0];
}

TEST(Undetermined, GravityNeverAlongMinusY) {
  std::vector<TableSegment> segments = SixPositionPlan();
  segments.erase(
      std::remove_if(segments.begin(), segments.end(), [](const TableSegment& s) { return s.up.y() < -0.5; }),
      segments.end());
  const auto findings = Findings(segments, MemsNoise(1));
  EXPECT_TRUE(Mentions(
      findings,
      "gyro g_sensitivity column y (xy, yy, zy) is undetermined: no positions with gravity along -y"))
      << findings[0];
  EXPECT_TRUE(
      Mentions(findings,
               "accel scale y and misalignment xy, zy are undetermined: no positions with gravity along -y"));
  // Without g-sensitivity the gyro is fine; the accelerometer still is not.
  FitOptions no_h;
  no_h.fit_g_sensitivity = false;
  const auto without_h = Findings(segments, MemsNoise(1), no_h);
  EXPECT_FALSE(Mentions(without_h, "g_sensitivity"));
  EXPECT_TRUE(Mentions(without_h, "accel scale y"));
}

TEST(Undetermined, RatesAboutAnAxisAtTooFewTemperatures) {
  // Rates about x only in the first two soaks: a cubic in x's scale cannot be fitted.
  const SensorModel truth = testing::RandomMemsModel(1);
  std::vector<TableSegment> all = SixPositionPlan();
  std::vector<TableSegment> no_x_rates;
  for (const TableSegment& s : all) {
    if (s.IsStatic() || s.up.x() == 0.0) no_x_rates.push_back(s);
  }
  SimulationOptions early = MemsNoise(1);
  early.soak_temps_c = {-40.0, -10.0};
  SimulationOptions late = MemsNoise(2);
  late.soak_temps_c = {25.0, 55.0, 85.0};
  late.start_time_s = 10000.0;
  std::vector<Window> windows = Simulate(early, all, truth);
  const std::vector<Window> rest = Simulate(late, no_x_rates, truth);
  windows.insert(windows.end(), rest.begin(), rest.end());
  const FitSummary fit = FitThermalModel(windows, Site(), all, FitOptions());
  ASSERT_EQ(fit.status, FitStatus::kUndetermined);
  EXPECT_TRUE(
      Mentions(fit.undetermined,
               "gyro scale x and misalignment yx, zx are undetermined: rate segments or turns about x at "
               "only 2 distinct temperatures (-40.0, -10.0 degC), the gyro temperature order 3 "
               "needs 4"))
      << fit.undetermined[0];
}

TEST(Undetermined, NoWindowsAtAll) {
  const FitSummary fit = FitThermalModel({}, Site(), SixPositionPlan(), FitOptions());
  EXPECT_EQ(fit.status, FitStatus::kUndetermined);
  EXPECT_TRUE(Mentions(fit.undetermined, "no usable windows"));
}

// ---------------------------------------------------------------- fitting a subset

// A static-only run (six faces, no rotation) at five temperatures: the whole model is refused,
// naming the gyro scale and suggesting --fit accel; the accelerometer alone is recovered within
// its sigmas, and the held gyro keeps its stated values (scale 1, the rest 0) with sigma 0.
TEST(Subset, AStaticOnlyRunCalibratesTheAccelerometerAlone) {
  const std::vector<TableSegment> plan = SixPositionPlan(/*with_rates=*/false);
  const SensorModel truth = testing::RandomMemsModel(31);
  const std::vector<Window> windows = Simulate(MemsNoise(31), plan, truth);
  const FitSummary whole = FitThermalModel(windows, Site(), plan, FitOptions());
  ASSERT_EQ(whole.status, FitStatus::kUndetermined);
  EXPECT_TRUE(Mentions(whole.undetermined, "gyro scale x and misalignment yx, zx are undetermined"));
  EXPECT_TRUE(Mentions(whole.undetermined, "fit a subset: --fit accel"));

  FitOptions options;
  std::string error;
  ASSERT_TRUE(ParseFitGroups("accel", &options, &error)) << error;
  EXPECT_EQ(options.Groups(true),
            (std::vector<std::string>{"accel.bias", "accel.scale", "accel.misalignment"}));
  const FitSummary fit = FitThermalModel(windows, Site(), plan, options);
  ASSERT_TRUE(fit.IsSolutionUsable()) << fit.FullReport();
  double worst = 0.0;
  for (int c = 0; c < kAccelCoefficients; ++c) {
    const int i = c * kPolynomialTerms;
    ASSERT_GT(fit.sigma.accel[i], 0.0) << c;
    const double z = (fit.model.accel[i] - truth.accel[i]) / fit.sigma.accel[i];
    worst = std::max(worst, std::abs(z));
    EXPECT_LT(std::abs(z), 3.5) << "accel coefficient " << c << ": " << fit.model.accel[i] << " vs "
                                << truth.accel[i] << " +- " << fit.sigma.accel[i];
  }
  std::printf("static-only, accel alone: worst |z| over 12 accel coefficients at 25 degC %.2f\n", worst);
  for (int i = 0; i < kGyroParameters; ++i) {
    const bool constant_scale = i % kPolynomialTerms == 0 && i / kPolynomialTerms >= kScaleCoefficient &&
                                i / kPolynomialTerms < kMisalignmentCoefficient;
    EXPECT_EQ(fit.model.gyro[i], constant_scale ? 1.0 : 0.0) << i;
    EXPECT_EQ(fit.sigma.gyro[i], 0.0) << i;
  }

  // The gyro bias too, the rest of the gyro held at the truth (a prior calibration).
  ASSERT_TRUE(ParseFitGroups("gyro-bias,accel", &options, &error)) << error;
  options.held = truth;
  const FitSummary with_bias = FitThermalModel(windows, Site(), plan, options);
  ASSERT_TRUE(with_bias.IsSolutionUsable()) << with_bias.FullReport();
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (kBiasCoefficient + axis) * kPolynomialTerms;
    EXPECT_LT(std::abs(with_bias.model.gyro[i] - truth.gyro[i]), 3.5 * with_bias.sigma.gyro[i]) << axis;
    const int s = (kScaleCoefficient + axis) * kPolynomialTerms;
    EXPECT_NEAR(with_bias.model.gyro[s], truth.gyro[s], 1e-9 * truth.gyro[s]) << axis;
    EXPECT_EQ(with_bias.sigma.gyro[s], 0.0);
  }
}

TEST(Subset, ParsesTheGroupsToFit) {
  FitOptions options;
  std::string error;
  ASSERT_TRUE(ParseFitGroups("gyro-bias,accel", &options, &error));
  EXPECT_EQ(options.gyro_fit, SensorFit::kBias);
  EXPECT_EQ(options.accel_fit, SensorFit::kAll);
  EXPECT_EQ(options.Groups(false),
            (std::vector<std::string>{"gyro.scale", "gyro.misalignment", "gyro.g_sensitivity"}));
  ASSERT_TRUE(ParseFitGroups("all", &options, &error));
  EXPECT_TRUE(options.Groups(false).empty());
  EXPECT_FALSE(ParseFitGroups("accel,magnetometer", &options, &error));
  EXPECT_NE(error.find("\"magnetometer\" is not a group to fit"), std::string::npos) << error;
  EXPECT_FALSE(ParseFitGroups("", &options, &error));
}

TEST(FitOptions, ValidateAndLossNames) {
  FitOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.gyro_temp_order = 4;
  EXPECT_NE(options.Validate(), "");
  RobustLoss loss;
  std::string error;
  EXPECT_TRUE(ParseRobustLoss("cauchy", &loss, &error));
  EXPECT_EQ(loss, RobustLoss::kCauchy);
  EXPECT_FALSE(ParseRobustLoss("tukey", &loss, &error));
  EXPECT_EQ(error, "\"tukey\" is not a robust loss (none, huber, cauchy)");
  EXPECT_EQ(FitSummary().BriefReport(), "fit not run");
}

}  // namespace
}  // namespace imufit
