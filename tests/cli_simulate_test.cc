// End-to-end tests of `imufit simulate`: the same seed gives the same bytes, the truth it writes
// is the truth docs/spec.md defines for a plan, samples and truth are written together or not at
// all, and its options are checked.
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

// Earth's rotation rate, rad/s, as docs/spec.md states it.
constexpr double kEarthRate = 7.292115e-5;

// The truth of a plan's dwell segments, written from docs/spec.md section 2 (rad/s, m/s^2, body).
std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> SpecTruthOfPlan(const std::string& plan_path) {
  const YAML::Node plan = YAML::LoadFile(plan_path);
  const auto vector = [](const YAML::Node& v) {
    return Eigen::Vector3d(v[0].as<double>(), v[1].as<double>(), v[2].as<double>());
  };
  const double g = plan["gravity_mps2"].as<double>();
  const bool has_latitude = static_cast<bool>(plan["latitude_deg"]);
  const double phi = has_latitude ? plan["latitude_deg"].as<double>() * kDegToRad : 0.0;
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> truth;
  for (const YAML::Node& segment : plan["segments"]) {
    const Eigen::Vector3d up = vector(segment["up"]).normalized();
    const double rate = segment["rate_dps"] ? segment["rate_dps"].as<double>() * kDegToRad : 0.0;
    Eigen::Vector3d omega = rate * up;
    if (has_latitude) {
      omega += kEarthRate * std::sin(phi) * up;
      if (rate == 0.0 && segment["north"])
        omega += kEarthRate * std::cos(phi) * vector(segment["north"]).normalized();
    }
    Eigen::Vector3d a = g * up;
    if (rate != 0.0 && segment["lever_arm_m"]) {
      const Eigen::Vector3d r = vector(segment["lever_arm_m"]);
      a -= rate * rate * (r - up * r.dot(up));
    }
    truth[segment["id"].as<int>()] = {omega, a};
  }
  return truth;
}

// ------------------------------------------------------------------------------------------ simulate

TEST_F(CliTest, SimulateIsDeterministic) {
  const auto simulate = [&](const std::string& name, const std::string& seed) {
    const RunResult r = Run({"simulate",
                             "--plan",
                             Fixture("plan_6pos.yaml"),
                             "--calibration",
                             Fixture("mems_truth.yaml"),
                             "-o",
                             Path(name),
                             "--ramp=-40,85",
                             "--passes",
                             "2",
                             "--rate",
                             "25",
                             "--dwell",
                             "1",
                             "--transition",
                             "0.5",
                             "--gyro-noise-density",
                             "8.7e-5",
                             "--accel-noise-density",
                             "1.5e-3",
                             "--gyro-bias-instability",
                             "2.4e-5",
                             "--accel-random-walk",
                             "3e-5",
                             "--temp-noise",
                             "0.05",
                             "--quantize",
                             "--seed",
                             seed,
                             "--quiet"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "");  // --quiet
    return ReadBytes(Path(name));
  };
  const std::string a = simulate("a.csv", "11");
  const std::string b = simulate("b.csv", "11");
  const std::string c = simulate("c.csv", "12");
  EXPECT_GT(a.size(), 10000u);
  EXPECT_EQ(a, b) << "the same seed must give the same bytes";
  EXPECT_NE(a, c) << "another seed must give another run";
  // Only the seed in the provenance comment differs? No: the samples themselves differ.
  EXPECT_NE(a.substr(a.find("time_s")), c.substr(c.find("time_s")));
}

// The truth that `imufit simulate --truth` writes for dwell samples is the truth docs/spec.md section 2
// defines (Earth rate with and without `north`, centripetal term of the lever arm).
TEST_F(CliTest, SimulatedTruthFollowsTheSpec) {
  for (const char* plan : {"plan_6pos.yaml", "plan_24pos.yaml"}) {
    const auto [samples, truth_path] = SimulateNoiseless(Fixture(plan), Fixture("mems_truth.yaml"), "run");
    const auto expected = SpecTruthOfPlan(Fixture(plan));
    const Table truth = ReadTable(truth_path);
    std::set<int> seen;
    int transitions = 0;
    for (size_t i = 0; i < truth.rows.size(); ++i) {
      const int segment = std::stoi(truth.rows[i][truth.Column("segment")]);
      if (segment < 0) {
        ++transitions;
        continue;
      }
      seen.insert(segment);
      ASSERT_TRUE(expected.count(segment)) << segment;
      EXPECT_LE((truth.Vector(i, "gyro") - expected.at(segment).first).norm(), 1e-14)
          << plan << " " << segment;
      EXPECT_LE((truth.Vector(i, "accel") - expected.at(segment).second).norm(), 1e-13)
          << plan << " " << segment;
    }
    EXPECT_EQ(seen.size(), expected.size()) << plan;
    EXPECT_GT(transitions, 0) << plan;
  }
}

// simulate -o S --truth T writes both or neither: a truth file that fails at its very end (a disk
// that fills up; here a file size limit the samples fit under and the truth does not) leaves no
// samples file, which would otherwise pass for a complete simulation.
TEST_F(CliTest, SimulateWritesSamplesAndTruthTogetherOrNeither) {
  const std::vector<std::string> args = SmallRunArgs(Path("samples.csv.gz"), {"--truth", Path("truth.csv")});
  RunResult r = Run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const uintmax_t samples_bytes = fs::file_size(Path("samples.csv.gz"));
  const uintmax_t truth_bytes = fs::file_size(Path("truth.csv"));
  // The truth must fail when it is committed, after the samples are complete: it fits in the 1 MiB
  // an output holds before its first write, and the samples fit under the limit.
  constexpr uintmax_t kOutputBufferBytes = 1 << 20;
  ASSERT_LT(truth_bytes, kOutputBufferBytes);
  ASSERT_LT(samples_bytes, truth_bytes);
  fs::remove(Path("samples.csv.gz"));
  fs::remove(Path("truth.csv"));

  r = RunWithFileSizeLimit(args, (samples_bytes + truth_bytes) / 2);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("truth.csv: write failed"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>()) << "the samples were written without their truth";

  // Neither when the truth cannot even be started.
  std::vector<std::string> unwritable = args;
  unwritable.back() = Path("missing/truth.csv");  // the value of --truth
  r = Run(unwritable);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("missing/truth.csv: cannot create"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>());
}

TEST_F(CliTest, SimulateJitterMustKeepTimesIncreasing) {
  const RunResult r = Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"),
                           "-o", Path("x.csv"), "--rate", "50", "--time-jitter-s", "0.01"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("time jitter"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace imufit::testing
