// `imufit batch --shard` into one store on the backend under test: four shards writing at once
// give every unit exactly once and the lot the yield and figures of one unsharded batch; a shard
// stopped part way and run again completes.
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/shard.h"
#include "imufit/factory/store.h"
#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

constexpr int kUnits = 40;
constexpr int kShards = 4;
constexpr double kSameFigure = 1e-12;  // the same fit in two runs: the same numbers

constexpr const char* kLimits = R"(format: imufit-limits
version: 1
name: MEMS-A acceptance
nominal: {gyro_scale: 939.65, accel_scale: 208.838}
criteria:
  - {quantity: gyro_bias_dps, max_abs: 5}
  - {quantity: gyro_g_sensitivity_dpsg, max_abs: 0.05}
  - {quantity: fit_temp_range_c, covers: [-20, 60]}
)";

testing::RunResult Imufit(const fs::path& folder, const std::vector<std::string>& args,
                          const std::string& name) {
  return testing::RunProgram(IMUFIT_EXE, args, (folder / (name + ".out")).string(),
                             (folder / (name + ".err")).string());
}

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// A lot of kUnits units, each its own serial; every fifth unit's gyro g-sensitivity fails the
// limits. Two simulated runs, copied (the plans differ by serial, so every run is its own).
class ShardTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::path(FreshSqliteStore("shard_lot"));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    WriteText(folder_ / "limits.yaml", kLimits);
    const std::string truth = std::string(IMUFIT_FIXTURES_DIR) + "/mems_truth.yaml";
    std::string bad = testing::ReadBytes(truth);
    bad = std::regex_replace(bad, std::regex("xx: \\[0\\.0483,"), "xx: [0.15,");
    WriteText(folder_ / "bad_truth.yaml", bad);
    const std::string plan = testing::ReadBytes(std::string(IMUFIT_FIXTURES_DIR) + "/plan_6pos.yaml");
    for (const std::string& which : {std::string("good"), std::string("bad")}) {
      const testing::RunResult r = Imufit(folder_,
                                          {"simulate",
                                           "--plan",
                                           std::string(IMUFIT_FIXTURES_DIR) + "/plan_6pos.yaml",
                                           "--calibration",
                                           which == "good" ? truth : (folder_ / "bad_truth.yaml").string(),
                                           "-o",
                                           (folder_ / (which + ".csv")).string(),
                                           "--rate",
                                           "10",
                                           "--dwell",
                                           "3",
                                           "--temps",
                                           "-20,5,30,60",
                                           "--gyro-noise-density",
                                           "2e-4",
                                           "--accel-noise-density",
                                           "2e-3",
                                           "--seed",
                                           "7",
                                           "-q"},
                                          "simulate_" + which);
      ASSERT_EQ(r.status, 0) << r.err;
    }
    for (int i = 0; i < kUnits; ++i) {
      const std::string unit = "unit-" + std::to_string(100 + i);
      const fs::path dir = folder_ / "units" / unit;
      WriteText(dir / "plan.yaml", std::regex_replace(plan, std::regex("format: imufit-plan\n"),
                                                      "format: imufit-plan\nserial: SN-" + unit + "\n"));
      fs::copy_file(folder_ / (i % 5 == 0 ? "bad.csv" : "good.csv"), dir / "samples.csv");
    }
  }

  void TearDown() override { fs::remove_all(folder_); }

  std::vector<std::string> Batch(const std::string& out, const std::string& store) const {
    return {"batch",       (folder_ / "units").string(),
            "-o",          (folder_ / out).string(),
            "--limits",    (folder_ / "limits.yaml").string(),
            "--store",     store,
            "--lot",       "LOT-S",
            "--no-report", "-q"};
  }

  fs::path folder_;
};

TEST_F(ShardTest, FourShardsAtOnceGiveEveryUnitOnceAndTheUnshardedLot) {
  const std::string whole = FreshStore("shard_whole"), sharded = FreshStore("shard_four");
  std::vector<std::string> args = Batch("out_whole", whole);
  args.insert(args.end(), {"--jobs", "2"});
  const testing::RunResult one = Imufit(folder_, args, "whole");
  ASSERT_EQ(one.status, 3) << one.err;  // some units fail their limits
  std::vector<std::thread> shards;
  std::vector<testing::RunResult> results(kShards);
  for (int i = 0; i < kShards; ++i) {
    shards.emplace_back([&, i] {
      std::vector<std::string> shard = Batch("out_shards", sharded);
      shard.insert(shard.end(),
                   {"--jobs", "1", "--shard", std::to_string(i) + "/" + std::to_string(kShards)});
      results[i] = Imufit(folder_, shard, "shard" + std::to_string(i));
    });
  }
  for (std::thread& t : shards) t.join();
  for (const testing::RunResult& r : results)
    EXPECT_TRUE(r.status == 0 || r.status == 3) << r.status << r.err;
  ResultsStore a(whole), b(sharded);
  EXPECT_EQ(b.CountFits(), kUnits);
  const std::vector<LotYield> ya = a.Yield("LOT-S"), yb = b.Yield("LOT-S");
  ASSERT_EQ(ya.size(), 1u);
  ASSERT_EQ(yb.size(), 1u);
  EXPECT_EQ(yb[0].units, kUnits);
  EXPECT_EQ(ya[0].failed, kUnits / 5);
  EXPECT_EQ(yb[0].passed, ya[0].passed);
  EXPECT_EQ(yb[0].failed, ya[0].failed);
  EXPECT_EQ(yb[0].not_fitted, ya[0].not_fitted);
  const std::vector<LotValue> va = a.LotValues("gyro_bias_dps.x"), vb = b.LotValues("gyro_bias_dps.x");
  ASSERT_EQ(va.size(), static_cast<size_t>(kUnits));
  ASSERT_EQ(vb.size(), va.size());
  for (size_t i = 0; i < va.size(); ++i) {
    EXPECT_EQ(vb[i].unit, va[i].unit);
    EXPECT_NEAR(vb[i].value, va[i].value, kSameFigure) << va[i].unit;
  }
  EXPECT_FALSE(fs::exists(folder_ / "out_shards" / "lot_summary.csv"));  // the lot page comes from the store
}

TEST_F(ShardTest, AShardStoppedPartWayAndRunAgainCompletes) {
  const std::string store = FreshStore("shard_resume");
  std::vector<std::string> args = Batch("out_resume", store);
  args.insert(args.end(), {"--jobs", "1", "--shard", "1/4"});
  std::vector<std::string> stopped = args;
  stopped.insert(stopped.end(), {"--max-units", "2"});
  const testing::RunResult first = Imufit(folder_, stopped, "stopped");
  EXPECT_EQ(first.status, 1) << first.err;  // stopped early
  EXPECT_EQ(ResultsStore(store).CountFits(), 2);
  const testing::RunResult second = Imufit(folder_, args, "resumed");
  EXPECT_TRUE(second.status == 0 || second.status == 3) << second.err;
  int expected = 0;
  for (int i = 0; i < kUnits; ++i)
    expected += ShardOf("unit-" + std::to_string(100 + i), kShards) == 1 ? 1 : 0;
  ResultsStore resumed(store);
  EXPECT_EQ(resumed.CountFits(), expected);
  EXPECT_EQ(resumed.Yield("LOT-S")[0].units, expected);
}

}  // namespace
}  // namespace imufit
