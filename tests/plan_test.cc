// `plan check`'s prediction against known truth: the spread of fitted coefficients over simulated
// runs (white noise and a wandering bias), the fit's own reported sigma on one run, and the
// classical results of calibration design (rotation-invariant position sets; D-optimal soaks of a
// cubic).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "imufit/fit/plan_information.h"
#include "imufit/fit/thermal_fit.h"
#include "imufit/model/constants.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/plan/hand_check.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"
#include "imufit/plan/plan_prediction.h"
#include "imufit/run/windows.h"
#include "imufit/sim/field_session.h"
#include "imufit/sim/simulator.h"
#include "test_models.h"

namespace imufit {
namespace {

using testing::SixPositionPlan;

// Monte Carlo: the RMS over runs and coefficients of a class of (fitted - truth) / predicted sigma
// lies within this of 1 (relative). 60 runs of 12..36 coefficients a class: the sampling error of
// the RMS is a few per cent.
constexpr double kSpreadTolerance = 0.15;
constexpr int kMonteCarloRuns = 60;
// One run: the fit's reported sigma of every parameter within this of the prediction (relative;
// the fit scales by the run's own reduced chi-square and measures the noise from the samples).
constexpr double kReportedSigmaTolerance = 0.10;
// Exact identities of linear algebra, relative.
constexpr double kIdentityTolerance = 1e-9;
// The D-efficiencies the literature quotes to three figures.
constexpr double kQuotedEfficiencyTolerance = 0.0005;

TableSite Site() {
  TableSite site;
  site.gravity_mps2 = 9.80665;
  site.latitude_rad = 48.0 * kDegToRad;
  return site;
}

// Four soaks, 50 Hz, 3 s dwells: white noise and a Gauss-Markov bias whose wander adds about a
// tenth to the variance of a window mean.
SimulationOptions Schedule(std::uint64_t seed) {
  SimulationOptions o;
  o.soak_temps_c = {-30.0, 5.0, 45.0, 80.0};
  o.dwell_s = 3.0;
  o.transition_s = 1.0;
  o.rate_hz = 50.0;
  o.gyro_noise_density = 1e-4;
  o.accel_noise_density = 5e-4;
  o.gyro_bias_instability = 2e-5;
  o.accel_bias_instability = 1e-4;
  o.bias_correlation_s = 100.0;
  o.seed = seed;
  return o;
}

// The fit's weighting of the wandering bias, as CheckPlan sets it from the schedule.
FitOptions FitOptionsFor(const SimulationOptions& schedule) {
  FitOptions options;
  options.gyro_bias_stability_radps = schedule.gyro_bias_instability;
  options.accel_bias_stability_mps2 = schedule.accel_bias_instability;
  options.bias_correlation_s = schedule.bias_correlation_s;
  return options;
}

// A unit near nominal (raw in SI), with temperature terms in every class.
SensorModel Truth() {
  SensorModel model = SensorModel::Identity();
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto fill = [&](double* c, double value, double spread) {
    c[0] += value;
    c[1] = spread * u(engine) / 60.0;
    c[2] = spread * u(engine) / 3600.0;
    c[3] = spread * u(engine) / 216000.0;
  };
  for (int axis = 0; axis < 3; ++axis) {
    fill(&model.gyro[(kBiasCoefficient + axis) * 4], 0.01 * u(engine), 0.002);
    fill(&model.gyro[(kScaleCoefficient + axis) * 4], 0.005 * u(engine), 0.001);
    fill(&model.accel[(kBiasCoefficient + axis) * 4], 0.05 * u(engine), 0.01);
    fill(&model.accel[(kScaleCoefficient + axis) * 4], 0.005 * u(engine), 0.001);
  }
  for (int m = 0; m < 6; ++m) {
    fill(&model.gyro[(kMisalignmentCoefficient + m) * 4], 0.003 * u(engine), 0.0005);
    fill(&model.accel[(kMisalignmentCoefficient + m) * 4], 0.003 * u(engine), 0.0005);
  }
  for (int h = 0; h < 9; ++h) fill(&model.gyro[(kGSensitivityCoefficient + h) * 4], 1e-4 * u(engine), 2e-5);
  return model;
}

// The predicted 1-sigma of every parameter (powers of dT), 0 where held.
struct Predicted {
  std::vector<double> gyro, accel;
};

Predicted Predict(const std::vector<TableSegment>& segments, const SimulationOptions& schedule) {
  const std::vector<Window> windows = PlannedWindows(segments, Site(), schedule, WindowOptions());
  const PlanInformation info =
      ComputePlanInformation(windows, Site(), segments, FitOptionsFor(schedule), 1e-4);
  EXPECT_TRUE(info.undetermined.empty()) << (info.undetermined.empty() ? "" : info.undetermined.front());
  const auto sigmas = [](const SensorInformation& s) {
    std::vector<double> out;
    for (int p = 0; p < s.to_reference.rows(); ++p) {
      const Eigen::RowVectorXd a = s.to_reference.row(p);
      out.push_back(std::sqrt((a * s.covariance * a.transpose())(0, 0)));
    }
    return out;
  };
  return {sigmas(info.gyro), sigmas(info.accel)};
}

// The windows of a simulated run of `truth`.
std::vector<Window> SimulatedWindows(const std::vector<TableSegment>& segments,
                                     const SimulationOptions& schedule, const SensorModel& truth) {
  WindowBuilder builder(WindowOptions(), segments);
  SimulateRun(schedule, Site(), segments, truth,
              [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
  return builder.Finish();
}

FitSummary FitOneRun(const std::vector<TableSegment>& segments, const SimulationOptions& schedule,
                     const SensorModel& truth) {
  return FitThermalModel(SimulatedWindows(segments, schedule, truth), Site(), segments,
                         FitOptionsFor(schedule));
}

std::string ClassOf(bool gyro, int parameter) {
  return std::string(gyro ? "gyro." : "accel.") + kCoefficientNames[parameter / kPolynomialTerms].group;
}

// Per coefficient class, over fits: the sums of ((fitted - truth) / predicted sigma)^2 and of the
// fit's reported sigma / predicted.
struct ClassTally {
  double sum_z2 = 0.0;
  double sum_reported = 0.0;
  int count = 0;
  double Spread() const { return std::sqrt(sum_z2 / count); }
  double Reported() const { return sum_reported / count; }
};

void AddToTally(const FitSummary& fit, const SensorModel& truth, const Predicted& predicted,
                std::map<std::string, ClassTally>* tally) {
  for (bool gyro : {true, false}) {
    const std::vector<double>& sigma = gyro ? predicted.gyro : predicted.accel;
    for (size_t p = 0; p < sigma.size(); ++p) {
      if (sigma[p] <= 0.0) continue;
      const double error = gyro ? fit.model.gyro[p] - truth.gyro[p] : fit.model.accel[p] - truth.accel[p];
      ClassTally& t = (*tally)[ClassOf(gyro, static_cast<int>(p))];
      t.sum_z2 += (error / sigma[p]) * (error / sigma[p]);
      t.sum_reported += (gyro ? fit.sigma.gyro[p] : fit.sigma.accel[p]) / sigma[p];
      ++t.count;
    }
  }
}

TEST(PlanPrediction, SpreadOverSimulatedRunsMatchesThePredictedSigma) {
  const std::vector<TableSegment> segments = SixPositionPlan();
  const SensorModel truth = Truth();
  const Predicted predicted = Predict(segments, Schedule(1));
  std::map<std::string, ClassTally> tally;
  for (int run = 0; run < kMonteCarloRuns; ++run) {
    const FitSummary fit = FitOneRun(segments, Schedule(1000 + run), truth);
    ASSERT_TRUE(fit.IsSolutionUsable()) << "run " << run;
    AddToTally(fit, truth, predicted, &tally);
  }
  ASSERT_EQ(tally.size(), 7u);  // every coefficient class
  for (const auto& [group, t] : tally) {
    std::printf("%-20s spread / predicted sigma %.3f (%d fitted values)\n", group.c_str(), t.Spread(),
                t.count);
    EXPECT_NEAR(t.Spread(), 1.0, kSpreadTolerance) << group << ": spread / predicted sigma over " << t.count;
  }
}

TEST(PlanPrediction, TheFitsReportedSigmaMatchesThePrediction) {
  const std::vector<TableSegment> segments = SixPositionPlan();
  const Predicted predicted = Predict(segments, Schedule(1));
  const FitSummary fit = FitOneRun(segments, Schedule(77), Truth());
  ASSERT_TRUE(fit.IsSolutionUsable());
  for (bool gyro : {true, false}) {
    const std::vector<double>& sigma = gyro ? predicted.gyro : predicted.accel;
    for (size_t p = 0; p < sigma.size(); ++p) {
      const double reported = gyro ? fit.sigma.gyro[p] : fit.sigma.accel[p];
      if (sigma[p] <= 0.0) continue;
      EXPECT_NEAR(reported / sigma[p], 1.0, kReportedSigmaTolerance)
          << ClassOf(gyro, p) << " parameter " << p;
    }
  }
}

// CheckPlan's table is the same prediction, in display units.
TEST(PlanPrediction, TheCheckTableShowsThePrediction) {
  const std::vector<TableSegment> segments = SixPositionPlan();
  const SimulationOptions schedule = Schedule(1);
  const Predicted predicted = Predict(segments, schedule);
  const PlanCheck check = CheckPlan(segments, Site(), schedule, FitOptions(), PlanCheckOptions());
  int found = 0;
  for (const PlanRow& row : check.rows) {
    if (row.name == "gyro bias x") {
      EXPECT_NEAR(row.sigma, predicted.gyro[0] * kRadToDeg, kIdentityTolerance * row.sigma);
      ++found;
    }
    if (row.name == "accel scale z (linear term)") {
      const int p = (kScaleCoefficient + 2) * kPolynomialTerms + 1;
      EXPECT_NEAR(row.sigma, predicted.accel[p] * 1e6, kIdentityTolerance * row.sigma);
      ++found;
    }
  }
  EXPECT_EQ(found, 2);
}

// Unit vectors of the 6 faces, 12 edges and 8 corners of a cube.
std::vector<Eigen::Vector3d> CubeDirections(int nonzero) {
  std::vector<Eigen::Vector3d> out;
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        const Eigen::Vector3d v(x, y, z);
        if (v.cwiseAbs().sum() == nonzero) out.push_back(v.normalized());
      }
    }
  }
  return out;
}

// The accelerometer covariance (linear model at one temperature) of a static plan at `ups`, the
// total dwell `total_s` shared equally.
Eigen::MatrixXd LinearAccelCovariance(const std::vector<Eigen::Vector3d>& ups, double total_s) {
  std::vector<TableSegment> segments;
  for (const Eigen::Vector3d& up : ups) {
    TableSegment s;
    s.id = static_cast<int>(segments.size()) + 1;
    s.up = up;
    segments.push_back(s);
  }
  SimulationOptions schedule;
  schedule.soak_temps_c = {25.0};
  schedule.rate_hz = 100.0;
  schedule.dwell_s = total_s / ups.size() + WindowOptions().trim_s;  // the windows share total_s
  schedule.gyro_noise_density = 1e-4;
  schedule.accel_noise_density = 5e-4;
  FitOptions options;
  options.gyro_fit = SensorFit::kNone;
  options.accel_temp_order = 0;
  const std::vector<Window> windows = PlannedWindows(segments, TableSite(), schedule, WindowOptions());
  const PlanInformation info = ComputePlanInformation(windows, TableSite(), segments, options, 1e-4);
  EXPECT_TRUE(info.undetermined.empty());
  const Eigen::MatrixXd& a = info.accel.to_reference;
  return a * info.accel.covariance * a.transpose();
}

TEST(PlanDesignClassics, FacesEdgesAndTheirUnionsGiveTheSameLinearAccelVariancePerDwell) {
  constexpr double kTotalS = 468.0;  // 6, 12, 18 and 26 positions share it in whole samples
  const std::vector<Eigen::Vector3d> faces = CubeDirections(1);
  const std::vector<Eigen::Vector3d> edges = CubeDirections(2);
  const std::vector<Eigen::Vector3d> corners = CubeDirections(3);
  ASSERT_EQ(faces.size(), 6u);
  ASSERT_EQ(edges.size(), 12u);
  ASSERT_EQ(corners.size(), 8u);
  std::vector<Eigen::Vector3d> eighteen = faces;
  eighteen.insert(eighteen.end(), edges.begin(), edges.end());
  std::vector<Eigen::Vector3d> twenty_six = eighteen;
  twenty_six.insert(twenty_six.end(), corners.begin(), corners.end());
  const Eigen::MatrixXd reference = LinearAccelCovariance(faces, kTotalS);
  ASSERT_GT(reference.diagonal().maxCoeff(), 0.0);
  const std::vector<const std::vector<Eigen::Vector3d>*> designs = {&edges, &eighteen, &twenty_six};
  for (const std::vector<Eigen::Vector3d>* ups : designs) {
    const Eigen::MatrixXd c = LinearAccelCovariance(*ups, kTotalS);
    for (int p = 0; p < c.rows(); ++p) {
      if (reference(p, p) == 0.0) continue;
      EXPECT_NEAR(c(p, p), reference(p, p), kIdentityTolerance * reference(p, p))
          << ups->size() << " positions, parameter " << p;
    }
  }
  // Not every design: the six faces with +z once more (unbalanced) give another variance per dwell.
  std::vector<Eigen::Vector3d> unbalanced = faces;
  unbalanced.push_back(Eigen::Vector3d::UnitZ());
  const Eigen::MatrixXd c = LinearAccelCovariance(unbalanced, kTotalS);
  double largest_change = 0.0;
  for (int p = 0; p < c.rows(); ++p) {
    if (reference(p, p) > 0.0)
      largest_change = std::max(largest_change, std::abs(c(p, p) / reference(p, p) - 1.0));
  }
  EXPECT_GT(largest_change, 0.01);
}

TEST(PlanDesignClassics, CubicSoaksAtTheEndsAndPlusMinusOneOverRootFiveAreDOptimal) {
  const std::array<double, 2> range = {-1.0, 1.0};
  const double a = 1.0 / std::sqrt(5.0);
  EXPECT_NEAR(CubicDEfficiency({-1.0, -a, a, 1.0}, range), 1.0, kIdentityTolerance);
  // No four soaks do better (random designs, and the symmetric family around the optimum).
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    EXPECT_LE(CubicDEfficiency({u(engine), u(engine), u(engine), u(engine)}, range),
              1.0 + kIdentityTolerance);
  }
  for (double b : {0.3, 0.4, 0.44, 0.46, 0.5, 0.6}) {
    EXPECT_LT(CubicDEfficiency({-1.0, -b, b, 1.0}, range), 1.0) << b;
  }
  // Four equally spaced soaks; a uniform ramp (many windows evenly over the range).
  EXPECT_NEAR(CubicDEfficiency({-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0}, range), 0.959, kQuotedEfficiencyTolerance);
  std::vector<double> ramp;
  for (int i = 0; i < 20000; ++i) ramp.push_back(-1.0 + (i + 0.5) * 2.0 / 20000);
  // Exactly (det of the uniform moments 16/23625 over the optimum's 16/3125)^(1/4) = (25/189)^(1/4)
  // = 0.6031 (quoted elsewhere as 0.605).
  EXPECT_NEAR(CubicDEfficiency(ramp, range), std::pow(25.0 / 189.0, 0.25), kIdentityTolerance * 1e3);
  EXPECT_NEAR(CubicDEfficiency(ramp, range), 0.603, kQuotedEfficiencyTolerance);
  // Scaled to degC: the same figures over -40..85.
  EXPECT_NEAR(CubicDEfficiency({-40.0, 1.6667, 43.3333, 85.0}, {-40.0, 85.0}), 0.959,
              kQuotedEfficiencyTolerance);
}

// plan check reports the D-efficiency of the planned temperatures.
TEST(PlanDesignClassics, PlanCheckReportsTheTemperatureEfficiency) {
  const std::vector<TableSegment> segments = SixPositionPlan();
  SimulationOptions schedule = Schedule(1);
  schedule.soak_temps_c = {-40.0, -40.0 + 125.0 / 3.0, 85.0 - 125.0 / 3.0, 85.0};
  EXPECT_NEAR(CheckPlan(segments, Site(), schedule, FitOptions(), PlanCheckOptions()).temperature_efficiency,
              0.959, kQuotedEfficiencyTolerance);
  const double half = 62.5 / std::sqrt(5.0);
  schedule.soak_temps_c = {-40.0, 22.5 - half, 22.5 + half, 85.0};
  EXPECT_NEAR(CheckPlan(segments, Site(), schedule, FitOptions(), PlanCheckOptions()).temperature_efficiency,
              1.0, kIdentityTolerance);
}

// A calibration as FitRun writes it, as far as the prediction reads it: the model, its sigmas and
// the record of what was fitted with which weighting.
Calibration CalibrationOf(const FitSummary& fit, const FitOptions& options) {
  Calibration calibration;
  calibration.model = fit.model;
  calibration.sigma = fit.sigma;
  FitRecord record;
  record.gyro_temp_order = options.gyro_temp_order;
  record.accel_temp_order = options.accel_temp_order;
  record.g_sensitivity_fitted = options.fit_g_sensitivity;
  record.fitted = options.Groups(true);
  record.gyro_bias_stability_radps = options.gyro_bias_stability_radps;
  record.accel_bias_stability_mps2 = options.accel_bias_stability_mps2;
  record.bias_correlation_s = options.bias_correlation_s;
  calibration.fit = record;
  return calibration;
}

// The truth of Truth() in raw units of `raw_per_si` counts per SI unit (bias, scale, g-sensitivity).
SensorModel InCounts(SensorModel model, double raw_per_si) {
  for (int c = 0; c < kGyroCoefficients; ++c) {
    if (c >= kMisalignmentCoefficient && c < kGSensitivityCoefficient) continue;
    for (int k = 0; k < kPolynomialTerms; ++k) model.gyro[c * kPolynomialTerms + k] *= raw_per_si;
  }
  for (int c = 0; c < kMisalignmentCoefficient; ++c) {
    for (int k = 0; k < kPolynomialTerms; ++k) model.accel[c * kPolynomialTerms + k] *= raw_per_si;
  }
  return model;
}

// The certificate's prediction on a fitted run names the coefficient `plan check` names for the
// same plan and schedule, and its sigma is the fit's within the one-run tolerance: for a unit in
// SI with a wandering bias and for one in counts (white noise), whose sigmas the prediction states
// through the fitted scale factors.
TEST(PlanPrediction, AFittedRunsLimitingCoefficientIsThePlansWithTheFitsSigma) {
  // Without the +-300 deg/s about x, the gyro scale x is clearly the weakest of its group.
  std::vector<TableSegment> segments;
  for (const TableSegment& s : SixPositionPlan()) {
    if (!(s.up.x() == 1.0 && std::abs(s.rate_radps) > 200.0 * kDegToRad)) segments.push_back(s);
  }
  Plan plan;
  plan.segments = segments;
  plan.site = Site();
  // Tolerances far apart: the gyro scale limits, whatever the run's noise.
  const std::map<std::string, double> tolerances = {{"gyro.scale", 1.0}, {"accel.scale", 1e3}};
  for (const double raw_per_si : {1.0, 1000.0}) {
    SimulationOptions schedule = Schedule(77);  // the noise is in SI
    if (raw_per_si != 1.0) schedule.gyro_bias_instability = schedule.accel_bias_instability = 0.0;
    PlanCheckOptions options;
    options.tolerances = tolerances;
    const PlanCheck check = CheckPlan(segments, Site(), schedule, FitOptions(), options);
    ASSERT_FALSE(check.rows.empty());
    EXPECT_EQ(check.rows.front().name, "gyro scale x");
    const FitOptions fit_options = FitOptionsFor(schedule);
    const std::vector<Window> windows = SimulatedWindows(segments, schedule, InCounts(Truth(), raw_per_si));
    const FitSummary fit = FitThermalModel(windows, Site(), segments, fit_options);
    ASSERT_TRUE(fit.IsSolutionUsable());
    const LimitingPrediction p = PredictLimiting(CalibrationOf(fit, fit_options), plan, windows, tolerances);
    ASSERT_EQ(p.why_not, "") << raw_per_si;
    std::printf("%g raw per SI unit: %s\n", raw_per_si, LimitingPredictionText(p).c_str());
    EXPECT_EQ(p.name, check.rows.front().name) << raw_per_si;
    EXPECT_EQ(p.figure, "gyro_scale_per_dps.x") << raw_per_si;
    EXPECT_NEAR(p.predicted_sigma / check.rows.front().sigma, 1.0, kReportedSigmaTolerance) << raw_per_si;
    EXPECT_NEAR(p.achieved_sigma / p.predicted_sigma, 1.0, kReportedSigmaTolerance) << raw_per_si;
    EXPECT_DOUBLE_EQ(p.tolerance, 1.0);
  }
}

// The certificate's row, with and without tolerances, and where nothing can be predicted.
TEST(PlanPrediction, TheCertificateRowSaysPredictedAndAchieved) {
  LimitingPrediction p;
  p.name = "gyro bias z";
  p.unit = "deg/s";
  p.tolerance = 0.01;
  p.ratio = 0.0241;
  p.predicted_sigma = 1.2e-4;
  p.achieved_sigma = 1.3e-4;
  p.achieved_expanded = 2.7e-4;
  EXPECT_EQ(
      LimitingPredictionText(p),
      "gyro bias z: predicted sigma 0.00012 deg/s, achieved 0.00013 deg/s (U 0.00027 deg/s), at 25 degC; "
      "tolerance 0.01 deg/s, predicted 2 sigma over the range / tolerance 0.0241");
  p.tolerance = 0.0;
  p.achieved_expanded = -1.0;
  p.term = 1;
  p.name = "gyro bias z (linear term)";
  p.unit = "deg/s/degC";
  EXPECT_EQ(
      LimitingPredictionText(p),
      "no tolerances given (no limits file); the sigma that grows most over the range, gyro bias z (linear "
      "term): predicted sigma 0.00012 deg/s/degC, achieved 0.00013 deg/s/degC");
  EXPECT_EQ(PredictLimiting(Calibration(), Plan(), {}, {}).why_not,
            "the calibration has no fit record or no sigmas");
  EXPECT_EQ(LimitingPredictionText(PredictLimiting(Calibration(), Plan(), {}, {})),
            "not predicted: the calibration has no fit record or no sigmas");
}

// A limits file's coefficient criteria as tolerances: a limit on the value or its sigma as it is,
// a [min, max] limit by its half-width, per cent in ppm, the smallest of a group's.
TEST(PlanPrediction, LimitsGiveTheTolerancesOfTheirGroups) {
  Limits limits;
  const auto criterion = [](const std::string& quantity, double max_abs) {
    LimitCriterion c;
    c.quantity = quantity;
    c.max_abs = max_abs;
    return c;
  };
  limits.criteria = {criterion("gyro_bias_dps", 0.5), criterion("gyro_bias_dps", 0.01),
                     criterion("accel_scale_error_pct", 0.2), criterion("accel_bias_mg", 0.0),
                     criterion("fit_temp_range_c", 0.0)};
  limits.criteria[3].min = -3.0;
  limits.criteria[3].max = 1.0;
  std::map<std::string, double> tolerances;
  TolerancesFromLimits(limits, &tolerances);
  EXPECT_EQ(tolerances, (std::map<std::string, double>{
                            {"gyro.bias", 0.01}, {"accel.scale", 2000.0}, {"accel.bias", 2.0}}));
}

// A fast ramp read by a slow logger: 0.43 degC/s at 10 Hz passes the windows' 0.5 degC span in 12
// samples, fewer than a window's 20. Plan check cuts its windows with the fit's own code, so the
// prediction holds: the same windows as every run's, and the fit's reported sigmas and their
// spread over runs match it (a window builder that dropped every short piece lost the whole run,
// and a prediction of one window per dwell claimed samples the fit never had).
TEST(PlanPrediction, HoldsOnAFastRampReadByASlowLogger) {
  constexpr int kRuns = 12;
  // The mean over runs of the fit's reported sigma / predicted, per class: within this of 1
  // (relative). 12 runs of 12..36 coefficients a class.
  constexpr double kReportedTolerance = 0.10;
  // The RMS of (fitted - truth) / predicted sigma, per class: within this of 1 (relative; the
  // sampling error of an RMS over 144..432 values is 3.5 .. 6 %).
  constexpr double kFastRampSpreadTolerance = 0.2;
  const std::vector<TableSegment> segments = SixPositionPlan();
  const auto schedule = [](std::uint64_t seed) {
    SimulationOptions o = Schedule(seed);
    o.ramp = true;
    o.ramp_from_c = -40.0;
    o.ramp_to_c = 85.0;
    o.passes = 4;
    o.rate_hz = 10.0;
    return o;
  };
  WindowStats planned_stats;
  const std::vector<Window> planned =
      PlannedWindows(segments, Site(), schedule(1), WindowOptions(), &planned_stats);
  EXPECT_EQ(planned_stats.short_samples, 0);
  EXPECT_EQ(planned_stats.window_samples,
            planned_stats.samples - planned_stats.transition_samples - planned_stats.trimmed_samples);
  const Predicted predicted = Predict(segments, schedule(1));
  const SensorModel truth = Truth();
  std::map<std::string, ClassTally> tally;
  for (int run = 0; run < kRuns; ++run) {
    const std::vector<Window> windows = SimulatedWindows(segments, schedule(500 + run), truth);
    ASSERT_EQ(windows.size(), planned.size()) << "run " << run;
    for (size_t w = 0; w < windows.size(); ++w) {
      EXPECT_EQ(windows[w].samples, planned[w].samples);
      EXPECT_NEAR(windows[w].temp_c, planned[w].temp_c, 0.05);  // the temperature's reading noise
    }
    const FitSummary fit = FitThermalModel(windows, Site(), segments, FitOptionsFor(schedule(1)));
    ASSERT_TRUE(fit.IsSolutionUsable()) << "run " << run;
    AddToTally(fit, truth, predicted, &tally);
  }
  ASSERT_EQ(tally.size(), 7u);
  for (const auto& [group, t] : tally) {
    std::printf("%-20s spread / predicted %.3f, reported / predicted %.3f\n", group.c_str(), t.Spread(),
                t.Reported());
    EXPECT_NEAR(t.Reported(), 1.0, kReportedTolerance) << group;
    EXPECT_NEAR(t.Spread(), 1.0, kFastRampSpreadTolerance) << group;
  }
}

// Static positions on a cube: its faces (6), edges (12) or corners (8), then +-100 and +-300 deg/s
// about each axis: the 26-, 18- and 14-position plans of the literature, with rates.
std::vector<TableSegment> CubePlan(bool faces, bool edges, bool corners) {
  std::vector<TableSegment> segments;
  const auto add = [&segments](const Eigen::Vector3d& up, double rate_dps) {
    TableSegment s;
    s.id = static_cast<int>(segments.size()) + 1;
    s.up = up.normalized();
    s.rate_radps = rate_dps * kDegToRad;
    segments.push_back(s);
  };
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        const int nonzero = (x != 0) + (y != 0) + (z != 0);
        if ((nonzero == 1 && faces) || (nonzero == 2 && edges) || (nonzero == 3 && corners)) {
          add(Eigen::Vector3d(x, y, z), 0.0);
        }
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (double rate_dps : {100.0, -100.0, 300.0, -300.0}) add(Eigen::Vector3d::Unit(axis), rate_dps);
  }
  return segments;
}

// `segments` simulated for a unit in counts (testing::RandomMemsModel) and fitted as `imufit fit`
// fits a file: the channel check, the windows and the fit. Every coefficient within kSigmas of the
// truth (noisy) or kNoiseFree of it (relative to the coefficient's largest truth in its class).
void ExpectFitsAndHitsTruth(const std::string& name, const std::vector<TableSegment>& segments, bool noisy) {
  constexpr double kSigmas = 5.0;
  constexpr double kNoiseFree = 1e-7;  // relative, worst case
  SimulationOptions schedule;
  schedule.soak_temps_c = {-40.0, -5.45, 50.45, 85.0};
  schedule.dwell_s = 6.0;
  schedule.transition_s = 1.0;
  schedule.rate_hz = 50.0;
  if (noisy) {
    schedule.gyro_noise_density = 1e-4;
    schedule.accel_noise_density = 1e-3;
    schedule.quantize = true;
  }
  const SensorModel truth = testing::RandomMemsModel(3);
  Plan plan;
  plan.path = name;
  plan.site = Site();
  plan.segments = segments;
  SamplesInMemory samples;
  samples.name = name + (noisy ? " noisy" : " noise-free");
  samples.has_segment = true;
  SimulateRun(schedule, plan.site, segments, truth,
              [&](const Sample& raw, const SegmentTruth&) { samples.samples.push_back(raw); });
  FitRunResult result;
  try {
    result = FitRun(plan, "", samples, FitRunOptions());
  } catch (const std::exception& e) {
    ADD_FAILURE() << samples.name << ": " << e.what();
    return;
  }
  ASSERT_TRUE(result.fit.IsSolutionUsable()) << samples.name;
  for (bool gyro : {true, false}) {
    const double* fitted = gyro ? result.fit.model.gyro.data() : result.fit.model.accel.data();
    const double* sigma = gyro ? result.fit.sigma.gyro.data() : result.fit.sigma.accel.data();
    const std::vector<double> expected = gyro ? std::vector<double>(truth.gyro.begin(), truth.gyro.end())
                                              : std::vector<double>(truth.accel.begin(), truth.accel.end());
    for (size_t p = 0; p < expected.size(); ++p) {
      double largest = 0.0;  // of the parameter's class and term
      for (size_t q = p % kPolynomialTerms; q < expected.size(); q += kPolynomialTerms) {
        if (ClassOf(gyro, static_cast<int>(q)) == ClassOf(gyro, static_cast<int>(p))) {
          largest = std::max(largest, std::abs(expected[q]));
        }
      }
      const double bound = noisy ? kSigmas * sigma[p] : kNoiseFree * std::max(largest, 1e-12);
      EXPECT_LE(std::abs(fitted[p] - expected[p]), bound)
          << samples.name << ": " << ClassOf(gyro, static_cast<int>(p)) << " parameter " << p;
    }
  }
}

// The channel check judges each channel against the truth the plan gives each window: faces at 1 g,
// edges at 0.71 g and corners at 0.58 g are one line, not scatter (they were read as a dead
// channel). The plan `plan design` writes for docs/plan.md's example (corners and rates) too.
TEST(PlanFits, FacesEdgesAndCornersPlansFitAndHitTruth) {
  for (const bool noisy : {false, true}) {
    ExpectFitsAndHitsTruth("26 positions", CubePlan(true, true, true), noisy);
    ExpectFitsAndHitsTruth("18 positions", CubePlan(true, true, false), noisy);
    ExpectFitsAndHitsTruth("14 positions", CubePlan(true, false, true), noisy);
  }
}

TEST(PlanFits, TheDesignOfTheDocsExampleFitsAndHitsTruth) {
  PlanDesignOptions options;  // docs/plan.md's example
  options.positions = "faces,edges,corners";
  options.rates_dps = {100.0, 300.0};
  options.set_points_c = {-40.0, -15.0, -5.45, 10.0, 35.0, 50.45, 60.0, 85.0};
  options.check.tolerances = {{"gyro.bias", 0.0012}, {"accel.bias", 0.1}, {"gyro.scale", 60.0}};
  SimulationOptions schedule;
  schedule.dwell_s = 20.0;
  schedule.transition_s = 10.0;
  schedule.gyro_noise_density = 1e-4;
  schedule.accel_noise_density = 1e-3;
  const PlanDesign design = DesignPlan({}, Site(), schedule, options);
  ASSERT_TRUE(design.met);
  bool corners = false;
  for (const TableSegment& s : design.segments) {
    corners = corners || (s.rate_radps == 0.0 && (s.up.array().abs() > 0.5).count() == 3);
  }
  EXPECT_TRUE(corners) << "the design holds corner positions";
  for (const bool noisy : {false, true}) ExpectFitsAndHitsTruth("the designed plan", design.segments, noisy);
}

// A hand procedure (io/hand_procedure.h) quick to simulate: 12 rests of 4 s, 50 Hz.
HandProcedure QuickHand() {
  HandProcedure hand;
  hand.poses = 12;
  hand.dwell_s = 4.0;
  hand.turn_s = 1.5;
  hand.rate_hz = 50.0;
  return hand;
}

SimulationOptions HandNoise() {
  SimulationOptions noise;
  noise.gyro_noise_density = 1e-4;
  noise.accel_noise_density = 1e-3;
  return noise;
}

// The hand check's prediction against the spread of the field fit's values over many sessions of
// the procedure (other seeds, so other poses, turns and noise): per class of coefficient, the RMS
// of (fitted - truth) / predicted sigma. The prediction averages the fit's sigmas over
// kHandPredictionSessions sessions, whose poses differ: the spread over random sessions is what it
// predicts.
constexpr int kHandPredictionSessions = 8;
constexpr int kHandMonteCarloSessions = 40;
// The RMS z of a class within [1 / kHandSpreadRatio, kHandSpreadRatio] (relative): 40 sessions of
// 3..9 coefficients a class, the RMS's sampling error is 4..7 %; the prediction's own (8 sessions
// of random poses), a few per cent more.
constexpr double kHandSpreadRatio = 1.25;

TEST(HandCheckTest, PredictsTheSpreadOfFieldFitsOverSessionsOfTheProcedure) {
  const HandSetup setup = HandSetupOf(QuickHand(), HandNoise());
  PlanCheckOptions options;
  const HandCheck check = CheckHandProcedure(setup, options, kHandPredictionSessions);
  ASSERT_TRUE(check.undetermined.empty()) << check.undetermined.front();
  ASSERT_EQ(check.fitted, kHandPredictionSessions);
  std::map<std::string, double> predicted;  // row name -> sigma, SI
  for (const PlanRow& row : check.rows) {
    if (row.term == 0) predicted[row.name] = row.sigma / PlanGroupFactor(row.group);
  }
  const SensorModel truth = SensorModel::Identity();
  std::map<std::string, std::pair<double, int>> classes;  // group -> sum of z^2, count
  int fitted = 0;
  for (int s = 0; s < kHandMonteCarloSessions; ++s) {
    SimulationOptions schedule = setup.schedule;
    schedule.seed = 1000 + static_cast<std::uint64_t>(s);
    std::vector<Sample> samples;
    SimulateFieldSession(schedule, setup.session, truth,
                         [&samples](const Sample& raw, const SegmentTruth&) { samples.push_back(raw); });
    const FieldFitSummary fit = FitField(samples, setup.fit);
    if (!fit.IsSolutionUsable()) continue;
    ++fitted;
    for (const PlanRow& row : check.rows) {
      if (row.term != 0) continue;
      const int i = row.coefficient * kPolynomialTerms;
      const double error = row.gyro ? fit.model.gyro[i] - truth.gyro[i] : fit.model.accel[i] - truth.accel[i];
      const double z = error / predicted[row.name];
      classes[row.group].first += z * z;
      ++classes[row.group].second;
    }
  }
  EXPECT_EQ(fitted, kHandMonteCarloSessions);
  EXPECT_EQ(classes.size(), 7u);  // every group: biases, scales, misalignments, g-sensitivity
  for (const auto& [group, sum] : classes) {
    const double rms = std::sqrt(sum.first / sum.second);
    std::printf("%-20s RMS z %.3f over %d\n", group.c_str(), rms, sum.second);
    EXPECT_GT(rms, 1.0 / kHandSpreadRatio) << group;
    EXPECT_LT(rms, kHandSpreadRatio) << group;
  }
}

TEST(HandCheckTest, AProcedureWithoutAPoseNearADirectionIsReportedSo) {
  HandProcedure hand = QuickHand();
  hand.up = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
             Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};  // never the y axis down
  const HandCheck check = CheckHandProcedure(HandSetupOf(hand, HandNoise()), PlanCheckOptions(), 2);
  ASSERT_EQ(check.undetermined.size(), 1u);
  EXPECT_EQ(check.undetermined[0], "no pose with gravity near +y (the y axis down) (2 of 2 sessions)");
  EXPECT_EQ(check.fitted, 0);
  EXPECT_TRUE(check.rows.empty());
}

TEST(HandCheckTest, AnUnmetToleranceGetsMeasuredAlternatives) {
  PlanCheckOptions options;
  options.tolerances["accel.bias"] = 0.02;  // mg: tighter than 4 s rests give
  const HandCheck check = CheckHandProcedure(HandSetupOf(QuickHand(), HandNoise()), options, 2);
  ASSERT_TRUE(check.tolerance_unmet);
  ASSERT_EQ(check.alternatives.size(), 4u);
  EXPECT_EQ(check.alternatives[0].option, "--dwell 8");
  EXPECT_EQ(check.alternatives[1].option, "--dwell 16");
  EXPECT_EQ(check.alternatives[2].option, "--poses 18");
  EXPECT_EQ(check.alternatives[3].option, "--poses 24");
  // White noise on the rests: four times the dwell halves the accelerometer's bias sigma.
  EXPECT_LT(check.alternatives[1].worst_ratio, 0.6 * check.rows.front().ratio);
  EXPECT_GT(check.alternatives[1].session_s, check.session_s);
}

}  // namespace
}  // namespace imufit
