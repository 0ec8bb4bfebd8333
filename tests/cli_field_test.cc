// End-to-end tests of a calibration by hand: `imufit simulate --field` -> `imufit fit --field` ->
// `imufit apply`, judged on the corrected samples against issue 32's bars (|a| within 1 mg of g at
// every pose, gravity's direction after the turns within 0.3 deg RMS), and the command's refusals.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "cli_util.h"
#include "imufit/io/calibration.h"
#include "imufit/model/attitude_integration.h"

namespace imufit::testing {
namespace {

constexpr double kGravityMps2 = 9.80665;
// A refit of the golden session: every coefficient within this fraction of its sigma of the golden
// file's, every sigma within this relative difference (worst case; the same session and program
// give the same numbers up to the solver's last iterations).
constexpr double kGoldenSigmaFraction = 1e-3;
constexpr double kGoldenSigmaRelative = 1e-6;
// Issue 32's bars, RMS over the poses and over the turns.
constexpr double kMaxAccelNormRmsMps2 = 1e-3 * kGravityMps2;
constexpr double kMaxDirectionRmsRad = 0.3 * kDegToRad;

// `imufit simulate --field` of the MEMS unit (fixtures/mems_truth.yaml) at 25 degC: 12 poses of
// about 3 s, 100 Hz, white noise, counts, 2 ms of stamp jitter, a few lost samples; `extra` adds.
std::vector<std::string> FieldSessionArgs(const std::string& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"simulate",
                                   "--field",
                                   "--calibration",
                                   Fixture("mems_truth.yaml"),
                                   "-o",
                                   out,
                                   "--temps",
                                   "25",
                                   "--dwell",
                                   "3",
                                   "--rate",
                                   "100",
                                   "--gyro-noise-density",
                                   "2e-4",
                                   "--accel-noise-density",
                                   "1e-3",
                                   "--quantize",
                                   "--time-jitter-s",
                                   "0.002",
                                   "--drop-probability",
                                   "0.005",
                                   "--seed",
                                   "12",
                                   "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST_F(CliTest, FieldSessionSimulatedFittedAndApplied) {
  const std::string raw = Path("session.csv");
  const std::string truth = Path("truth.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--truth", truth})).status, 0);
  EXPECT_EQ(ReadTable(raw).header, (std::vector<std::string>{"time_s", "temp_c", "gyro_x", "gyro_y", "gyro_z",
                                                             "accel_x", "accel_y", "accel_z"}));
  const std::string calibration = Path("cal.yaml");
  const RunResult fit = Run({"fit", "--field", "--samples", raw, "-o", calibration});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("converged (12 poses, 11 turns"), std::string::npos) << fit.out;
  // The calibration as another program reads it: the body frame and the held terms' sigmas.
  const YAML::Node cal = YAML::LoadFile(calibration);
  EXPECT_EQ(cal["body_frame"].as<std::string>(), "accelerometer_xy");
  EXPECT_EQ(cal["fit"]["field"]["poses"].as<int>(), 12);
  EXPECT_EQ(cal["accel"]["misalignment"]["xy"][0].as<double>(), 0.0);
  EXPECT_EQ(cal["sigma"]["accel"]["misalignment"]["yz"][0].as<double>(), 0.0);
  EXPECT_GT(cal["sigma"]["gyro"]["scale"]["z"][0].as<double>(), 0.0);

  const std::string corrected = Path("corrected.csv");
  const RunResult apply = Run({"apply", "--calibration", calibration, "--samples", raw, "-o", corrected});
  ASSERT_EQ(apply.status, 0) << apply.err;
  const Table out = ReadTable(corrected);
  const Table labels = ReadTable(truth);  // segment: the pose, -1 turning
  ASSERT_EQ(out.rows.size(), labels.rows.size());
  // Each pose's corrected mean specific force, and its samples' span.
  struct Pose {
    Eigen::Vector3d a_sum = Eigen::Vector3d::Zero();
    int n = 0;
    size_t first = 0, last = 0;
  };
  std::vector<Pose> poses;
  for (size_t i = 0; i < out.rows.size(); ++i) {
    const int pose = static_cast<int>(labels.Number(i, "segment"));
    if (pose < 0) continue;
    if (pose >= static_cast<int>(poses.size())) {
      poses.resize(pose + 1);
      poses[pose].first = i;
    }
    poses[pose].a_sum += out.Vector(i, "accel");
    ++poses[pose].n;
    poses[pose].last = i;
  }
  ASSERT_EQ(poses.size(), 12u);
  double norm_sum = 0.0;
  for (const Pose& p : poses) norm_sum += std::pow((p.a_sum / p.n).norm() - kGravityMps2, 2);
  EXPECT_LT(std::sqrt(norm_sum / poses.size()), kMaxAccelNormRmsMps2);
  // Gravity's direction after each turn: the corrected gyro integrated from the last sample of a
  // pose to the first of the next, applied to the pose's mean direction.
  double direction_sum = 0.0;
  for (size_t p = 0; p + 1 < poses.size(); ++p) {
    std::vector<double> times_s;
    std::vector<Eigen::Vector3d> omega;
    for (size_t i = poses[p].last; i <= poses[p + 1].first; ++i) {
      times_s.push_back(out.Number(i, "time_s"));
      omega.push_back(out.Vector(i, "gyro"));
    }
    const Eigen::Vector3d from = (poses[p].a_sum / poses[p].n).normalized();
    const Eigen::Vector3d to = (poses[p + 1].a_sum / poses[p + 1].n).normalized();
    const Eigen::Vector3d predicted =
        RotateIntoCurrentFrame(IntegrateAttitude(times_s.data(), omega.data(), omega.size()), from);
    direction_sum += std::pow(std::atan2(predicted.cross(to).norm(), predicted.dot(to)), 2);
  }
  EXPECT_LT(std::sqrt(direction_sum / (poses.size() - 1)), kMaxDirectionRmsRad);
}

TEST_F(CliTest, FieldSimulationIsReproducible) {
  ASSERT_EQ(Run(FieldSessionArgs(Path("a.csv"), {})).status, 0);
  ASSERT_EQ(Run(FieldSessionArgs(Path("b.csv"), {})).status, 0);
  EXPECT_EQ(ReadFile(Path("a.csv")), ReadFile(Path("b.csv")));
}

TEST_F(CliTest, FieldFitRefusesWhatTheSessionCannotDetermine) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {})).status, 0);
  // The first third of the session: too few poses.
  std::ifstream in(raw);
  std::ofstream cut(Path("cut.csv"));
  std::string line;
  for (int n = 0; std::getline(in, line) && n < 1800; ++n) cut << line << "\n";
  cut.close();
  const std::string calibration = Path("cal.yaml");
  const RunResult r = Run({"fit", "--field", "--samples", Path("cut.csv"), "-o", calibration});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("poses at rest, needs at least 9"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing written"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(calibration));
}

TEST_F(CliTest, FieldOptionsAreChecked) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--no-temp-column"})).status, 0);
  const std::string out = Path("cal.yaml");
  const auto expect_bad = [&](const std::vector<std::string>& args, const std::string& message) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  };
  expect_bad({"fit", "--field", "--samples", raw, "-o", out}, "temp_c");  // no thermometer, no --temp-c
  expect_bad({"fit", "--samples", raw, "-o", out, "--temp-c", "25"}, "--plan is required (or --field)");
  expect_bad({"fit", "--field", "--plan", Fixture("plan_6pos.yaml"), "--samples", raw, "-o", out},
             "has no plan");
  expect_bad(
      {"fit", "--samples", raw, "-o", out, "--gravity-mps2", "9.8", "--plan", Fixture("plan_6pos.yaml")},
      "--field");
  expect_bad({"fit", "--field", "--samples", raw, "-o", out, "--temp-c", "25", "--gravity-mps2", "12"},
             "gravity_mps2");
  expect_bad({"fit", "--field", "--samples", raw, "-o", out, "--temp-c", "25", "--validate"},
             "--validate: is an option of a table fit, not of --field");
  expect_bad({"simulate", "--field", "--calibration", Fixture("mems_truth.yaml"), "-o", Path("s.csv"),
              "--poses", "5"},
             "poses");
  expect_bad({"simulate", "--field", "--plan", Fixture("plan_6pos.yaml"), "--calibration",
              Fixture("mems_truth.yaml"), "-o", Path("s.csv")},
             "has no plan");
  expect_bad({"simulate", "--calibration", Fixture("mems_truth.yaml"), "-o", Path("s.csv")},
             "--plan is required (or --field)");
  // With --temp-c the same session fits.
  const RunResult r = Run({"fit", "--field", "--samples", raw, "-o", out, "--temp-c", "25"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("every sample at 25 degC (--temp-c)"), std::string::npos) << r.out;
}

// The fixture's session by hand refitted gives its golden calibration (fixtures/README.md).
TEST_F(CliTest, FieldFitOfTheFixtureMatchesItsGolden) {
  const std::string out = Path("cal.yaml");
  const RunResult r =
      Run({"fit", "--field", "--samples", Fixture("mems_field_session.csv.gz"), "-o", out, "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Calibration fit = ReadCalibration(out);
  const Calibration golden = ReadCalibration(Fixture("golden/mems_field_session.yaml"));
  ASSERT_TRUE(fit.sigma && golden.sigma);
  const auto compare = [](const double* value, const double* sigma, const double* golden_value,
                          const double* golden_sigma, int count, const char* sensor) {
    for (int i = 0; i < count; ++i) {
      EXPECT_NEAR(value[i], golden_value[i], kGoldenSigmaFraction * golden_sigma[i]) << sensor << " " << i;
      EXPECT_NEAR(sigma[i], golden_sigma[i], kGoldenSigmaRelative * golden_sigma[i])
          << sensor << " sigma " << i;
    }
  };
  compare(fit.model.gyro.data(), fit.sigma->gyro.data(), golden.model.gyro.data(), golden.sigma->gyro.data(),
          kGyroParameters, "gyro");
  compare(fit.model.accel.data(), fit.sigma->accel.data(), golden.model.accel.data(),
          golden.sigma->accel.data(), kAccelParameters, "accel");
}

// A unit warming up during the session: fitted all the same, with a warning that the calibration
// is constant in temperature.
TEST_F(CliTest, FieldFitWarnsOfAWarmUp) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--warmup-c", "8", "--warmup-tau-s", "30"})).status, 0);
  const RunResult r = Run({"fit", "--field", "--samples", raw, "-o", Path("cal.yaml"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the session spans 17"), std::string::npos) << r.err;
}

// The same warm-up fitted over temperature: the biases cubic, the file's orders say so, no
// warning; scale factors in temperature from a 8-degree warm-up are refused with exit 1, naming
// the spread they need, and nothing is written.
TEST_F(CliTest, FieldFitOverAWarmUp) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--warmup-c", "8", "--warmup-tau-s", "30", "--poses", "20"})).status,
            0);
  const std::string out = Path("cal.yaml");
  RunResult r = Run({"fit", "--field", "--samples", raw, "-o", out, "--bias-temp-order", "3", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const YAML::Node cal = YAML::LoadFile(out);
  EXPECT_EQ(cal["fit"]["gyro_temp_order"].as<int>(), 3);
  EXPECT_NE(cal["gyro"]["bias"]["x"][1].as<double>(), 0.0);
  EXPECT_EQ(cal["gyro"]["scale"]["x"][1].as<double>(), 0.0);
  const std::string refused = Path("refused.yaml");
  r = Run({"fit", "--field", "--samples", raw, "-o", refused, "--scale-temp-order", "1", "-q"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("too little to fit the scale factors (order 1) in temperature, which needs 10 degC"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(refused));
}

// The unit's serial as for a table fit: the samples header's, and a stated one that contradicts it
// refused unless --allow-mismatch.
TEST_F(CliTest, FieldFitTakesTheSerialOfTheSamples) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--serial", "SN0001"})).status, 0);
  const std::string out = Path("cal.yaml");
  RunResult r = Run({"fit", "--field", "--samples", raw, "-o", out, "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(YAML::LoadFile(out)["serial"].as<std::string>(), "SN0001");
  const std::string other = Path("other.yaml");
  r = Run({"fit", "--field", "--samples", raw, "-o", other, "--serial", "SN0002", "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(other));
  r = Run({"fit", "--field", "--samples", raw, "-o", other, "--serial", "SN0002", "--allow-mismatch", "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_EQ(YAML::LoadFile(other)["serial"].as<std::string>(), "SN0002");
}

// Local gravity from the site: --latitude and --height-m give WGS-84 normal gravity (the file's
// fit: field: gravity_mps2 says which); with --gravity-mps2 as well, or a height alone, refused.
TEST_F(CliTest, FieldFitTakesGravityFromTheSite) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--gravity-mps2", "9.812464"})).status, 0);
  const std::string out = Path("cal.yaml");
  RunResult r =
      Run({"fit", "--field", "--samples", raw, "-o", out, "--latitude", "52.27", "--height-m", "80", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  constexpr double kNormalGravityAt52NMps2 =
      9.812464;  // WGS-84 at 52.27 deg, 80 m (model_test checks the formula)
  constexpr double kRoundingMps2 = 1e-5;
  EXPECT_NEAR(YAML::LoadFile(out)["fit"]["field"]["gravity_mps2"].as<double>(), kNormalGravityAt52NMps2,
              kRoundingMps2);
  r = Run({"fit", "--field", "--samples", raw, "-o", Path("both.yaml"), "--latitude", "52", "--gravity-mps2",
           "9.81"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("one or the other"), std::string::npos) << r.err;
  r = Run({"fit", "--field", "--samples", raw, "-o", Path("height.yaml"), "--height-m", "80"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("height_m needs latitude_deg"), std::string::npos) << r.err;
}

// --repeat: a second session of the same unit agrees within the combined sigmas; a session of a
// unit whose gyro x scale is 2 % off is named as differing there, and the file is the first's.
TEST_F(CliTest, FieldFitRepeatCompareSessions) {
  const std::string first = Path("first.csv");
  const std::string second = Path("second.csv");
  ASSERT_EQ(Run(FieldSessionArgs(first, {})).status, 0);
  std::vector<std::string> second_args = FieldSessionArgs(second, {});
  const auto seed = std::find(second_args.begin(), second_args.end(), "--seed");
  ASSERT_NE(seed, second_args.end());
  *(seed + 1) = "13";  // another session of the same unit
  ASSERT_EQ(Run(second_args).status, 0);
  const std::string out = Path("cal.yaml");
  RunResult r = Run({"fit", "--field", "--samples", first, "--repeat", second, "-o", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("repeatability against " + second), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the procedure is repeatable"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("differs:"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out));

  // Another unit: the truth's gyro x scale 2 % larger.
  std::ifstream in(Fixture("mems_truth.yaml"));
  std::string truth((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "x: [948.31,";  // the gyro's x scale, 2 % larger below
  ASSERT_NE(truth.find(from), std::string::npos);
  truth.replace(truth.find(from), from.size(), "x: [967.2762,");
  const std::string other_truth = Path("other_truth.yaml");
  std::ofstream(other_truth) << truth;
  second_args[3] = other_truth;
  ASSERT_EQ(Run(second_args).status, 0);
  r = Run({"fit", "--field", "--samples", first, "--repeat", second, "-o", Path("cal2.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("differs: gyro scale x"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the sessions differ beyond their sigmas"), std::string::npos) << r.out;
}

// Downstream: apply, allan --calibration and export take a field calibration; report (the
// certificate against a table run, with its limits) refuses it, saying why, and writes nothing.
TEST_F(CliTest, FieldCalibrationDownstream) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {})).status, 0);
  const std::string cal = Path("cal.yaml");
  ASSERT_EQ(Run({"fit", "--field", "--samples", raw, "-o", cal, "-q"}).status, 0);
  EXPECT_EQ(Run({"apply", "--calibration", cal, "--samples", raw, "-o", Path("corrected.csv"), "-q"}).status,
            0);
  // allan wants regular stamps (its own refusal of jitter is not the calibration's): a steady log.
  std::vector<std::string> steady_args = FieldSessionArgs(Path("steady.csv"), {});
  for (const char* jitter : {"--time-jitter-s", "--drop-probability"}) {
    const auto at = std::find(steady_args.begin(), steady_args.end(), jitter);
    ASSERT_NE(at, steady_args.end());
    steady_args.erase(at, at + 2);
  }
  ASSERT_EQ(Run(steady_args).status, 0);
  const RunResult allan =
      Run({"allan", "-s", Path("steady.csv"), "--calibration", cal, "-o", Path("adev.csv"), "-q"});
  EXPECT_EQ(allan.status, 0) << allan.err;
  for (const char* format : {"json", "c", "imucal"}) {
    const RunResult r =
        Run({"export", "-c", cal, "-f", format, "-o", Path(std::string("out.") + format), "-q"});
    EXPECT_EQ(r.status, 0) << format << ": " << r.err;
  }
  const std::string html = Path("report.html");
  const RunResult r = Run({"report", "-c", cal, "-p", Fixture("plan_6pos.yaml"), "-s", raw, "-o", html});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(
      r.err.find(
          "a calibration by hand (body_frame: accelerometer_xy, imufit fit --field) cannot be certified"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(html));
}

// A PX4 ULog that breaks the format: one line naming its byte offset, message type and what is
// wrong, exit 2, nothing written (python/tests/test_ulog.py fits whole ULog sessions).
TEST_F(CliTest, FieldFitRefusesABadUlogAtItsByte) {
  // The header, then a data message ('D', 4 bytes) of msg_id 7, which no subscription defines.
  const std::string bad = Write("bad.ulg", std::string("ULog\x01\x12\x35\x01", 8) + std::string(8, '\0') +
                                               std::string("\x04\x00"
                                                           "D"
                                                           "\x07\x00\x00\x00",
                                                           7));
  const RunResult r = Run({"fit", "--field", "--samples", bad, "-o", Path("cal.yaml")});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "imufit: " + bad + ": byte 16: 'D': msg_id 7, which no subscription ('A') defines\n");
  EXPECT_FALSE(std::filesystem::exists(Path("cal.yaml")));
  const RunResult unit =
      Run({"fit", "--field", "--samples", bad, "--time-unit", "ms", "-o", Path("cal.yaml")});
  EXPECT_EQ(unit.status, 2);
  EXPECT_NE(unit.err.find("--time-unit reads a CSV; this file is a PX4 ULog"), std::string::npos) << unit.err;
  const RunResult instance =
      Run({"fit", "--field", "--samples", bad, "--instance", "300", "-o", Path("cal.yaml")});
  EXPECT_EQ(instance.status, 2);
  EXPECT_NE(instance.err.find("\"300\" is not a ULog multi_id (0..255)"), std::string::npos) << instance.err;
  const std::string csv = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(csv, {})).status, 0);
  const RunResult on_csv =
      Run({"fit", "--field", "--samples", csv, "--instance", "1", "-o", Path("cal.yaml")});
  EXPECT_EQ(on_csv.status, 2);
  EXPECT_NE(on_csv.err.find("--instance chooses a PX4 ULog's sensors; this file is a CSV"), std::string::npos)
      << on_csv.err;
}

}  // namespace
}  // namespace imufit::testing
