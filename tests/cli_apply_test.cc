// End-to-end tests of `imufit apply`.
//
// The key acceptance test: a run simulated without noise from a known calibration, corrected by
// `imufit apply` with that calibration, gives back the true rate and specific force of every
// sample, transitions included, to kRecoveryToleranceSi. It is done twice: on `imufit simulate`'s
// own output and truth, and on samples this file computes with its own forward model written
// from docs/spec.md (it reads the calibration with yaml-cpp, not with imufit's reader), so that
// neither the simulator nor imufit's reader and model are checked only against themselves.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Core>
#include <Eigen/Dense>
#include <random>

#include "imufit/model/sensor_model.h"

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// Worst-case relative difference between two forward models that do the same arithmetic in a
// different order.
constexpr double kForwardAgreementRelative = 1e-12;

std::string FormatExactly(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// ------------------------------------------------------------------------------------------
// A forward model written from docs/spec.md section 1, independent of imufit's reader and model:
//   B = diag(S_g) inv(M_g) omega + V_g + H a,   A = diag(S_a) inv(M_a) a + V_a,
// every coefficient c0 + c1 dT + c2 dT^2 + c3 dT^3 with dT = T - reference_temp_c.
class SpecForwardModel {
 public:
  explicit SpecForwardModel(const std::string& calibration_path) {
    const YAML::Node root = YAML::LoadFile(calibration_path);
    reference_c_ = root["reference_temp_c"] ? root["reference_temp_c"].as<double>() : 25.0;
    gyro_ = root["gyro"];
    accel_ = root["accel"];
  }

  // The calibration's coefficient `group`.`name` (e.g. "bias", "x") at temp_c.
  static double Coefficient(const YAML::Node& sensor, const std::string& group, const std::string& name,
                            double dT) {
    const YAML::Node c = sensor[group][name];
    EXPECT_EQ(c.size(), 4u) << group << "." << name;
    return c[0].as<double>() + c[1].as<double>() * dT + c[2].as<double>() * dT * dT +
           c[3].as<double>() * dT * dT * dT;
  }

  Eigen::Vector3d Raw(const YAML::Node& sensor, double temp_c, const Eigen::Vector3d& truth,
                      const Eigen::Vector3d& specific_force, bool with_g_sensitivity) const {
    const double dT = temp_c - reference_c_;
    const char* axes[3] = {"x", "y", "z"};
    Eigen::Vector3d bias;
    Eigen::Vector3d scale;
    Eigen::Matrix3d misalignment = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d g_sensitivity = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) {
      bias(i) = Coefficient(sensor, "bias", axes[i], dT);
      scale(i) = Coefficient(sensor, "scale", axes[i], dT);
      for (int j = 0; j < 3; ++j) {
        const std::string name = std::string(axes[i]) + axes[j];  // row i, column j
        if (i != j) misalignment(i, j) = Coefficient(sensor, "misalignment", name, dT);
        if (with_g_sensitivity) g_sensitivity(i, j) = Coefficient(sensor, "g_sensitivity", name, dT);
      }
    }
    const Eigen::Vector3d sensor_frame = misalignment.fullPivLu().inverse() * truth;
    return scale.asDiagonal() * sensor_frame + bias + g_sensitivity * specific_force;
  }

  Eigen::Vector3d Gyro(double temp_c, const Eigen::Vector3d& omega, const Eigen::Vector3d& a) const {
    return Raw(gyro_, temp_c, omega, a, true);
  }
  Eigen::Vector3d Accel(double temp_c, const Eigen::Vector3d& a) const {
    return Raw(accel_, temp_c, a, Eigen::Vector3d::Zero(), false);
  }

  // The same coefficients in imufit's parameter layout (sensor_model.h), to cross-check the
  // model header's forward form against this one.
  SensorModel ToSensorModel() const {
    SensorModel model;
    model.basis.center_c = reference_c_;
    Fill(gyro_, kGyroCoefficients, model.gyro.data());
    Fill(accel_, kAccelCoefficients, model.accel.data());
    return model;
  }

 private:
  static void Fill(const YAML::Node& sensor, int coefficients, double* params) {
    for (int i = 0; i < coefficients; ++i) {
      const YAML::Node c = sensor[kCoefficientNames[i].group][kCoefficientNames[i].axis];
      for (int k = 0; k < kPolynomialTerms; ++k) params[i * kPolynomialTerms + k] = c[k].as<double>();
    }
  }

  double reference_c_ = 25.0;
  YAML::Node gyro_;
  YAML::Node accel_;
};

// ------------------------------------------------------------------------------------------ apply

// THE acceptance test: a noiseless simulation from a known calibration, corrected by
// `imufit apply` with that calibration, gives back the truth of every sample, transitions
// included, across the whole temperature range, with Earth rate and lever arms in the plan.
TEST_F(CliTest, ApplyRecoversTheTruthOfANoiselessSimulation) {
  for (const char* calibration : {"mems_truth.yaml", "tactical_truth.yaml"}) {
    for (const char* plan : {"plan_6pos.yaml", "plan_24pos.yaml"}) {
      SCOPED_TRACE(std::string(calibration) + " " + plan);
      const auto [samples, truth] =
          SimulateNoiseless(Fixture(plan), Fixture(calibration), "run", {"--ramp=-40,85", "--passes", "2"});
      const std::string corrected = Path("corrected.csv");
      const RunResult r =
          Run({"apply", "--calibration", Fixture(calibration), "--samples", samples, "-o", corrected});
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_EQ(r.err, "") << "no warning expected inside the fit range";
      ExpectRecovered(corrected, truth);
      const Table table = ReadTable(corrected);
      EXPECT_EQ(table.header, (std::vector<std::string>{"time_s", "temp_c", "segment", "gyro_x", "gyro_y",
                                                        "gyro_z", "accel_x", "accel_y", "accel_z"}));
    }
  }
}

// The bundled golden pair: fixtures/mems_6pos_noiseless.csv.gz corrected with mems_truth.yaml is
// fixtures/mems_6pos_noiseless_truth.csv.gz.
TEST_F(CliTest, ApplyTurnsTheNoiselessFixtureIntoItsTruth) {
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s",
                           Fixture("mems_6pos_noiseless.csv.gz"), "-o", Path("corrected.csv.gz"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  ExpectRecovered(Path("corrected.csv.gz"), Fixture("mems_6pos_noiseless_truth.csv.gz"));
}

// The same acceptance check without imufit's simulator: raw samples computed here from chosen
// truths with the forward model of docs/spec.md (SpecForwardModel), at random temperatures in
// -40..85 degC, written as a CSV with the columns in another order, an extra column, comments
// and CRLF line ends.
TEST_F(CliTest, ApplyInvertsAnIndependentForwardModel) {
  for (const char* calibration : {"mems_truth.yaml", "tactical_truth.yaml"}) {
    SCOPED_TRACE(calibration);
    const SpecForwardModel spec(Fixture(calibration));
    const SensorModel header_model = spec.ToSensorModel();
    std::mt19937_64 engine(2026);
    std::uniform_real_distribution<double> temp(-40.0, 85.0);
    std::uniform_real_distribution<double> rate(-6.0, 6.0);     // rad/s
    std::uniform_real_distribution<double> force(-30.0, 30.0);  // m/s^2
    std::string samples =
        "# hand-made raw samples\r\nnote,accel_z,gyro_y,segment,temp_c,accel_x,gyro_z,time_s,gyro_x,"
        "accel_y\r\n";
    std::string truth = "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
    constexpr int kSamples = 2000;
    for (int i = 0; i < kSamples; ++i) {
      const double t = 0.01 * i;
      const double temp_c = temp(engine);
      const int segment = i % 7 == 0 ? -1 : i / 50;
      const Eigen::Vector3d omega(rate(engine), rate(engine), rate(engine));
      const Eigen::Vector3d a(force(engine), force(engine), force(engine));
      const Eigen::Vector3d gyro_m = spec.Gyro(temp_c, omega, a);
      const Eigen::Vector3d accel_m = spec.Accel(temp_c, a);
      // The model header's forward form agrees with docs/spec.md's.
      Eigen::Vector3d header_gyro;
      Eigen::Vector3d header_accel;
      header_model.Forward(temp_c, omega, a, &header_gyro, &header_accel);
      ASSERT_LE((header_gyro - gyro_m).norm(), kForwardAgreementRelative * gyro_m.norm()) << i;
      ASSERT_LE((header_accel - accel_m).norm(), kForwardAgreementRelative * accel_m.norm()) << i;
      const auto f = FormatExactly;
      samples += "\"row " + std::to_string(i) + ", hand-made\"," + f(accel_m.z()) + "," + f(gyro_m.y()) +
                 "," + std::to_string(segment) + "," + f(temp_c) + "," + f(accel_m.x()) + "," +
                 f(gyro_m.z()) + "," + f(t) + "," + f(gyro_m.x()) + "," + f(accel_m.y()) + "\r\n";
      if (i == kSamples / 2) samples += "# a comment half way\r\n";
      truth += f(t) + "," + f(temp_c) + "," + std::to_string(segment) + "," + f(omega.x()) + "," +
               f(omega.y()) + "," + f(omega.z()) + "," + f(a.x()) + "," + f(a.y()) + "," + f(a.z()) + "\n";
    }
    const std::string samples_path = Write("raw.csv", samples);
    const std::string truth_path = Write("truth.csv", truth);
    const RunResult r = Run(
        {"apply", "--calibration", Fixture(calibration), "--samples", samples_path, "-o", Path("out.csv")});
    ASSERT_EQ(r.status, 0) << r.err;
    // Compare numerically: ExpectRecovered compares time and temperature text, which differ in
    // spelling between %.17g and the shortest round-trip form.
    const Table got = ReadTable(Path("out.csv"));
    const Table expected = ReadTable(truth_path);
    ASSERT_EQ(got.header, expected.header);
    ASSERT_EQ(got.rows.size(), static_cast<size_t>(kSamples));
    double worst = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      ASSERT_EQ(got.Number(i, "time_s"), expected.Number(i, "time_s"));
      ASSERT_EQ(got.Number(i, "temp_c"), expected.Number(i, "temp_c"));
      ASSERT_EQ(got.rows[i][2], expected.rows[i][2]) << "segment";
      worst = std::max(worst, (got.Vector(i, "gyro") - expected.Vector(i, "gyro")).cwiseAbs().maxCoeff());
      worst = std::max(worst, (got.Vector(i, "accel") - expected.Vector(i, "accel")).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, kRecoveryToleranceSi);
  }
}

TEST_F(CliTest, ApplyWithoutSegmentColumnWritesNone) {
  const std::string samples = Write("raw.csv",
                                    "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                    "0,25,23.4,-41.7,12.9,35.2,-18.6,52.9\n"
                                    "0.01,25,23.4,-41.7,12.9,35.2,-18.6,52.9\n");
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table out = ReadTable(Path("out.csv"));
  EXPECT_EQ(out.header, (std::vector<std::string>{"time_s", "temp_c", "gyro_x", "gyro_y", "gyro_z", "accel_x",
                                                  "accel_y", "accel_z"}));
  ASSERT_EQ(out.rows.size(), 2u);
  // Raw = bias at 25 degC: nothing moves and there is no specific force.
  for (const char* column : {"gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"}) {
    EXPECT_EQ(out.Number(0, column), 0.0) << column;
  }
}
TEST_F(CliTest, ApplyWarnsOnceWithACountOutsideTheFitTemperatureRange) {
  std::string narrow = ReadBytes(Fixture("mems_truth.yaml"));
  const std::string range = "fit_temp_range_c: [-40, 85]";
  ASSERT_NE(narrow.find(range), std::string::npos);
  narrow.replace(narrow.find(range), range.size(), "fit_temp_range_c: [-10, 60]");
  const std::string calibration = Write("narrow.yaml", narrow);
  const auto [samples, truth] =
      SimulateNoiseless(Fixture("plan_6pos.yaml"), Fixture("mems_truth.yaml"), "ramp", {"--ramp=-40,85"});
  const Table raw = ReadTable(samples);
  // Readings within 0.5 degC of the range are the thermometer's noise, not extrapolation (the
  // README's promise; io/correct_file.h kFitRangeToleranceC).
  constexpr double kFitRangeToleranceC = 0.5;
  long long outside = 0, within_tolerance = 0;
  for (size_t i = 0; i < raw.rows.size(); ++i) {
    const double t = raw.Number(i, "temp_c");
    outside += (t < -10.0 - kFitRangeToleranceC || t > 60.0 + kFitRangeToleranceC) ? 1 : 0;
    within_tolerance += ((t < -10.0 || t > 60.0) && t >= -10.5 && t <= 60.5) ? 1 : 0;
  }
  ASSERT_GT(outside, 0);
  ASSERT_GT(within_tolerance, 0);  // the ramp passes through the tolerance: those are not counted
  ASSERT_LT(outside, static_cast<long long>(raw.rows.size()));
  const RunResult r = Run({"apply", "-c", calibration, "-s", samples, "-o", Path("out.csv")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // once
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::to_string(outside) + " of " + std::to_string(raw.rows.size()) + " samples"),
            std::string::npos)
      << r.err;
  ExpectRecovered(Path("out.csv"), truth);  // a warning, not a refusal
}

}  // namespace
}  // namespace imufit::testing
