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

// With a limits file each coefficient criterion is judged as metrology judges a procedure: its
// tolerance (a [min, max] limit's half-width) over the U = 2 sigma the plan achieves, at least 4:1
// (--min-ratio); a noise criterion by the plan's longest static dwell.
TEST_F(CliPlanTest, LimitsAreJudgedByTheirRatioToUAndNoiseByTheStaticDwell) {
  const std::string limits = Write("limits.yaml", R"(format: imufit-limits
version: 1
name: plan check test
criteria:
  - {quantity: accel_bias_mg, min: -9.17, max: 35}
  - {quantity: gyro_bias_dps, max_abs: 0.004}
)");
  RunResult r = Run(Args({"--limits", limits, "--format", "yaml"}));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const YAML::Node criteria = YAML::Load(r.out)["criteria"];
  ASSERT_EQ(criteria.size(), 2u) << r.out;
  const double gyro_sigma = YamlSigma(r.out, "gyro bias x");
  const double gyro_ratio = criteria[1]["ratio"].as<double>();
  EXPECT_GE(gyro_ratio, 4.0);
  EXPECT_LE(gyro_ratio, 0.004 / (2.0 * gyro_sigma) * (1.0 + 1e-9));  // over the range, U >= 2 sigma(25 degC)
  EXPECT_NEAR(criteria[0]["tolerance"].as<double>(), 0.5 * (35 + 9.17), 1e-9);
  // A minimum the plan does not reach: exit 3, named.
  r = Run(Args({"--limits", limits, "--min-ratio", "10"}));
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("criterion gyro_bias_dps x, y, z within +-0.004: tolerance 0.004 deg/s / U "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(at least 10:1): NOT MET"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict: the plan cannot judge gyro_bias_dps"), std::string::npos) << r.out;
  // A bias instability needs half an hour of rest; 20 s dwells do not resolve it.
  const std::string noise = Write("noise_limits.yaml", R"(format: imufit-limits
version: 1
name: plan check test
criteria:
  - {quantity: gyro_bias_instability_dph, max_abs: 20}
)");
  r = Run(Args({"--limits", noise}));
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("needs a static stretch of 1800 s, the plan's longest is 20 s: not resolved"),
            std::string::npos)
      << r.out;
}

// Every option plan check's findings advise, plan check accepts: one-temperature, static and hand
// plans are checked with the orders and groups the fit will use.
TEST_F(CliPlanTest, EveryAdvisedOptionIsAccepted) {
  const std::string help = Run({"plan", "check", "--help"}).out;
  const std::vector<std::vector<std::string>> plans = {
      {Fixture("plan_24pos.yaml"), "--temps", "25"},
      {Fixture("plan_6faces_static.yaml"), "--temps=-40,0,40,85"},
      {Fixture("plan_hand_6faces_3turns.yaml"), "--temps", "25"}};
  const std::vector<std::vector<std::string>> remedies = {
      {"--gyro-temp-order", "0", "--accel-temp-order", "0"},
      {"--fit", "gyro-bias,accel", "--prior", Fixture("mems_truth.yaml")},
      {}};
  for (size_t i = 0; i < plans.size(); ++i) {
    std::vector<std::string> args = {
        "plan", "check", "--gyro-noise-density", "1e-4", "--accel-noise-density", "1e-3", "--dwell", "20"};
    args.insert(args.end(), plans[i].begin(), plans[i].end());
    const RunResult advised = Run(args);
    for (size_t at = advised.out.find("--"); at != std::string::npos; at = advised.out.find("--", at + 2)) {
      const std::string option = advised.out.substr(at, advised.out.find_first_of(" ,;)/", at) - at);
      EXPECT_NE(help.find(option), std::string::npos) << option << " advised:\n" << advised.out;
    }
    args.insert(args.end(), remedies[i].begin(), remedies[i].end());
    if (plans[i][0].find("plan_hand") != std::string::npos) {  // the file, not a folder named hand...
      args.insert(args.end(), {"--gyro-temp-order", "0", "--accel-temp-order", "0"});
    }
    const RunResult checked = Run(args);
    EXPECT_EQ(checked.status, 0) << plans[i][0] << "\n" << checked.out << checked.err;
  }
}

// The windows plan check predicts are the fit's: occurrences too short for a window are said, and a
// plan whose every occurrence is too short does not determine the model.
TEST_F(CliPlanTest, WindowsTheFitWillLeaveOutAreSaid) {
  RunResult r =
      Run({"plan", "check", Fixture("plan_24pos.yaml"), "--gyro-noise-density", "1e-4",
           "--accel-noise-density", "1e-3", "--temps=-20,10,50,85", "--dwell", "1", "--rate", "20"});
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("the fit would have no window: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segment occurrences shorter than 20 samples (--window-min-samples)"),
            std::string::npos)
      << r.out;
  r = Run({"plan", "check", Fixture("plan_24pos.yaml"), "--gyro-noise-density", "1e-4",
           "--accel-noise-density", "1e-3", "--temps=-20,10,50,85", "--dwell", "1", "--rate", "20",
           "--window-min-samples", "5"});
  EXPECT_EQ(r.status, 0) << r.out << r.err;
}

// The designed plan carries the station's gravity: the one given, else WGS84 normal gravity at the
// latitude (a plan at 9.80665 run at 9.81274 fits the accelerometer's scale 621 ppm off).
TEST_F(CliPlanTest, DesignWritesTheStationsGravity) {
  constexpr double kNormalGravityTolerance = 1e-4;  // m/s^2, absolute: the published 9.8127 at 52.27 deg
  std::vector<std::string> args = {"plan",
                                   "design",
                                   "-o",
                                   Path("a.yaml"),
                                   "--latitude",
                                   "52.27",
                                   "--tolerance",
                                   "gyro.bias=0.01,accel.bias=1",
                                   "--gyro-noise-density",
                                   "1e-4",
                                   "--accel-noise-density",
                                   "1e-3",
                                   "--dwell",
                                   "20"};
  RunResult r = Run(args);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NEAR(YAML::LoadFile(Path("a.yaml"))["gravity_mps2"].as<double>(), 9.8127, kNormalGravityTolerance);
  args[3] = Path("b.yaml");
  args.insert(args.end(), {"--gravity-mps2", "9.81274"});
  r = Run(args);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("b.yaml"))["gravity_mps2"].as<double>(), 9.81274);
}

// ---- A hand procedure (io/hand_procedure.h; docs/plan.md, "A hand procedure") ----

// A quick hand procedure (12 rests of 4 s at 50 Hz) with `extra` lines, written as hand.yaml, checked
// over 2 simulated sessions.
class CliHandPlanTest : public CliTest {
 protected:
  std::string Hand(const std::string& extra = "") const {
    return Write(
        "hand.yaml",
        "format: imufit-hand-procedure\nversion: 1\nposes: 12\ndwell_s: 4\nturn_s: 1.5\nrate_hz: 50\n" +
            extra);
  }
  RunResult Check(const std::string& hand, std::vector<std::string> extra) const {
    std::vector<std::string> args = {
        "plan", "check",      hand, "--gyro-noise-density", "1e-4", "--accel-noise-density",
        "1e-3", "--sessions", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    return Run(args);
  }
};

TEST_F(CliHandPlanTest, PredictsEveryFittedCoefficientAndParsesAsYaml) {
  const RunResult r = Check(Hand(), {"--tolerance", "gyro.bias=0.01"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("hand procedure: 12 poses, dwell 4 s, turns 1.5 s, 50 Hz"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("gyro g_sensitivity zz"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("accel misalignment xy"), std::string::npos) << r.out;  // held: the body frame
  EXPECT_NE(r.out.find("limiting: gyro bias"), std::string::npos) << r.out;
  const RunResult y = Check(Hand(), {"--format", "yaml"});
  ASSERT_EQ(y.status, 0) << y.err;
  const YAML::Node doc = YAML::Load(y.out);
  EXPECT_EQ(doc["kind"].as<std::string>(), "hand procedure");
  EXPECT_EQ(doc["rows"].size(), 30u);  // gyro 3+3+6+9, accel 3+3+3 (xy, xz, yz held)
  const RunResult j = Check(Hand(), {"--format", "json"});
  ASSERT_EQ(j.status, 0) << j.err;
  EXPECT_EQ(YAML::Load(j.out)["rows"].size(), 30u);
}

TEST_F(CliHandPlanTest, LongerDwellsShrinkTheRestsSigmasAsOneOverRootDwell) {
  const auto accel_bias = [this](const std::string& dwell) {
    const RunResult r = Check(Hand(), {"--format", "yaml", "--dwell", dwell});
    EXPECT_EQ(r.status, 0) << r.err;
    double sum = 0.0;
    for (const YAML::Node& row : YAML::Load(r.out)["rows"]) {
      if (row["group"].as<std::string>() == "accel.bias") sum += row["sigma"].as<double>();
    }
    return sum;
  };
  // White noise averaged over a rest: 16 s against 4 s halves the accelerometer's bias sigma
  // (the poses and turns of the sessions are the same: the seed is).
  constexpr double kRootDwellTolerance = 0.1;  // relative
  EXPECT_NEAR(accel_bias("16") / accel_bias("4"), 0.5, 0.5 * kRootDwellTolerance);
}

TEST_F(CliHandPlanTest, AMissingDirectionExitsOneInTheFitsWords) {
  const RunResult r = Check(Hand("up: [+x, -x, +y, +z, -z]\n"), {});
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("undetermined: no pose with gravity near +y (the y axis down) (2 of 2 sessions)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("imufit: the hand procedure does not reliably determine the model (1 finding)"),
            std::string::npos)
      << r.err;
}

TEST_F(CliHandPlanTest, AnUnmetToleranceExitsThreeWithAdviceThatItAccepts) {
  const RunResult r = Check(Hand(), {"--tolerance", "accel.bias=0.06"});
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  const std::string said = "advice: the shortest session that meets the tolerances: ";
  const size_t at = r.out.find(said);
  ASSERT_NE(at, std::string::npos) << r.out;
  // "--dwell 16 (...)": the option and its value, accepted by the check, which then meets it.
  const size_t from = at + said.size();
  const std::string advised = r.out.substr(from, r.out.find(" (", from) - from);
  const size_t space = advised.find(' ');
  const RunResult again =
      Check(Hand(), {"--tolerance", "accel.bias=0.06", advised.substr(0, space), advised.substr(space + 1)});
  EXPECT_EQ(again.status, 0) << advised << "\n" << again.out << again.err;
}

TEST_F(CliHandPlanTest, TroubleshootingQuotesTheMessages) {
  const std::string page = ReadBytes(Fixture("../docs/troubleshooting.md"));
  const std::string hand = Hand();
  for (const std::vector<std::string>& extra : std::vector<std::vector<std::string>>{{"--temps", "25"}}) {
    const RunResult r = Check(hand, extra);
    EXPECT_EQ(r.status, 2);
    std::string said = r.err.substr(0, r.err.find('\n'));
    said.replace(said.find(hand), hand.size(), "hand.yaml");
    EXPECT_NE(page.find("`" + said + "`"), std::string::npos) << said;
  }
  const RunResult r = Run({"plan", "check", Hand("up: [+x, -x, +y, +z, -z]\n"), "--gyro-noise-density",
                           "1e-4", "--accel-noise-density", "1e-3"});  // the default 3 sessions
  EXPECT_NE(page.find("`undetermined: no pose with gravity near +y (the y axis down) (3 of 3 sessions)`"),
            std::string::npos);
  EXPECT_NE(r.out.find("undetermined: no pose with gravity near +y (the y axis down) (3 of 3 sessions)"),
            std::string::npos)
      << r.out;
}

TEST_F(CliHandPlanTest, LimitsAreJudgedByTheirRatioToU) {
  const auto limits = [this](const std::string& max_abs) {
    return Write("limits.yaml",
                 "format: imufit-limits\nversion: 1\nname: hand\ncriteria:\n"
                 "  - {quantity: gyro_bias_dps, max_abs: " +
                     max_abs +
                     "}\n"
                     "  - {quantity: accel_misalignment_mrad, axes: [xy], max_abs: 3}\n");
  };
  // 12 rests of 4 s: the gyro's bias to about 0.0008 deg/s, U = 0.0017 deg/s.
  const RunResult tight = Check(Hand(), {"--limits", limits("0.004")});
  EXPECT_EQ(tight.status, 3) << tight.out << tight.err;
  EXPECT_NE(tight.out.find("criterion gyro_bias_dps x, y, z within +-0.004: tolerance 0.004 deg/s / U "),
            std::string::npos)
      << tight.out;
  EXPECT_NE(tight.out.find("(at least 4:1): NOT MET"), std::string::npos) << tight.out;
  // The accelerometer's misalignment xy is the body frame's (held): nothing to judge.
  EXPECT_EQ(tight.out.find("criterion accel_misalignment_mrad"), std::string::npos) << tight.out;
  const RunResult loose = Check(Hand(), {"--limits", limits("0.05")});
  EXPECT_EQ(loose.status, 0) << loose.out << loose.err;
  EXPECT_NE(loose.out.find("(at least 4:1): met"), std::string::npos) << loose.out;
}

TEST_F(CliHandPlanTest, BadInputExitsTwoNamingFileLineAndColumn) {
  const RunResult unknown = Check(Hand("poses_per_face: 2\n"), {});
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("hand.yaml:7:1"), std::string::npos) << unknown.err;
  const RunResult direction = Check(Hand("up: [+x, up]\n"), {});
  EXPECT_EQ(direction.status, 2);
  EXPECT_NE(direction.err.find("hand.yaml:7:10"), std::string::npos) << direction.err;
  EXPECT_NE(direction.err.find("\"up\": give +x, -x, +y, -y, +z, -z, corners"), std::string::npos)
      << direction.err;
  // A table plan's options are refused, not ignored; the hand's are refused on a table plan.
  const RunResult temps = Check(Hand(), {"--temps=-20,60"});
  EXPECT_EQ(temps.status, 2);
  EXPECT_NE(temps.err.find("--temps is an option of a table plan's check"), std::string::npos) << temps.err;
  const RunResult poses = Run(Args({"--poses", "12"}));
  EXPECT_EQ(poses.status, 2);
  EXPECT_NE(poses.err.find("--poses is an option of a hand procedure's check"), std::string::npos)
      << poses.err;
  EXPECT_EQ(Check(Hand(), {"--poses", "5"}).status, 2);
  EXPECT_EQ(Check(Hand("twist_axes: none\ntwist_deg: [10, 20]\n"), {}).status, 2);
}

}  // namespace
}  // namespace imufit::testing
