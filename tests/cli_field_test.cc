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
  // A calibration by hand has no plan: report refuses one, saying why, and writes nothing.
  const std::string html = Path("report.html");
  const RunResult r = Run({"report", "-c", cal, "-p", Fixture("plan_6pos.yaml"), "-s", raw, "-o", html});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(
      r.err.find("a calibration by hand (body_frame: accelerometer_xy, imufit fit --field) has no plan"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(html));
}

// The text of a certificate's element with data-key="key" (tags stripped); "" when there is none.
std::string CertificateText(const std::string& html, const std::string& key) {
  const size_t at = html.find("data-key=\"" + key + "\"");
  if (at == std::string::npos) return "";
  const size_t from = html.find('>', at) + 1;
  std::string text;
  int depth = 0;
  for (size_t i = from; i < html.size(); ++i) {
    if (html.compare(i, 2, "</") == 0) {
      if (depth == 0) break;
      --depth;
      i = html.find('>', i);
    } else if (html[i] == '<') {
      ++depth;
      i = html.find('>', i);
    } else {
      text += html[i];
    }
  }
  for (const auto& [entity, character] :
       {std::pair{"&#39;", "'"}, {"&quot;", "\""}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
    for (size_t at = text.find(entity); at != std::string::npos; at = text.find(entity, at + 1))
      text.replace(at, std::string(entity).size(), character);
  }
  return text;
}

// The U printed in the certificate's coefficient table for figure `name` (the cell after its 1-sigma).
double PrintedExpanded(const std::string& html, const std::string& name) {
  size_t at = html.find("data-figure=\"" + name + "\"");
  if (at == std::string::npos) return -1.0;
  for (int cell = 0; cell < 2; ++cell) at = html.find("<td", at + 1);
  const size_t from = html.find('>', at) + 1;
  return std::stod(html.substr(from, html.find('<', from) - from));
}

// One column of the figures a results store recorded, by figure name, as "name=value;...".
std::string StoredFigures(const std::string& db, const std::string& column) {
  return RunProgram("/usr/bin/python3",
                    {"-c",
                     "import sqlite3, sys\n"
                     "rows = sqlite3.connect(sys.argv[1]).execute('SELECT name, ' + sys.argv[2] + "
                     "' FROM figures ORDER BY name').fetchall()\n"
                     "print(';'.join('%s=%r' % r for r in rows))\n",
                     db, column},
                    db + ".out", db + ".err")
      .out;
}

double StoredFigure(const std::string& db, const std::string& name, const std::string& column) {
  const std::string out =
      RunProgram("/usr/bin/python3",
                 {"-c",
                  "import sqlite3, sys\n"
                  "print(repr(sqlite3.connect(sys.argv[1]).execute('SELECT ' + sys.argv[3] + "
                  "' FROM figures WHERE name = ?', (sys.argv[2],)).fetchone()[0]))\n",
                  db, name, column},
                 db + ".out", db + ".err")
          .out;
  return std::stod(out);
}

// Issue 32 item 5: the certificate of a calibration by hand says that no reference table was used,
// states the session, and its U covers the session's noise and the gravity value's uncertainty (by
// where gravity came from), nothing of a station. The U printed is the one the store records, and
// the verdict is the same whether or not the page is written (fit --field --limits, with and without
// --report; imufit report of the calibration).
TEST_F(CliTest, FieldCalibrationCertificate) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--serial", "SN-HAND-1"})).status, 0);
  // Accelerometer bias x is about +17.03 mg with U about 0.1 mg: 17.1 lies within the guard band.
  const std::string limits = Path("limits.yaml");
  std::ofstream(limits)
      << "format: imufit-limits\nversion: 1\nname: hand limits\nnominal: {accel_scale: 210}\n"
         "decision_rule: guarded\nguard_band: 1\ncriteria:\n"
         "  - {quantity: gyro_bias_dps, max_abs: 5}\n"
         "  - {quantity: accel_bias_mg, axes: [x], max_abs: 17.1}\n"
         "  - {quantity: accel_scale_error_pct, max_abs: 5}\n";
  const auto fit = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {
        "fit",  "--field", "--samples",       raw, "-o", Path(name + ".yaml"), "--limits",
        limits, "--store", Path(name + ".db")};
    args.insert(args.end(), extra.begin(), extra.end());
    return Run(args);
  };
  const RunResult plain = fit("plain", {});
  const RunResult certified = fit("certified", {"--report", Path("certified.html")});
  EXPECT_EQ(plain.status, 3) << plain.out << plain.err;  // failed limits
  EXPECT_EQ(certified.status, plain.status) << certified.out << certified.err;
  const auto table = [](const std::string& out) {
    const size_t from = out.find("  acceptance");
    return from == std::string::npos ? std::string() : out.substr(from, out.find("  wrote", from) - from);
  };
  ASSERT_FALSE(table(plain.out).empty()) << plain.out;
  EXPECT_EQ(table(plain.out), table(certified.out));
  EXPECT_NE(table(plain.out).find("inside the guard band"), std::string::npos) << table(plain.out);
  for (const char* column : {"expanded_u", "outcome", "judgement"})
    EXPECT_EQ(StoredFigures(Path("plain.db"), column), StoredFigures(Path("certified.db"), column)) << column;

  // imufit report of the calibration: the same verdict, no plan.
  const std::string cal = Path("plain.yaml");
  const std::string page = Path("report.html");
  const RunResult report = Run({"report", "-c", cal, "-s", raw, "-l", limits, "-o", page});
  EXPECT_EQ(report.status, 3) << report.out << report.err;
  EXPECT_NE(report.out.find("(acceptance FAIL)"), std::string::npos) << report.out;
  std::ifstream in(page);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // What the certificate says of its references, the frame and the session.
  EXPECT_NE(CertificateText(html, "field_reference").find("without a reference table or a known rate"),
            std::string::npos);
  EXPECT_EQ(CertificateText(html, "body_frame"), "accelerometer_xy");
  EXPECT_EQ(CertificateText(html, "field_poses"), "12");
  EXPECT_EQ(CertificateText(html, "field_turns"), "11");
  EXPECT_EQ(CertificateText(html, "field_saturated_turns"), "0");
  EXPECT_NE(CertificateText(html, "field_gravity").find("standard gravity (no local gravity given)"),
            std::string::npos);
  EXPECT_NE(CertificateText(html, "temp_range_c").find("25.0 .. 25.0 degC"), std::string::npos);
  EXPECT_NE(CertificateText(html, "field_accel_norm_rms_mg").find(" mg"), std::string::npos);
  EXPECT_NE(CertificateText(html, "field_direction_rms_deg").find(" deg"), std::string::npos);
  EXPECT_EQ(CertificateText(html, "field_noise_scales"), "1, 1, 1");
  EXPECT_EQ(CertificateText(html, "verdict"), "FAIL");
  EXPECT_EQ(CertificateText(html, "unit_serial"), "SN-HAND-1");
  const std::string covers = CertificateText(html, "budget_covers");
  EXPECT_NE(covers.find("hand tremor"), std::string::npos) << covers;
  EXPECT_NE(covers.find("the uncertainty of the local gravity 9.80665"), std::string::npos) << covers;
  const std::string not_covered = CertificateText(html, "budget_not_covered");
  EXPECT_NE(not_covered.find("no table's or station's errors"), std::string::npos) << not_covered;
  EXPECT_NE(not_covered.find("drift after the session"), std::string::npos) << not_covered;
  EXPECT_NE(CertificateText(html, "noise_not_measured").find("imufit allan --noise-yaml"), std::string::npos);
  EXPECT_EQ(html.find("rate table"), std::string::npos);  // no table, not even a line to fill in

  // U: the fit's 2 sigma with, for standard gravity, the accelerometer scale's share of a gravity
  // anywhere on Earth (half width 0.03 m/s^2, rectangular), computed here from the sigma recorded.
  const Calibration calibration = ReadCalibration(cal);
  for (const char* axis : {"x", "y", "z"}) {
    const std::string name = std::string("accel_scale_per_g.") + axis;
    const double value = StoredFigure(Path("plain.db"), name, "value");
    const double sigma = StoredFigure(Path("plain.db"), name, "sigma");
    const double u_g = 0.03 / std::sqrt(3.0) / kGravityMps2;
    const double expected = 2.0 * std::hypot(sigma, value * (1.0 - 1.0 / (1.0 + u_g)));
    const double stored = StoredFigure(Path("plain.db"), name, "expanded_u");
    EXPECT_NEAR(stored, expected, 1e-9 * expected) << name;
    EXPECT_GT(stored, 10.0 * 2.0 * sigma) << name;  // gravity dominates: about 0.35 % of the scale
    // The page prints it to two significant digits.
    const double printed = PrintedExpanded(html, name);
    const double digit = std::pow(10.0, std::floor(std::log10(stored)) - 1.0);
    EXPECT_NEAR(printed, stored, 0.5 * digit + 1e-12) << name;
  }
  // A gyro figure has no share of gravity: U = 2 sigma.
  const double sigma = StoredFigure(Path("plain.db"), "gyro_bias_dps.x", "sigma");
  EXPECT_NEAR(StoredFigure(Path("plain.db"), "gyro_bias_dps.x", "expanded_u"), 2.0 * sigma, 1e-12 * sigma);

  // Gravity stated (--gravity-mps2): taken as exact, said so; the accelerometer scale's U is 2 sigma.
  // (a value of exactly 9.80665 is standard gravity, taken as unknown: the option's default.)
  ASSERT_EQ(fit("stated", {"--gravity-mps2", "9.8125", "--report", Path("stated.html")}).status, 3);
  const YAML::Node stated = YAML::LoadFile(Path("stated.yaml"));
  EXPECT_EQ(stated["fit"]["field"]["gravity_source"].as<std::string>(), "stated");
  const double stated_sigma = StoredFigure(Path("stated.db"), "accel_scale_per_g.x", "sigma");
  EXPECT_NEAR(StoredFigure(Path("stated.db"), "accel_scale_per_g.x", "expanded_u"), 2.0 * stated_sigma,
              1e-12 * stated_sigma);
  std::ifstream stated_in(Path("stated.html"));
  const std::string stated_html((std::istreambuf_iterator<char>(stated_in)),
                                std::istreambuf_iterator<char>());
  EXPECT_NE(CertificateText(stated_html, "budget_covers").find("taken as exact"), std::string::npos);
  // From the latitude: WGS-84 normal gravity, recorded with the site.
  ASSERT_EQ(fit("site", {"--latitude", "48.1", "--height-m", "520"}).status, 3);
  const YAML::Node site = YAML::LoadFile(Path("site.yaml"));
  EXPECT_EQ(site["fit"]["field"]["gravity_source"].as<std::string>(), "latitude");
  EXPECT_EQ(site["fit"]["field"]["latitude_deg"].as<double>(), 48.1);
  EXPECT_EQ(site["fit"]["field"]["height_m"].as<double>(), 520.0);
}

// The certificate by hand prints to PDF as a table run's does (headless Chromium): on at most
// kMostFieldCertificatePages of A4, every page naming it a certificate by hand, the reference statement
// in the text.
TEST_F(CliTest, FieldCertificatePrintsToPdf) {
  if (!std::filesystem::exists("/usr/bin/chromium") || !std::filesystem::exists("/usr/bin/pdftotext") ||
      !std::filesystem::exists("/usr/bin/pdfinfo")) {
    GTEST_SKIP() << "no chromium, pdftotext or pdfinfo (Debian: chromium poppler-utils)";
  }
  constexpr int kMostFieldCertificatePages = 3;
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {"--serial", "SN-HAND-3"})).status, 0);
  const std::string cal = Path("cal.yaml");
  ASSERT_EQ(Run({"fit", "--field", "--samples", raw, "-o", cal, "-q"}).status, 0);
  const RunResult r = Run({"report", "-c", cal, "-s", raw, "-o", Path("hand.html"), "--pdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + Path("hand.html") + " and " + Path("hand.pdf")), std::string::npos)
      << r.out;
  const RunResult info = RunProgram("/usr/bin/pdfinfo", {Path("hand.pdf")});
  ASSERT_EQ(info.status, 0) << info.err;
  const size_t at = info.out.find("Pages:");
  ASSERT_NE(at, std::string::npos) << info.out;
  const int pages = std::stoi(info.out.substr(at + 6));
  EXPECT_GE(pages, 1);
  EXPECT_LE(pages, kMostFieldCertificatePages);
  const RunResult text = RunProgram("/usr/bin/pdftotext", {Path("hand.pdf"), "-"});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("IMU calibration certificate (by hand) SN-HAND-3"), std::string::npos);
  EXPECT_NE(text.out.find("without a reference table or a known rate"), std::string::npos);
  EXPECT_NE(text.out.find("page " + std::to_string(pages) + " of " + std::to_string(pages)),
            std::string::npos);
}

// fit --field refuses what a certificate needs and the session does not give, before any work.
TEST_F(CliTest, FieldCertificateOptionsAreChecked) {
  const std::string raw = Path("session.csv");
  ASSERT_EQ(Run(FieldSessionArgs(raw, {})).status, 0);
  const std::string out = Path("cal.yaml");
  RunResult r = Run({"fit", "--field", "--samples", raw, "-o", out, "--pdf"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--pdf: prints the certificate: give --report too"), std::string::npos) << r.err;
  r = Run({"fit", "--field", "--samples", raw, "-o", out, "--report", raw});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  r = Run({"report", "-c", Fixture("golden/mems_6pos_soak.yaml"), "-s", raw, "-o", Path("r.html")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--plan is required"), std::string::npos) << r.err;
}

// ---------------------------------------------------------------- several sessions of one unit

// A session of the MEMS unit (`truth`, default fixtures/mems_truth.yaml) at `temp_c`: ten rests of
// about 3 s at 50 Hz, the unit's `serial`; `extra` adds.
std::vector<std::string> SessionAt(const std::string& out, int temp_c, int seed,
                                   const std::string& truth = "", const std::vector<std::string>& extra = {},
                                   const std::string& serial = "SN0001") {
  std::vector<std::string> args = {"simulate",
                                   "--field",
                                   "--calibration",
                                   truth.empty() ? Fixture("mems_truth.yaml") : truth,
                                   "-o",
                                   out,
                                   "--temps",
                                   std::to_string(temp_c),
                                   "--poses",
                                   "10",
                                   "--dwell",
                                   "3",
                                   "--rate",
                                   "50",
                                   "--gyro-noise-density",
                                   "2e-4",
                                   "--accel-noise-density",
                                   "1e-3",
                                   "--serial",
                                   serial,
                                   "--seed",
                                   std::to_string(seed),
                                   "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// Four sessions (0, 15, 30, 45 degC, each its own power-on) fitted jointly, biases quadratic and
// scale factors linear in temperature: each session's share printed and recorded in the file as
// PyYAML-like readers see it (yaml-cpp here; the schema and PyYAML in python/tests), every session's
// bias tested and consistent.
TEST_F(CliTest, FieldSessionsFittedJointly) {
  std::vector<std::string> sessions;
  for (const int temp_c : {0, 15, 30, 45}) {
    sessions.push_back(Path("s" + std::to_string(temp_c) + ".csv"));
    ASSERT_EQ(Run(SessionAt(sessions.back(), temp_c, 40 + temp_c)).status, 0);
  }
  const std::string calibration = Path("joint.yaml");
  std::vector<std::string> args = {"fit", "--field", "--bias-temp-order", "2", "--scale-temp-order",
                                   "1",   "-o",      calibration};
  for (const std::string& session : sessions) args.insert(args.end(), {"--samples", session});
  const RunResult fit = Run(args);
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("converged (4 sessions, 40 poses, 36 turns"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("sessions (4): what each contributed, and its biases' offset from the joint fit"),
            std::string::npos)
      << fit.out;
  EXPECT_NE(fit.out.find("s30.csv: "), std::string::npos) << fit.out;
  EXPECT_EQ(fit.out.find("beyond chance"), std::string::npos) << fit.out;
  EXPECT_EQ(fit.err.find("cannot be tested"), std::string::npos) << fit.err;
  const YAML::Node record = YAML::LoadFile(calibration)["fit"];
  EXPECT_FALSE(record["samples"]);  // names one file: the sessions are listed under field
  EXPECT_FALSE(record["samples_sha256"]);
  const YAML::Node field = record["field"];
  ASSERT_EQ(field["session_samples"].size(), 4u);
  long long samples = 0;
  for (size_t s = 0; s < 4; ++s) {
    EXPECT_EQ(field["session_samples"][s].as<std::string>(), sessions[s]);
    EXPECT_EQ(field["session_samples_sha256"][s].as<std::string>().size(), 64u);
    EXPECT_EQ(field["session_poses"][s].as<int>(), 10);
    EXPECT_EQ(field["session_turns"][s].as<int>(), 9);
    EXPECT_NEAR(field["session_temp_min_c"][s].as<double>(), 15.0 * s, 0.5);
    EXPECT_LT(field["session_gyro_bias_chi2"][s].as<double>(), 21.11);
    samples += field["session_samples_read"][s].as<long long>();
  }
  EXPECT_EQ(samples, record["samples_read"].as<long long>());
  EXPECT_EQ(field["poses"].as<int>(), 40);
  EXPECT_TRUE(field["session_biases_tested"].as<bool>());
  EXPECT_EQ(YAML::LoadFile(calibration)["serial"].as<std::string>(), "SN0001");
  // The calibration is an ordinary one: apply corrects a session with it.
  EXPECT_EQ(Run({"apply", "-q", "--calibration", calibration, "--samples", sessions[1], "-o",
                 Path("corrected.csv")})
                .status,
            0);

  // Three of them with a quadratic: the curve passes through every session's bias, nothing can
  // be tested, and the user is told so; the file says so too.
  const RunResult three = Run({"fit", "--field", "--bias-temp-order", "2", "--samples", sessions[0],
                               "--samples", sessions[2], "--samples", sessions[3], "-o", Path("three.yaml")});
  ASSERT_EQ(three.status, 0) << three.err;
  EXPECT_NE(three.err.find("warning: the sessions' biases cannot be tested against each other"),
            std::string::npos)
      << three.err;
  const YAML::Node untested = YAML::LoadFile(Path("three.yaml"))["fit"]["field"];
  EXPECT_FALSE(untested["session_biases_tested"].as<bool>());
  EXPECT_FALSE(untested["session_gyro_bias_chi2"]);
}

// Three sessions at 25 degC, one recorded after a power-on that moved the gyro bias by 0.05 deg/s
// (a MEMS unit's turn-on repeatability): refused, exit 1, nothing written; the session with the
// offset named first (the other two are off the mean it pulls, by half as much).
TEST_F(CliTest, FieldSessionsWithATurnOnOffsetAreRefused) {
  YAML::Node truth = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* axis : {"x", "y", "z"}) {
    const double scale = truth["gyro"]["scale"][axis][0].as<double>();
    truth["gyro"]["bias"][axis][0] = truth["gyro"]["bias"][axis][0].as<double>() + 0.05 * kDegToRad * scale;
  }
  const std::string turned_on = Path("turned_on.yaml");
  std::ofstream(turned_on) << truth;
  std::vector<std::string> args = {"fit", "--field", "-o", Path("joint.yaml")};
  for (const int s : {1, 2, 3}) {
    const std::string session = Path("s" + std::to_string(s) + ".csv");
    ASSERT_EQ(Run(SessionAt(session, 25, 60 + s, s == 2 ? turned_on : "")).status, 0);
    args.insert(args.end(), {"--samples", session});
  }
  const RunResult fit = Run(args);
  EXPECT_EQ(fit.status, 1) << fit.err;
  EXPECT_NE(fit.err.find("disagree (3 sessions, 30 poses, 27 turns): " + Path("s2.csv") + ": its gyro bias"),
            std::string::npos)
      << fit.err;
  EXPECT_NE(fit.err.find("turn-on repeatability"), std::string::npos) << fit.err;
  EXPECT_NE(fit.err.find("(beyond chance)"), std::string::npos) << fit.err;
  EXPECT_FALSE(std::filesystem::exists(Path("joint.yaml")));
}

// Each session's temperature for logs without one; what cannot be done with several sessions.
TEST_F(CliTest, FieldSessionsTemperaturesSerialsAndRefusals) {
  const std::string cold = Path("cold.csv");
  const std::string warm = Path("warm.csv");
  const std::string hot = Path("hot.csv");
  ASSERT_EQ(Run(SessionAt(cold, 10, 81, "", {"--no-temp-column"})).status, 0);
  ASSERT_EQ(Run(SessionAt(warm, 25, 82, "", {"--no-temp-column"})).status, 0);
  ASSERT_EQ(Run(SessionAt(hot, 40, 83, "", {"--no-temp-column"})).status, 0);
  const std::vector<std::string> three = {"fit", "--field",   "--samples", cold, "--samples",
                                          warm,  "--samples", hot,         "-o", Path("cal.yaml")};
  const auto with = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = three;
    args.insert(args.end(), extra.begin(), extra.end());
    return Run(args);
  };
  const RunResult fit = with({"--session-temp-c", "10,25,40", "--bias-temp-order", "2"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("sessions: "), std::string::npos);
  EXPECT_NE(fit.out.find("10.0 .. 40.0 degC"), std::string::npos) << fit.out;
  const YAML::Node field = YAML::LoadFile(Path("cal.yaml"))["fit"]["field"];
  EXPECT_EQ(field["session_temp_min_c"][2].as<double>(), 40.0);
  // Given once per session, as a list: the same.
  EXPECT_EQ(with({"--session-temp-c", "10", "--session-temp-c", "25", "--session-temp-c", "40",
                  "--bias-temp-order", "2", "-q"})
                .status,
            0);

  for (const auto& [extra, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--session-temp-c", "10,25"}, "gives 2 temperatures for 3 sessions"},
           {{"--session-temp-c", "10,25,40", "--temp-c", "20"}, "and --temp-c both given"},
           {{"--session-temp-c", "10,25,400"}, "is not a plausible temperature"},
           {{"--temp-c", "25", "--repeat", cold}, "--repeat: compares one session with another"},
       }) {
    const RunResult refused = with(extra);
    EXPECT_EQ(refused.status, 2) << message;
    EXPECT_NE(refused.err.find(message), std::string::npos) << refused.err;
  }
  // A table fit takes one run.
  const RunResult table = Run({"fit", "--plan", Fixture("mems_truth.yaml"), "--samples", cold, "--samples",
                               warm, "-o", Path("table.yaml")});
  EXPECT_EQ(table.status, 2);
  EXPECT_NE(table.err.find("--samples: given 2 times: a table fit takes one run"), std::string::npos)
      << table.err;
  // Sessions of two units.
  const std::string other = Path("other.csv");
  ASSERT_EQ(Run(SessionAt(other, 40, 84, "", {"--no-temp-column"}, "SN0002")).status, 0);
  const RunResult units = Run(
      {"fit", "--field", "--temp-c", "25", "--samples", cold, "--samples", other, "-o", Path("units.yaml")});
  EXPECT_EQ(units.status, 2);
  EXPECT_NE(units.err.find("the sessions of a joint fit are of one unit"), std::string::npos) << units.err;
  EXPECT_FALSE(std::filesystem::exists(Path("units.yaml")));
  // A session that holds no rest, by name.
  const std::string moving = Path("moving.csv");
  {
    std::ifstream in(cold);
    std::ofstream out(moving);
    std::string line;
    for (int i = 0; i < 30 && std::getline(in, line); ++i) out << line << "\n";  // 0.5 s
  }
  const RunResult no_rest = Run({"fit", "--field", "--temp-c", "25", "--samples", cold, "--samples", moving,
                                 "-o", Path("moving.yaml")});
  EXPECT_EQ(no_rest.status, 1);
  EXPECT_NE(no_rest.err.find(moving + ": no pose at rest found"), std::string::npos) << no_rest.err;
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
