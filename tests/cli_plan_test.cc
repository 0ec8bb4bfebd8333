// `imufit plan check` end to end: the table, the YAML, the exit statuses, and the prediction's
// scaling laws (sigma falls as 1/sqrt(dwell) for white noise).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

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
  const size_t at = yaml.find("name: \"" + name + "\"");
  if (at == std::string::npos) return -1.0;
  const size_t sigma = yaml.find("sigma: ", at);
  return std::strtod(yaml.c_str() + sigma + 7, nullptr);
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

TEST_F(CliPlanTest, BadInputExitsTwo) {
  EXPECT_EQ(Run(Args({"--tolerance", "gyro.bogus=1"})).status, 2);
  EXPECT_EQ(Run(Args({"--tolerance", "gyro.bias=-1"})).status, 2);
  EXPECT_EQ(Run({"plan", "check", Fixture("plan_24pos.yaml")}).status, 2);  // no noise given
}

}  // namespace
}  // namespace imufit::testing
