// End-to-end tests of logs without labels or a thermometer: `imufit segment` finds the plan's
// segments in the data as the simulator's truth has them, a log that disagrees with its plan is
// refused (exit 1), `--temp-c` stands in for the thermometer in segment, fit and apply, and a hand
// session calibrates end to end through the README's commands.
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

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// The arguments of `imufit simulate` for a soak of the MEMS unit over the 6-position plan written
// without its segment column (50 Hz, 5 s dwells, 1 s transitions, white noise, raw counts) into
// `out`; `extra` adds options.
std::vector<std::string> UnlabelledSoakArgs(const std::string& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"simulate",
                                   "-p",
                                   Fixture("plan_6pos.yaml"),
                                   "-c",
                                   Fixture("mems_truth.yaml"),
                                   "-o",
                                   out,
                                   "--rate=50",
                                   "--dwell=5",
                                   "--transition=1",
                                   "--gyro-noise-density=8.7e-5",
                                   "--accel-noise-density=1.5e-3",
                                   "--quantize",
                                   "--no-segment-column",
                                   "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// `imufit segment` labels a simulated log written without its segment column (jittered times) as the
// simulator's truth does: most samples of every dwell get their segment, none a wrong one.
TEST_F(CliTest, SegmentLabelsAnUnlabelledLogAsTheTruthDoes) {
  const std::string raw = Path("raw.csv");
  const std::string truth = Path("truth.csv");
  ASSERT_EQ(
      Run(UnlabelledSoakArgs(raw, {"--truth", truth, "--temps=-20,60", "--time-jitter-s", "0.005"})).status,
      0);
  EXPECT_EQ(ReadTable(raw).header, (std::vector<std::string>{"time_s", "temp_c", "gyro_x", "gyro_y", "gyro_z",
                                                             "accel_x", "accel_y", "accel_z"}));
  const std::string labelled = Path("labelled.csv");
  const RunResult r = Run({"segment", "--plan", Fixture("plan_6pos.yaml"), "--samples", raw, "-o", labelled});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("36 segments found in 2 passes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segment  pass  kind"), std::string::npos) << r.out;
  const Table got = ReadTable(labelled);
  const Table want = ReadTable(truth);
  ASSERT_EQ(got.rows.size(), want.rows.size());
  long long truly_labelled = 0;
  long long correct = 0;
  long long wrong = 0;
  for (size_t i = 0; i < got.rows.size(); ++i) {
    ASSERT_EQ(got.rows[i][got.Column("time_s")], want.rows[i][want.Column("time_s")]);
    const int label = std::stoi(got.rows[i][got.Column("segment")]);
    const int true_label = std::stoi(want.rows[i][want.Column("segment")]);
    truly_labelled += true_label >= 0;
    correct += label >= 0 && label == true_label;
    wrong += label >= 0 && label != true_label;
  }
  EXPECT_GE(static_cast<double>(correct) / truly_labelled, 0.7);
  EXPECT_EQ(wrong, 0);
  // The labelled log fits like any labelled run.
  const RunResult fit =
      Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", labelled, "-o", Path("cal.yaml"),
           "--gyro-temp-order", "1", "--accel-temp-order", "1", "--no-g-sensitivity", "-q"});
  EXPECT_EQ(fit.status, 0) << fit.err;
}

TEST_F(CliTest, SegmentRefusesALogThatDisagreesWithThePlanWithExitOne) {
  const std::string raw = Path("raw.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", raw,
                 "--rate", "50", "--dwell", "5", "--transition", "1", "--no-segment-column", "-q"})
                .status,
            0);
  // The plan without its +x face (12 .. 17 s in the log): an extra rest in the log.
  YAML::Node root = YAML::Load(ReadFile(Fixture("plan_6pos.yaml")));
  YAML::Node kept(YAML::NodeType::Sequence);
  for (const YAML::Node& segment : root["segments"]) {
    if (segment["id"].as<int>() != 3) kept.push_back(segment);
  }
  root["segments"] = kept;
  YAML::Emitter emitter;
  emitter << root;
  const std::string plan = Write("plan.yaml", emitter.c_str());
  const std::string output = Write("labelled.csv", "precious\n");
  for (const char* command : {"segment", "fit"}) {
    const RunResult r = Run({command, "-p", plan, "-s", raw, "-o", output});
    EXPECT_EQ(r.status, 1) << command << ": " << r.err;
    EXPECT_NE(r.err.find("raw.csv: the log does not match the plan " + plan + ": at t = "), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("with the raw axes as they are: at t = 12."), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("nothing written"), std::string::npos) << r.err;
    EXPECT_EQ(ReadBytes(output), "precious\n");
  }
  EXPECT_EQ(Listing(), (std::set<std::string>{"raw.csv", "plan.yaml", "labelled.csv"}));
}

// A lab log without a thermometer and without labels: --temp-c in segment, fit and apply.
TEST_F(CliTest, ALogWithoutTemperatureOrLabelsCalibratesWithTempC) {
  const std::string raw = Path("raw.csv");
  ASSERT_EQ(Run(UnlabelledSoakArgs(raw, {"--temps", "21", "--no-temp-column"})).status, 0);
  EXPECT_EQ(ReadTable(raw).header, (std::vector<std::string>{"time_s", "gyro_x", "gyro_y", "gyro_z",
                                                             "accel_x", "accel_y", "accel_z"}));
  const std::string plan = Fixture("plan_6pos.yaml");
  const std::string cal = Path("cal.yaml");
  RunResult r = Run({"fit", "-p", plan, "-s", raw, "-o", cal});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column \"temp_c\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--temp-c"), std::string::npos) << r.err;
  r = Run({"fit", "-p", plan, "-s", raw, "-o", cal, "--temp-c", "21", "--gyro-temp-order", "3"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("use --gyro-temp-order 0 --accel-temp-order 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(cal));
  r = Run({"fit", "-p", plan, "-s", raw, "-o", cal, "--temp-c", "21"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("no temp_c column, every sample at 21 degC (--temp-c): temperature orders 0"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("no segment column: 18 segments found in 1 pass"), std::string::npos) << r.out;
  const YAML::Node written = YAML::LoadFile(cal);
  EXPECT_EQ(written["fit"]["gyro_temp_order"].as<int>(), 0);
  EXPECT_EQ(written["fit_temp_range_c"][0].as<double>(), 21.0);

  // A file that has temp_c is refused with --temp-c (no reading is silently replaced).
  const std::string with_temp = Write("with_temp.csv",
                                      "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                      "0,25,1,2,3,4,5,6\n");
  r = Run({"apply", "-c", cal, "-s", with_temp, "-o", Path("x.csv"), "--temp-c", "21"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("has a temp_c column"), std::string::npos) << r.err;
  r = Run({"apply", "-c", cal, "-s", raw, "-o", Path("x.csv")});
  EXPECT_EQ(r.status, 2);
  r = Run({"apply", "-c", cal, "-s", raw, "-o", Path("corrected.csv"), "--temp-c", "21", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table corrected = ReadTable(Path("corrected.csv"));
  ASSERT_FALSE(corrected.rows.empty());
  EXPECT_EQ(corrected.Number(0, "temp_c"), 21.0);
  EXPECT_NEAR(corrected.Vector(0, "accel").norm(), 9.81274, 0.05);  // at rest, +z up

  // segment keeps the file's columns: temp_c only when given.
  ASSERT_EQ(Run({"segment", "-p", plan, "-s", raw, "-o", Path("a.csv"), "-q"}).status, 0);
  EXPECT_EQ(ReadTable(Path("a.csv")).header.size(), 8u);
  ASSERT_EQ(Run({"segment", "-p", plan, "-s", raw, "-o", Path("b.csv"), "--temp-c", "21", "-q"}).status, 0);
  EXPECT_EQ(ReadTable(Path("b.csv")).header,
            (std::vector<std::string>{"time_s", "temp_c", "segment", "gyro_x", "gyro_y", "gyro_z", "accel_x",
                                      "accel_y", "accel_z"}));
}

// A hand session (six faces and a 360 deg turn about each axis, raw counts, without labels or a
// thermometer) calibrates end to end through the README's commands: every coefficient within its
// stated sigmas, a certificate that reads the run as the fit did, a calibration that corrects it.
TEST_F(CliTest, HandSessionWithoutLabelsOrTemperatureCalibratesEndToEnd) {
  // Within this many of its reported sigmas (worst case over the 25 degC coefficients).
  constexpr double kTruthSigmas = 3.5;
  const std::string plan = Fixture("plan_hand_6faces_3turns.yaml");
  const std::string raw = Path("hand.csv");
  const std::string truth = Path("hand_truth.csv");
  ASSERT_EQ(Run(HandSessionArgs(raw, {"--no-temp-column", "--truth", truth})).status, 0);
  const RunResult segment =
      Run({"segment", "--plan", plan, "--samples", raw, "-o", Path("hand_labelled.csv")});
  ASSERT_EQ(segment.status, 0) << segment.err;
  EXPECT_NE(segment.out.find("9 segments found in 1 pass"), std::string::npos) << segment.out;
  EXPECT_EQ(std::count(segment.out.begin(), segment.out.end(), '\n') - 3, 9) << segment.out;
  const std::string calibration = Path("hand_cal.yaml");
  const RunResult fit = Run({"fit", "--plan", plan, "--samples", raw, "--temp-c", "25", "-o", calibration,
                             "--report", Path("hand_fit.html"), "--serial", "HAND-1"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("temperature orders 0"), std::string::npos) << fit.out;
  // The certificate reads the run as the fit did (labels found in the data, --temp-c): its noise
  // section looks for the longest rest instead of failing on the missing columns.
  const RunResult report = Run({"report", "-c", calibration, "-p", plan, "-s", raw, "--temp-c", "25", "-o",
                                Path("hand_report.html"), "--serial", "HAND-1"});
  ASSERT_EQ(report.status, 0) << report.err;
  for (const char* html : {"hand_fit.html", "hand_report.html"}) {
    const std::string text = ReadBytes(Path(html));
    EXPECT_NE(text.find("the longest static stretch is"), std::string::npos) << html;
    EXPECT_EQ(text.find("no segment column"), std::string::npos) << html;
    EXPECT_EQ(text.find("temp_c"), std::string::npos) << html << ": a missing-column message";
  }

  const YAML::Node got = YAML::LoadFile(calibration);
  const YAML::Node want = YAML::LoadFile(Fixture("mems_truth.yaml"));
  int checked = 0;
  for (const char* sensor : {"gyro", "accel"}) {
    for (const auto& group : got[sensor]) {
      const std::string name = group.first.as<std::string>();
      if (name == "unit") continue;
      for (const auto& coefficient : group.second) {
        const std::string axis = coefficient.first.as<std::string>();
        const double estimate = coefficient.second[0].as<double>();
        const double sigma = got["sigma"][sensor][name][axis][0].as<double>();
        const double true_value = want[sensor][name][axis][0].as<double>();  // at 25 degC
        ASSERT_GT(sigma, 0.0) << sensor << " " << name << " " << axis;
        EXPECT_LE(std::abs(estimate - true_value), kTruthSigmas * sigma)
            << sensor << " " << name << " " << axis << ": " << estimate << " vs " << true_value << " +- "
            << sigma;
        if (std::string(sensor) == "gyro" && name == "scale") {
          EXPECT_LT(sigma / true_value, 1e-4) << "the turns set the gyro scale to better than 100 ppm";
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 21 + 12);

  // The calibration corrects the session: every resting sample's mean within what the noise leaves.
  const RunResult apply = Run({"apply", "--calibration", calibration, "--samples", raw, "--temp-c", "25",
                               "-o", Path("hand_corrected.csv"), "-q"});
  ASSERT_EQ(apply.status, 0) << apply.err;
  const Table corrected = ReadTable(Path("hand_corrected.csv"));
  const Table true_values = ReadTable(truth);
  ASSERT_EQ(corrected.rows.size(), true_values.rows.size());
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> error_sum;  // per static face
  std::map<int, int> count;
  for (size_t i = 0; i < corrected.rows.size(); ++i) {
    const int face = std::stoi(true_values.rows[i][true_values.Column("segment")]);
    if (face < 1 || face > 6) continue;
    error_sum.try_emplace(face, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    error_sum[face].first += corrected.Vector(i, "gyro") - true_values.Vector(i, "gyro");
    error_sum[face].second += corrected.Vector(i, "accel") - true_values.Vector(i, "accel");
    ++count[face];
  }
  ASSERT_EQ(error_sum.size(), 6u);
  for (const auto& [face, sums] : error_sum) {
    EXPECT_LT((sums.first / count[face]).norm(), 0.005 * kDegToRad) << "face " << face << ", rad/s";
    EXPECT_LT((sums.second / count[face]).norm(), 0.5e-3 * 9.80665) << "face " << face << ", m/s^2";
  }
}

}  // namespace
}  // namespace imufit::testing
