// End-to-end tests of `imufit allan` on a raw-count log (its tests on rates are in
// cli_allan_rates_test.cc): `--calibration` corrects on the way in as `imufit apply` does.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "imufit/io/machine_text.h"
#include "imufit/io/sha256.h"

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// The angle random walk a summary of `imufit allan` prints for `column`, deg/sqrt(h) (NaN if none).
double PrintedArw(const std::string& summary, const std::string& column) {
  const size_t at = summary.find(column + " (gyro");
  const std::string label = "angle random walk";
  const size_t line = at == std::string::npos ? std::string::npos : summary.find(label, at);
  return line == std::string::npos ? std::nan("") : std::stod(summary.substr(line + label.size()));
}

// `imufit allan --calibration` analyses a raw-count log through the shared
// correction, with the result of `imufit apply` then `imufit allan` to the last bit, and the
// simulated noise density comes back.
TEST_F(CliTest, AllanWithCalibrationEqualsApplyThenAllanOnARawLog) {
  const std::string truth = Fixture("mems_truth.yaml");
  // 300 s at 100 Hz fix the ARW to about 1 % (one sigma); not quantised, so the white noise is
  // the simulated one alone.
  constexpr double kArwRelativeTolerance = 0.05;
  const std::string plan = StaticPlan();
  StaticRun("raw.csv.gz", 300, 40, 11);

  // Raw counts without a calibration: the warning names the cure.
  RunResult r = Run({"allan", "-s", Path("raw.csv.gz"), "-c", "gyro_x", "-o", Path("raw_allan.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("gyro_x has a mean of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--calibration CAL.yaml"), std::string::npos) << r.err;

  r = Run({"allan", "-s", Path("raw.csv.gz"), "--calibration", truth, "-o", Path("direct.csv"),
           "--noise-yaml", Path("direct.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");  // corrected: nothing implausible, inside the fit range
  const std::string direct_summary = r.out;
  ASSERT_EQ(Run({"apply", "-c", truth, "-s", Path("raw.csv.gz"), "-o", Path("corrected.csv"), "-q"}).status,
            0);
  r = Run({"allan", "-s", Path("corrected.csv"), "-o", Path("applied.csv"), "--noise-yaml",
           Path("applied.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  // Every deviation, bound and noise term bit for bit (the files differ only in the input named).
  EXPECT_EQ(ReadBytes(Path("direct.csv")), ReadBytes(Path("applied.csv")));
  std::string direct_yaml = ReadBytes(Path("direct.yaml"));
  const std::string applied_yaml = ReadBytes(Path("applied.yaml"));
  // The noise file names the calibration the figures were corrected through, with its SHA-256
  // (only then); the summary names it too.
  EXPECT_EQ(YAML::Load(direct_yaml)["noise"]["calibration"].as<std::string>(), truth);
  EXPECT_EQ(YAML::Load(direct_yaml)["noise"]["calibration_sha256"].as<std::string>(), Sha256OfFile(truth));
  EXPECT_FALSE(YAML::Load(applied_yaml)["noise"]["calibration"]);
  EXPECT_FALSE(YAML::Load(applied_yaml)["noise"]["calibration_sha256"]);
  EXPECT_EQ(direct_summary.find(Path("raw.csv.gz") + " corrected by " + truth + ": "), 0u) << direct_summary;
  EXPECT_EQ(r.out.find(Path("corrected.csv") + ": "), 0u) << r.out;
  const std::string recorded = "  calibration: " + YamlStringText(truth) +
                               "\n  calibration_sha256: " + YamlStringText(Sha256OfFile(truth)) + "\n";
  ASSERT_NE(direct_yaml.find(recorded), std::string::npos) << direct_yaml;
  direct_yaml.erase(direct_yaml.find(recorded), recorded.size());
  direct_yaml.replace(direct_yaml.find(Path("raw.csv.gz")), Path("raw.csv.gz").size(), Path("corrected.csv"));
  EXPECT_EQ(direct_yaml, applied_yaml);
  const auto summary_body = [](const std::string& summary) { return summary.substr(summary.find('\n')); };
  EXPECT_EQ(summary_body(direct_summary), summary_body(r.out));
  const double expected_arw = kStaticGyroNoiseDensity * 180.0 / M_PI * 60.0;
  for (const char* column : {"gyro_x", "gyro_y", "gyro_z"}) {
    const double arw = PrintedArw(direct_summary, column);
    EXPECT_NEAR(arw, expected_arw, kArwRelativeTolerance * expected_arw) << column << "\n" << direct_summary;
  }

  // A log without temp_c needs --temp-c, as apply does; --temp-c alone, --scale with
  // --calibration and a column no calibration corrects are bad invocations; nothing is written.
  r = Run({"simulate", "-p", plan, "-c", truth, "-o", Path("no_temp.csv"), "--rate", "100", "--dwell", "30",
           "--no-temp-column", "--no-segment-column", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "-o", Path("x.csv")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column \"temp_c\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--temp-c"), std::string::npos) << r.err;
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "--temp-c", "25", "-c",
           "gyro_z,temp_c", "-o", Path("no_temp_allan.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(ReadBytes(Path("no_temp_allan.csv")).find("\ntemp_c,oadev,0.01,"), std::string::npos);
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "--temp-c", "125", "-c", "gyro_z",
           "-o", Path("hot.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lie more than 0.5 degC outside the calibration's fit temperature range"),
            std::string::npos)
      << r.err;
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--temp-c", "25"},
        {"--calibration", truth, "--scale", "939.65"},
        {"--calibration", truth, "--temp-c", "25", "-c", "gyro_x,segment"},
        {"--calibration", Path("x.csv"), "--temp-c", "25"}}) {
    std::vector<std::string> args = {"allan", "-s", Path("no_temp.csv"), "-o", Path("x.csv")};
    args.insert(args.end(), bad.begin(), bad.end());
    r = Run(args);
    EXPECT_EQ(r.status, 2) << bad[0] << " " << bad[1] << ": " << r.err;
    EXPECT_FALSE(fs::exists(Path("x.csv"))) << bad[0];
  }
}

// A static log too short to resolve the slow terms: the noise file holds no `nan` or `inf`, every
// number in it is finite, and the terms the log cannot resolve are marked `<key>_resolved: false`.
TEST_F(CliTest, AllanNoiseYamlOfAShortStaticLogHoldsOnlyFiniteNumbers) {
  StaticRun("short.csv", 20, 25, 5);
  RunResult r = Run({"allan", "-s", Path("short.csv"), "--calibration", Fixture("mems_truth.yaml"), "-o",
                     Path("short_adev.csv"), "--noise-yaml", Path("short_noise.yaml"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = ReadBytes(Path("short_noise.yaml"));
  // No value spelled nan or inf (in any of YAML's spellings); words such as "inflation" are fine.
  const std::regex non_finite(R"((:|\[|,)\s*[-+]?\.?(nan|inf)\b)", std::regex::icase);
  EXPECT_FALSE(std::regex_search(text, non_finite)) << text;
  EXPECT_NE(text.find("_resolved: false"), std::string::npos) << text;
  int numbers = 0;
  const std::function<void(const YAML::Node&)> visit = [&](const YAML::Node& node) {
    if (node.IsMap() || node.IsSequence()) {
      for (const auto& child : node) visit(node.IsMap() ? child.second : child);
      return;
    }
    double value = 0.0;
    if (node.IsScalar() && YAML::convert<double>::decode(node, value)) {
      EXPECT_TRUE(std::isfinite(value)) << node.Scalar();
      ++numbers;
    }
  };
  visit(YAML::Load(text));
  EXPECT_GT(numbers, 10) << text;
  // Kalibr's random walks, which 20 s cannot resolve, are their upper bounds: never 0.
  const YAML::Node kalibr = YAML::Load(text)["noise"]["kalibr"];
  for (const char* key : {"gyroscope_random_walk", "accelerometer_random_walk"}) {
    ASSERT_TRUE(kalibr[key]) << key << "\n" << text;
    EXPECT_GT(kalibr[key].as<double>(), 0.0) << key;
  }
}

}  // namespace
}  // namespace imufit::testing
