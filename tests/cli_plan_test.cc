// `imufit plan check` end to end: the table, the YAML, the exit statuses, and the prediction's
// scaling laws (sigma falls as 1/sqrt(dwell) for white noise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <yaml-cpp/yaml.h>

#include "cli_util.h"
#include "test_util.h"

namespace imufit::testing {
namespace {

class CliPlanTest : public CliTest {};

const std::vector<std::string> kNoise = {"--gyro-noise-density",
                                         "1e-4",
                                         "--accel-noise-density",
                                         "1e-3",
                                         "--temps=-20,10,50,85",
                                         "--dwell",
                                         "20",
                                         "--rate",
                                         "100"};

std::vector<std::string> Args(std::vector<std::string> extra) {
  std::vector<std::string> args = {"plan", "check", Fixture("plan_24pos.yaml")};
  args.insert(args.end(), kNoise.begin(), kNoise.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// The sigma of the row named `name` in the YAML output.
double YamlSigma(const std::string& yaml, const std::string& name) {
  for (const YAML::Node& row : YAML::Load(yaml)["rows"]) {
    if (row["name"].as<std::string>() == name) return row["sigma"].as<double>();
  }
  return -1.0;
}

TEST_F(CliPlanTest, PrintsEveryCoefficientAndTheLimitingOne) {
  const RunResult r = Run(Args({"--tolerance", "gyro.bias=0.01"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("gyro bias x (cubic term)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("accel scale z"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("limiting: gyro bias"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("temperatures: a cubic is best determined by soaks at -20, "), std::string::npos)
      << r.out;
}

TEST_F(CliPlanTest, ExitThreeWhenATolerenceCannotBeMet) {
  const RunResult r = Run(Args({"--tolerance", "accel.bias=1e-6"}));
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("verdict: the plan cannot meet accel bias"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("chamber hours:"), std::string::npos) << r.out;
}

TEST_F(CliPlanTest, WhiteNoiseSigmaFallsAsOneOverRootDwell) {
  constexpr double kTolerance = 0.02;  // the 0.5 s trim makes the windows 19.5 s and 79.5 s
  const RunResult short_run = Run(Args({"--format", "yaml"}));
  std::vector<std::string> longer = Args({"--format", "yaml"});
  for (size_t i = 0; i + 1 < longer.size(); ++i) {
    if (longer[i] == "--dwell") longer[i + 1] = "80";
  }
  const RunResult long_run = Run(longer);
  ASSERT_EQ(short_run.status, 0) << short_run.err;
  ASSERT_EQ(long_run.status, 0) << long_run.err;
  for (const std::string name : {"gyro bias x", "accel scale y", "gyro misalignment xy (linear term)"}) {
    const double ratio = YamlSigma(short_run.out, name) / YamlSigma(long_run.out, name);
    EXPECT_NEAR(ratio, std::sqrt(79.5 / 19.5), kTolerance * ratio) << name;
  }
}

TEST_F(CliPlanTest, UndeterminedPlanExitsOneNamingWhatIsMissing) {
  const RunResult r = Run({"plan", "check", Fixture("plan_24pos.yaml"), "--gyro-noise-density", "1e-4",
                           "--accel-noise-density", "1e-3", "--temps", "25", "--dwell", "20"});
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("undetermined: "), std::string::npos) << r.out;
}

// A node's content whatever its style (flow or block): scalars, [lists], {maps}.
std::string Canonical(const YAML::Node& node) {
  std::string out;
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) {
    for (const YAML::Node& e : node) out += Canonical(e) + ",";
    return "[" + out + "]";
  }
  for (const auto& e : node) out += e.first.Scalar() + ":" + Canonical(e.second) + ",";
  return "{" + out + "}";
}

// JSON says what the YAML says: the same keys, the same numbers (both read by one YAML reader:
// JSON is YAML).
TEST_F(CliPlanTest, JsonHoldsTheYamlsContent) {
  const RunResult yaml = Run(Args({"--format", "yaml", "--tolerance", "gyro.bias=0.01,accel.bias=0.5"}));
  const RunResult json = Run(Args({"--format", "json", "--tolerance", "gyro.bias=0.01,accel.bias=0.5"}));
  ASSERT_EQ(yaml.status, 0) << yaml.err;
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_EQ(json.out.front(), '{');
  EXPECT_NE(json.out.find("\"rows\": ["), std::string::npos) << json.out;
  const YAML::Node from_yaml = YAML::Load(yaml.out);
  const YAML::Node from_json = YAML::Load(json.out);
  ASSERT_EQ(from_yaml.size(), from_json.size());
  for (const auto& entry : from_yaml) {
    const std::string key = entry.first.as<std::string>();
    EXPECT_EQ(Canonical(entry.second), Canonical(from_json[key])) << key;
  }
  EXPECT_GT(from_json["rows"].size(), 40u);
  EXPECT_EQ(from_json["rows"][0]["name"].as<std::string>().rfind("gyro bias", 0), 0u);
}

// The latitude given overrides the plan's: the Earth rate the gyro sees changes, the sigmas hardly do.
TEST_F(CliPlanTest, LatitudeIsOptional) {
  const RunResult plans = Run(Args({"--format", "yaml"}));
  const RunResult equator = Run(Args({"--format", "yaml", "--latitude", "0"}));
  ASSERT_EQ(plans.status, 0) << plans.err;
  ASSERT_EQ(equator.status, 0) << equator.err;
  EXPECT_NE(plans.out, equator.out);
  EXPECT_EQ(Run(Args({"--latitude", "91"})).status, 2);
}

// The unit's noise from `imufit allan --noise-yaml`: the same prediction as the densities it holds
// typed by hand, and close to that of the densities the record was simulated with.
TEST_F(CliPlanTest, NoiseFromAllanNoiseYaml) {
  constexpr double kGyroDensity = kStaticGyroNoiseDensity;
  constexpr double kAccelDensity = kStaticAccelNoiseDensity;
  constexpr double kFittedDensityTolerance = 0.08;  // relative: 300 s at 100 Hz, worst of three axes
  const std::string truth = Fixture("mems_truth.yaml");
  StaticRun("raw.csv.gz", 300, 40, 11);
  RunResult r = Run({"allan", "-s", Path("raw.csv.gz"), "--calibration", truth, "-o", Path("allan.csv"),
                     "--noise-yaml", Path("noise.yaml"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const YAML::Node kalibr = YAML::LoadFile(Path("noise.yaml"))["noise"]["kalibr"];
  const std::string gyro = kalibr["gyroscope_noise_density"].Scalar();
  const std::string accel = kalibr["accelerometer_noise_density"].Scalar();
  EXPECT_NEAR(std::stod(gyro), kGyroDensity, kFittedDensityTolerance * kGyroDensity);
  EXPECT_NEAR(std::stod(accel), kAccelDensity, kFittedDensityTolerance * kAccelDensity);

  const std::vector<std::string> schedule = {
      "--temps=-20,10,50,85", "--dwell", "20", "--rate", "100", "--format", "yaml"};
  std::vector<std::string> from_file = {"plan", "check", Fixture("plan_24pos.yaml"), "--noise-yaml",
                                        Path("noise.yaml")};
  std::vector<std::string> by_hand = {
      "plan", "check", Fixture("plan_24pos.yaml"), "--gyro-noise-density", gyro, "--accel-noise-density",
      accel};
  // The bias instability the file resolved (worst axis) goes with the densities.
  const YAML::Node columns = YAML::LoadFile(Path("noise.yaml"))["noise"]["columns"];
  for (const std::string sensor : {"gyro", "accel"}) {
    const std::string key = sensor == "gyro" ? "bias_instability_radps" : "bias_instability_mps2";
    double worst = 0.0;
    for (const std::string axis : {"_x", "_y", "_z"}) {
      const YAML::Node figure = columns[sensor + axis][key];
      if (figure) worst = std::max(worst, figure[0].as<double>());
    }
    if (worst > 0.0) {
      by_hand.push_back("--" + sensor + "-bias-instability");
      by_hand.push_back(columns[sensor + "_x"] ? YAML::Dump(YAML::Node(worst)) : "0");
    }
  }
  from_file.insert(from_file.end(), schedule.begin(), schedule.end());
  by_hand.insert(by_hand.end(), schedule.begin(), schedule.end());
  const RunResult file_check = Run(from_file);
  const RunResult hand_check = Run(by_hand);
  ASSERT_EQ(file_check.status, 0) << file_check.err;
  ASSERT_EQ(hand_check.status, 0) << hand_check.err;
  for (const std::string name : {"gyro bias x", "accel scale y"}) {
    EXPECT_DOUBLE_EQ(YamlSigma(file_check.out, name), YamlSigma(hand_check.out, name)) << name;
  }
  // Not a noise file: exit 2 naming it.
  r = Run({"plan", "check", Fixture("plan_24pos.yaml"), "--noise-yaml", Fixture("plan_6pos.yaml")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("plan_6pos.yaml"), std::string::npos) << r.err;
}

// A number printed after `label` in `text` (nan when absent).
double NumberAfter(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  return at == std::string::npos ? std::nan("") : std::strtod(text.c_str() + at + label.size(), nullptr);
}

// `plan design` gives a plan that meets the tolerances (plan check says so) in no more chamber hours
// than the hand-made 24-position plan that meets them too, at its D-optimal soaks.
TEST_F(CliPlanTest, DesignMeetsTheTolerancesInNoMoreHoursThanAHandPlan) {
  constexpr double kSoakSettleS = 1800.0;
  const std::vector<std::string> schedule = {"--gyro-noise-density",
                                             "1e-4",
                                             "--accel-noise-density",
                                             "1e-3",
                                             "--dwell",
                                             "20",
                                             "--transition",
                                             "10",
                                             "--rate",
                                             "100",
                                             "--tolerance",
                                             "gyro.bias=0.0012,accel.bias=0.1,gyro.scale=60"};
  const std::string hand_soaks = "--temps=-40,-5.45,50.45,85";  // ends and +-1/sqrt(5) of the half-range
  std::vector<std::string> hand = {"plan",     "check",    Fixture("plan_24pos.yaml"),
                                   hand_soaks, "--format", "yaml"};
  hand.insert(hand.end(), schedule.begin(), schedule.end());
  const RunResult hand_check = Run(hand);
  ASSERT_EQ(hand_check.status, 0) << hand_check.out << hand_check.err;  // the hand plan meets them
  const double hand_hours = NumberAfter(hand_check.out, "plan_hours: ") + 4 * kSoakSettleS / 3600.0;

  std::vector<std::string> design = {"plan",
                                     "design",
                                     "-o",
                                     Path("designed.yaml"),
                                     "--positions",
                                     "faces,edges,corners",
                                     "--rates",
                                     "100,300",
                                     "--latitude",
                                     "52.27",
                                     "--set-points=-40,-15,-5.45,10,35,50.45,60,85",
                                     "--soak-settle",
                                     "1800"};
  design.insert(design.end(), schedule.begin(), schedule.end());
  const RunResult designed = Run(design);
  ASSERT_EQ(designed.status, 0) << designed.out << designed.err;
  EXPECT_NE(designed.out.find("predicted before the exchange:"), std::string::npos) << designed.out;
  EXPECT_NE(designed.out.find("predicted after the exchange:"), std::string::npos) << designed.out;
  const size_t temps_at = designed.out.find("--temps=", designed.out.find("after exchange:"));
  ASSERT_NE(temps_at, std::string::npos) << designed.out;
  const std::string soaks = designed.out.substr(temps_at, designed.out.find(')', temps_at) - temps_at);

  std::vector<std::string> check = {"plan", "check", Path("designed.yaml"), soaks, "--format", "yaml"};
  check.insert(check.end(), schedule.begin(), schedule.end());
  const RunResult design_check = Run(check);
  EXPECT_EQ(design_check.status, 0) << design_check.out << design_check.err;
  const double soak_count = static_cast<double>(std::count(soaks.begin(), soaks.end(), ',') + 1);
  const double design_hours =
      NumberAfter(design_check.out, "plan_hours: ") + soak_count * kSoakSettleS / 3600.0;
  EXPECT_LE(design_hours, hand_hours) << designed.out;
  EXPECT_NEAR(NumberAfter(designed.out.substr(designed.out.find("after exchange:")), "): "), design_hours,
              0.01);
  std::printf("design: %.2f h (%s), hand plan: %.2f h\n", design_hours, soaks.c_str(), hand_hours);
}

TEST_F(CliPlanTest, DesignExitsThreeWhenNoPlanMeetsTheTolerancesAndTwoWithoutOne) {
  const std::vector<std::string> noise = {"--gyro-noise-density", "1e-4", "--accel-noise-density", "1e-3"};
  std::vector<std::string> args = {"plan", "design", "-o", Path("x.yaml"), "--tolerance", "accel.bias=1e-7"};
  args.insert(args.end(), noise.begin(), noise.end());
  const RunResult unmet = Run(args);
  EXPECT_EQ(unmet.status, 3) << unmet.out << unmet.err;
  EXPECT_NE(unmet.out.find("verdict: no plan of these candidates meets the tolerances"), std::string::npos);
  EXPECT_EQ(Listing().count("x.yaml"), 0u);  // nothing written
  args = {"plan", "design", "-o", Path("x.yaml")};
  args.insert(args.end(), noise.begin(), noise.end());
  const RunResult none = Run(args);
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("give at least one tolerance"), std::string::npos) << none.err;
  args.insert(args.end(), {"--tolerance", "gyro.bias=0.01", "--rates", "2000"});
  EXPECT_EQ(Run(args).status, 2);  // beyond the table's limit
}

// docs/troubleshooting.md quotes what the program prints for the common mistakes.
TEST_F(CliPlanTest, TroubleshootingQuotesTheMessages) {
  const std::string page = ReadBytes(Fixture("../docs/troubleshooting.md"));
  const std::vector<std::vector<std::string>> mistakes = {
      {"plan", "check", Fixture("plan_24pos.yaml")},
      {"plan", "design", "-o", Path("x.yaml"), "--gyro-noise-density", "1e-4", "--accel-noise-density",
       "1e-3"},
      {"plan", "check", Fixture("plan_24pos.yaml"), "--gyro-noise-density", "1e-4", "--accel-noise-density",
       "1e-3", "--tolerance", "gyro.bias=1deg"}};
  for (const std::vector<std::string>& args : mistakes) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2);
    const std::string said = r.err.substr(0, r.err.find('\n'));
    EXPECT_NE(page.find("`" + said + "`"), std::string::npos) << said;
  }
}

TEST_F(CliPlanTest, BadInputExitsTwo) {
  EXPECT_EQ(Run(Args({"--tolerance", "gyro.bogus=1"})).status, 2);
  EXPECT_EQ(Run(Args({"--tolerance", "gyro.bias=-1"})).status, 2);
  EXPECT_EQ(Run({"plan", "check", Fixture("plan_24pos.yaml")}).status, 2);  // no noise given
}

}  // namespace
}  // namespace imufit::testing
