// End-to-end tests of `imufit fit`: a calibration that corrects another run, runs refused for
// what they cannot determine (naming it), a subset fitted on purpose, bad input, a held-out run,
// and hand-rotated sessions (turns through a known angle) with lost samples and a sign flipped.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

TEST_F(CliTest, FitWritesACalibrationThatCorrectsAnotherRun) {
  const std::string calibration = Path("calibration.yaml");
  const RunResult fit = Run({"fit", "--plan", Fixture("plan_6pos.yaml"), "--samples",
                             Fixture("mems_6pos_soak.csv.gz"), "-o", calibration, "--validate"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("converged"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("at 25 degC (+- 1 sigma)"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("leave-one-temperature-out validation"), std::string::npos) << fit.out;
  const YAML::Node written = YAML::LoadFile(calibration);
  EXPECT_EQ(written["format"].as<std::string>(), "imufit-calibration");
  EXPECT_EQ(written["sigma"]["gyro"]["g_sensitivity"]["zz"].size(), 4u);
  EXPECT_EQ(written["fit"]["windows_used"].as<int>(), 90);
  EXPECT_EQ(written["fit"]["distinct_temperatures_c"].size(), 5u);

  // The fitted calibration corrects the noiseless run (same unit, other temperatures) to within
  // what the noise of the fitted run leaves: a few thousandths of a deg/s, a few tenths of a mg.
  constexpr double kGyroToleranceRadps = 0.02 * kDegToRad;
  constexpr double kAccelToleranceMps2 = 1e-3 * 9.80665;
  const std::string corrected = Path("corrected.csv");
  const RunResult apply =
      Run({"apply", "-c", calibration, "-s", Fixture("mems_6pos_noiseless.csv.gz"), "-o", corrected, "-q"});
  ASSERT_EQ(apply.status, 0) << apply.err;
  const Table got = ReadTable(corrected);
  const Table truth = ReadTable(Fixture("mems_6pos_noiseless_truth.csv.gz"));
  ASSERT_EQ(got.rows.size(), truth.rows.size());
  double worst_gyro = 0.0;
  double worst_accel = 0.0;
  for (size_t r = 0; r < got.rows.size(); ++r) {
    for (const char* axis : {"x", "y", "z"}) {
      const int g = got.Column(std::string("gyro_") + axis);
      const int a = got.Column(std::string("accel_") + axis);
      worst_gyro = std::max(worst_gyro, std::abs(std::stod(got.rows[r][g]) - std::stod(truth.rows[r][g])));
      worst_accel = std::max(worst_accel, std::abs(std::stod(got.rows[r][a]) - std::stod(truth.rows[r][a])));
    }
  }
  EXPECT_LT(worst_gyro, kGyroToleranceRadps);
  EXPECT_LT(worst_accel, kAccelToleranceMps2);
}

// A hot-only run never reached 25 degC: the summary's 25 degC figures say they are extrapolated;
// a run through 25 degC says nothing of the kind.
TEST_F(CliTest, FitSummaryMarksFiguresOutsideTheFittedRangeAsExtrapolated) {
  const std::string hot = Path("hot.csv");
  std::vector<std::string> hot_run = SmallRunArgs(hot, {"--seed=7"});
  *std::find(hot_run.begin(), hot_run.end(), "--temps=-20,5,30,60") = "--temps=40,55,70,85";
  ASSERT_EQ(Run(hot_run).status, 0);
  RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", hot, "-o", Path("hot.yaml")});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("  at 25 degC (+- 1 sigma) (extrapolated: fitted 40..85 degC):\n"),
            std::string::npos)
      << fit.out;
  const std::string through = Path("through.csv");
  ASSERT_EQ(Run(SmallRunArgs(through, {"--seed=7"})).status, 0);
  fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", through, "-o", Path("through.yaml")});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("  at 25 degC (+- 1 sigma):\n"), std::string::npos) << fit.out;
  EXPECT_EQ(fit.out.find("extrapolated"), std::string::npos) << fit.out;
}

TEST_F(CliTest, FitRefusesARunThatCannotDetermineTheModel) {
  const std::string samples = Path("one_temperature.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", samples,
                 "--temps", "25", "--rate", "10", "--dwell", "3", "-q"})
                .status,
            0);
  const std::string output = Write("calibration.yaml", "precious\n");
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", output});
  EXPECT_EQ(fit.status, 1);
  EXPECT_NE(fit.err.find("does not determine the model"), std::string::npos) << fit.err;
  EXPECT_EQ(std::count(fit.err.begin(), fit.err.end(), '\n'), 1) << "one line: " << fit.err;
  EXPECT_NE(
      fit.err.find("too few temperatures for a cubic temperature model: 1 distinct temperature (25.0 degC), "
                   "at least 4 needed"),
      std::string::npos)
      << fit.err;
  EXPECT_EQ(ReadBytes(output), "precious\n");
  EXPECT_EQ(Listing(), (std::set<std::string>{"one_temperature.csv", "calibration.yaml"}));
  // The same run determines a constant model.
  const RunResult constant =
      Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", Path("constant.yaml"),
           "--gyro-temp-order", "0", "--accel-temp-order", "0", "-q"});
  EXPECT_EQ(constant.status, 0) << constant.err;
}

// A static-only run: refused as a whole (naming the gyro scale, suggesting --fit accel), fitted
// with --fit accel: the accelerometer near the truth, the gyro held at scale 1 and 0 with sigma 0.
TEST_F(CliTest, FitAccelAloneCalibratesAStaticOnlyRun) {
  const std::string plan = Fixture("plan_6faces_static.yaml");
  const std::string samples = SimulateNoiseless(plan, Fixture("mems_truth.yaml"), "static",
                                                {"--temps=-20,5,30,55,80", "--dwell", "3"})
                                  .first;
  const RunResult whole = Run({"fit", "-p", plan, "-s", samples, "-o", Path("whole.yaml")});
  EXPECT_EQ(whole.status, 1);
  EXPECT_NE(whole.err.find("gyro scale z and misalignment xz, yz are undetermined"), std::string::npos)
      << whole.err;
  EXPECT_NE(whole.err.find("--fit accel"), std::string::npos) << whole.err;
  EXPECT_FALSE(fs::exists(Path("whole.yaml")));

  const RunResult fit = Run({"fit", "-p", plan, "-s", samples, "-o", Path("accel.yaml"), "--fit", "accel"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("gyro x   bias +0.00000 (held) deg/s"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("(gyro held, not fitted)"), std::string::npos) << fit.out;
  const YAML::Node got = YAML::LoadFile(Path("accel.yaml"));
  const YAML::Node truth = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* group : {"bias", "scale", "misalignment"}) {
    for (const auto& entry : truth["accel"][group]) {
      const std::string name = entry.first.as<std::string>();
      for (int k = 0; k < 4; ++k) {
        const double want = entry.second[k].as<double>();
        EXPECT_NEAR(got["accel"][group][name][k].as<double>(), want, 1e-6 * std::max(1.0, std::abs(want)))
            << "accel." << group << "." << name << "[" << k << "]";
      }
      EXPECT_EQ(got["sigma"]["accel"][group][name].size(), 4u);
    }
    for (const auto& entry : got["gyro"][group]) {
      const bool unit_scale = std::string(group) == "scale";
      EXPECT_EQ(entry.second[0].as<double>(), unit_scale ? 1.0 : 0.0) << "gyro." << group;
      EXPECT_EQ(got["sigma"]["gyro"][group][entry.first.as<std::string>()][0].as<double>(), 0.0);
    }
  }
  EXPECT_EQ(got["fit"]["fitted"].as<std::vector<std::string>>(),
            (std::vector<std::string>{"accel.bias", "accel.scale", "accel.misalignment"}));
  EXPECT_EQ(got["fit"]["held"].size(), 4u);
  EXPECT_EQ(got["fit"]["held_values"].as<std::string>(), "scale 1, others 0");
  const RunResult bad =
      Run({"fit", "-p", plan, "-s", samples, "-o", Path("bad.yaml"), "--fit", "accelerometer"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("is not a group to fit"), std::string::npos) << bad.err;
}

TEST_F(CliTest, FitNamesAnAxisGravityNeverPointsAlong) {
  // The 6-position plan without its -y face: g-sensitivity and accelerometer column y are lost.
  std::string plan = ReadFile(Fixture("plan_6pos.yaml"));
  YAML::Node root = YAML::Load(plan);
  YAML::Node kept(YAML::NodeType::Sequence);
  for (const YAML::Node& segment : root["segments"]) {
    if (segment["up"][1].as<double>() < -0.5) continue;
    kept.push_back(segment);
  }
  root["segments"] = kept;
  YAML::Emitter emitter;
  emitter << root;
  const std::string plan_path = Write("plan.yaml", emitter.c_str());
  const std::string samples = Path("run.csv");
  ASSERT_EQ(Run({"simulate", "-p", plan_path, "-c", Fixture("mems_truth.yaml"), "-o", samples,
                 "--temps=-40,0,40,85", "--rate", "10", "--dwell", "3", "-q"})
                .status,
            0);
  const RunResult fit = Run({"fit", "-p", plan_path, "-s", samples, "-o", Path("calibration.yaml")});
  EXPECT_EQ(fit.status, 1);
  EXPECT_NE(
      fit.err.find(
          "gyro g_sensitivity column y (xy, yy, zy) is undetermined: no positions with gravity along -y"),
      std::string::npos)
      << fit.err;
  EXPECT_NE(fit.err.find("accel scale y and misalignment xy, zy are undetermined"), std::string::npos)
      << fit.err;
  EXPECT_FALSE(fs::exists(Path("calibration.yaml")));
}

TEST_F(CliTest, FitRefusesBadInputWithExitTwo) {
  // A segment id the plan does not have: located at its line and field.
  const std::string samples = Write("samples.csv",
                                    "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                    "0,25,99,1,2,3,4,5,6\n");
  RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", Path("c.yaml")});
  EXPECT_EQ(fit.status, 2);
  EXPECT_NE(fit.err.find("samples.csv:2:3: segment: segment 99 is not in the plan"), std::string::npos)
      << fit.err;
  fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o",
             Path("c.yaml"), "--loss", "tukey"});
  EXPECT_EQ(fit.status, 2);
  EXPECT_NE(fit.err.find("\"tukey\" is not a robust loss (none, huber, cauchy)"), std::string::npos)
      << fit.err;
  fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o",
             Path("c.yaml"), "--gyro-temp-order", "4"});
  EXPECT_EQ(fit.status, 2);
  EXPECT_FALSE(fs::exists(Path("c.yaml")));
}

TEST_F(CliTest, FitReportsErrorsOnAHeldOutRun) {
  const RunResult fit =
      Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o",
           Path("calibration.yaml"), "--check-samples", Fixture("mems_6pos_ramp.csv.gz")});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("held-out run"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("    all      216"), std::string::npos) << fit.out;
  const YAML::Node written = YAML::LoadFile(Path("calibration.yaml"));
  EXPECT_LT(written["check"]["gyro_error_rms_radps"].as<double>(), 0.02 * kDegToRad);
}

// A hand-rotated session (six faces and a 360 deg turn about each axis, raw counts, no labels)
// whose serial link lost samples keeps its gyro scale (set by the three turns alone) within its
// stated sigma and says what was lost; a gap longer than --max-turn-gap drops its turn.
TEST_F(CliTest, HandSessionWithLostSamplesKeepsItsGyroScaleAndSaysWhatWasLost) {
  // A serial link that loses 1 % of the frames, three in a row: the turns are integrated across
  // the gaps (before, each lost sample took its share of the angle: 0.3 % of scale, 65 sigma).
  constexpr double kTruthSigmas = 3.5;
  const std::string plan = Fixture("plan_hand_6faces_3turns.yaml");
  const std::string raw = Path("lossy.csv");
  ASSERT_EQ(Run(HandSessionArgs(raw, {"--drop-probability=0.0033", "--drop-burst=3"})).status, 0);
  const std::string calibration = Path("lossy_cal.yaml");
  const RunResult fit = Run({"fit", "--plan", plan, "--samples", raw, "--gyro-temp-order", "0",
                             "--accel-temp-order", "0", "-o", calibration});
  ASSERT_EQ(fit.status, 0) << fit.err;
  // 33 losses of 3 were simulated; the one among the first 256 stamps (while the time grid is
  // acquired) goes uncounted.
  EXPECT_NE(fit.out.find(
                "time stamps: 96 samples lost in 32 gaps (longest 0.03 s): turns are integrated across them"),
            std::string::npos)
      << fit.out;
  const YAML::Node got = YAML::LoadFile(calibration);
  const YAML::Node want = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* axis : {"x", "y", "z"}) {
    const double estimate = got["gyro"]["scale"][axis][0].as<double>();
    const double sigma = got["sigma"]["gyro"]["scale"][axis][0].as<double>();
    const double true_value = want["gyro"]["scale"][axis][0].as<double>();
    EXPECT_LE(std::abs(estimate - true_value), kTruthSigmas * sigma)
        << axis << ": " << estimate << " vs " << true_value << " +- " << sigma;
  }
  // A gap longer than --max-turn-gap drops its turn; without the turns nothing sets the gyro scale.
  const RunResult strict =
      Run({"fit", "--plan", plan, "--samples", raw, "--gyro-temp-order", "0", "--accel-temp-order", "0",
           "--max-turn-gap", "0.015", "-o", Path("strict.yaml")});
  EXPECT_EQ(strict.status, 1) << strict.err;
  EXPECT_NE(strict.err.find("turns dropped for a gap longer than 0.015 s"), std::string::npos) << strict.err;
  EXPECT_NE(strict.err.find("gyro scale"), std::string::npos) << strict.err;
  EXPECT_FALSE(std::filesystem::exists(Path("strict.yaml")));
}

// A hand-rotated cube (six faces, one 360 degree turn about each axis, raw counts, one
// temperature) calibrates end to end with the gyro scale within its stated sigma, and the same
// run against a plan with one turn's sign flipped is refused, naming the convention to check.
TEST_F(CliTest, HandRotatedCubeCalibratesAndASignFlipIsRefused) {
  std::string plan_text =
      "format: imufit-plan\nversion: 1\ngravity_mps2: 9.80665\nsegments:\n"
      "  - {id: 1, up: [0, 0, 1]}\n  - {id: 2, up: [0, 0, -1]}\n  - {id: 3, up: [1, 0, 0]}\n"
      "  - {id: 4, up: [-1, 0, 0]}\n  - {id: 5, up: [0, 1, 0]}\n  - {id: 6, up: [0, -1, 0]}\n"
      "  - {id: 7, up: [0, 0, 1], angle_deg: 360, axis: [1, 0, 0]}\n"
      "  - {id: 8, up: [0, 0, 1], angle_deg: 360, axis: [0, 1, 0]}\n"
      "  - {id: 9, up: [0, 0, 1], angle_deg: 360}\n";
  const std::string plan = Write("cube.yaml", plan_text);
  RunResult r = Run({"simulate", "-p", plan, "-c", Fixture("mems_truth.yaml"), "-o", Path("cube.csv"),
                     "--gyro-noise-density", "1e-4", "--accel-noise-density", "5e-4", "--quantize", "--seed",
                     "3", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"fit", "-p", plan, "-s", Path("cube.csv"), "-o", Path("cal.yaml"), "--gyro-temp-order", "0",
           "--accel-temp-order", "0"});
  ASSERT_EQ(r.status, 0) << r.err;
  const YAML::Node fitted = YAML::LoadFile(Path("cal.yaml"));
  const YAML::Node truth = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* axis : {"x", "y", "z"}) {
    const double estimate = fitted["gyro"]["scale"][axis][0].as<double>();
    const double sigma = fitted["sigma"]["gyro"]["scale"][axis][0].as<double>();
    EXPECT_LT(std::abs(estimate - truth["gyro"]["scale"][axis][0].as<double>()), 3.0 * sigma) << axis;
  }
  // The printed sigmas are magnitudes.
  EXPECT_EQ(r.out.find("+- -"), std::string::npos) << r.out;

  plan_text.replace(plan_text.find("angle_deg: 360, axis: [1, 0, 0]"), 14, "angle_deg: -360");
  r = Run({"fit", "-p", Write("flipped.yaml", plan_text), "-s", Path("cube.csv"), "-o",
           Path("flipped_cal.yaml"), "--gyro-temp-order", "0", "--accel-temp-order", "0"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("gyro_x reads with its sign inverted against the plan"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("right-hand rule"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("flipped_cal.yaml")));

  // apply refuses a calibration with a negative scale as bad input.
  YAML::Node negative = YAML::LoadFile(Path("cal.yaml"));
  negative["gyro"]["scale"]["y"][0] = -negative["gyro"]["scale"]["y"][0].as<double>();
  YAML::Emitter emitter;
  emitter << negative;
  r = Run({"apply", "-c", Write("negative.yaml", emitter.c_str()), "-s", Path("cube.csv"), "-o",
           Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("gyro.scale.y: the scale factor is negative"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
}

// A labelled log against a plan with a mistake in it (two faces' ids exchanged, a rate typed 200 for
// 300, a rate's sign lost) is refused before the fit, on one line naming the segments, the
// temperatures, what was measured and the likely cause, and nothing is written; the same run fits
// against the right plan with the same options.
TEST_F(CliTest, FitRefusesALabelledLogThatContradictsThePlan) {
  ASSERT_EQ(Run(SmallRunArgs(Path("run.csv"), {})).status, 0);
  const std::string plan = ReadFile(Fixture("plan_6pos.yaml"));
  const auto edited = [&](const std::vector<std::pair<std::string, std::string>>& edits) {
    std::string text = plan;
    for (const auto& [from, to] : edits) {
      const size_t at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      text.replace(at, from.size(), to);
    }
    return text;
  };
  const std::map<std::string, std::string> plans = {
      {"swapped",
       edited({{"{id: 1, up", "{id: X, up"}, {"{id: 3, up", "{id: 1, up"}, {"{id: X, up", "{id: 3, up"}})},
      {"typo", edited({{"{id: 9, up: [0, 0, 1], rate_dps: 300", "{id: 9, up: [0, 0, 1], rate_dps: 200"}})},
      {"sign",
       edited({{"{id: 14, up: [1, 0, 0], rate_dps: -300", "{id: 14, up: [1, 0, 0], rate_dps: 300"}})}};
  const std::map<std::string, std::vector<std::string>> expected = {
      {"swapped",
       {"run.csv: the labelled log does not match the plan",
        "segment 1 (up (+1, +0, +0)) measures gravity along "
        "(-0.00, -0.00, +1.00), 90 deg from its up at every temperature (-20, 5, 30, 60 degC)",
        "segment 3 (up (+0, +0, +1)) measures gravity along (+1.00",
        "ids exchanged between segments 1 and 3"}},
      {"typo",
       {"segment 9 (rate +200 deg/s about (+0, +0, +1)) measures 300 deg/s about (+0.00, +0.00, +1.00)",
        "at every temperature (-20, 5, 30, 60 degC): a typo in the rate?"}},
      {"sign",
       {"segment 14 (rate +300 deg/s about (+1, +0, +0)) measures 300 deg/s", "(-300 deg/s about its axis)",
        "a lost sign?"}}};
  for (const auto& [name, text] : plans) {
    const RunResult r = Run(
        {"fit", "-p", Write(name + ".yaml", text), "-s", Path("run.csv"), "-o", Path(name + "_cal.yaml")});
    EXPECT_EQ(r.status, 1) << name << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const std::string& part : expected.at(name))
      EXPECT_NE(r.err.find(part), std::string::npos) << part << "\n" << r.err;
    EXPECT_FALSE(fs::exists(Path(name + "_cal.yaml"))) << name;
    // docs/troubleshooting.md quotes the message as printed (the folder left out).
    std::string said = r.err.substr(0, r.err.size() - 1);
    const std::string folder = Path("x").substr(0, Path("x").size() - 1);
    for (size_t at = said.find(folder); at != std::string::npos; at = said.find(folder))
      said.erase(at, folder.size());
    EXPECT_NE(ReadFile(Fixture("../docs/troubleshooting.md")).find("`" + said + "`"), std::string::npos)
        << said;
  }
  const RunResult good =
      Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Path("run.csv"), "-o", Path("cal.yaml"), "-q"});
  EXPECT_EQ(good.status, 0) << good.err;
  EXPECT_TRUE(fs::exists(Path("cal.yaml")));
}

// A copy of the CSV `from` with the raw column `column` set to `value` in every row.
std::string WithConstantColumn(const std::string& from, const std::string& column, const std::string& value) {
  std::stringstream lines(ReadFile(from));
  std::string line;
  std::string text;
  int index = -1;
  while (std::getline(lines, line)) {
    if (!line.empty() && line[0] != '#') {
      std::vector<std::string> fields;
      std::stringstream row(line);
      for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
      if (index < 0) {
        index = static_cast<int>(std::find(fields.begin(), fields.end(), column) - fields.begin());
      } else {
        fields[index] = value;
      }
      line.clear();
      for (const std::string& field : fields) line += (line.empty() ? "" : ",") + field;
    }
    text += line + "\n";
  }
  return text;
}

// A gyro axis that reads 0 in every row and an accelerometer axis at its rail are named with the
// evidence, on one line, before the fit (no solver log), and nothing is written.
TEST_F(CliTest, FitNamesADeadOrRailedChannel) {
  ASSERT_EQ(Run(SmallRunArgs(Path("run.csv"), {})).status, 0);
  const std::map<std::string, std::string> expected = {
      {"dead",
       "dead.csv: gyro_y does not respond: raw spread 0 between the +-300 deg/s about y (segments 17, 18), "
       "raw mean 0: dead or disconnected?; nothing written"},
      {"rail",
       "rail.csv: accel_z reads 32767 in every sample: at its rail (saturated, or a fault holds it "
       "there)?; nothing written"}};
  Write("dead.csv", WithConstantColumn(Path("run.csv"), "gyro_y", "0"));
  Write("rail.csv", WithConstantColumn(Path("run.csv"), "accel_z", "32767"));
  for (const auto& [name, message] : expected) {
    const RunResult r =
        Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Path(name + ".csv"), "-o", Path(name + ".yaml")});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err, "imufit: " + Path(message) + "\n");
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(Path(name + ".yaml")));
  }
}

// A rate typed 303 for 300 is within what the label check allows (a scale error), but the fit that
// follows down-weights that segment at every temperature: refused; with
// --write-inconsistent written, and marked in the file, on the summary line, in a warning and on the
// certificate.
TEST_F(CliTest, FitRefusesAnInconsistentFitUnlessAskedToWriteIt) {
  ASSERT_EQ(Run(SmallRunArgs(Path("run.csv"), {})).status, 0);
  std::string plan = ReadFile(Fixture("plan_6pos.yaml"));
  const std::string from = "{id: 17, up: [0, 1, 0], rate_dps: 300";
  plan.replace(plan.find(from), from.size(), "{id: 17, up: [0, 1, 0], rate_dps: 303");
  const std::string plan_path = Write("plan.yaml", plan);
  RunResult r = Run({"fit", "-p", plan_path, "-s", Path("run.csv"), "-o", Path("cal.yaml")});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("the fit is inconsistent with the run's noise: segment 17 down-weighted at every "
                       "temperature (-20, 5, 30, 60 degC)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("(--write-inconsistent writes it anyway, marked); nothing written"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));

  r = Run({"fit", "-p", plan_path, "-s", Path("run.csv"), "-o", Path("cal.yaml"), "--write-inconsistent",
           "--report", Path("cert.html")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("INCONSISTENT (written with --write-inconsistent)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("imufit: warning: the fit is inconsistent with the run's noise: segment 17"),
            std::string::npos)
      << r.err;
  const YAML::Node written = YAML::LoadFile(Path("cal.yaml"));
  EXPECT_NE(written["fit"]["inconsistent"].as<std::string>().find("segment 17 down-weighted"),
            std::string::npos);
  EXPECT_NE(ReadFile(Path("cert.html")).find("written with --write-inconsistent"), std::string::npos);
}

}  // namespace
}  // namespace imufit::testing
