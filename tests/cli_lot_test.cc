// `imufit lot --store` end to end on the backend under test (cli_lot_test --backend sqlite|postgresql,
// as store_test), on lots fitted with `imufit batch --shard` into one store: four shards writing at
// once give every unit exactly once and, through `imufit lot`, the lot summary and page of one
// unsharded batch; a shard stopped part way, or killed (SIGKILL) mid-batch, and run again completes
// with every unit once and every output whole.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/lot_summary.h"
#include "imufit/factory/shard.h"
#include "imufit/factory/store_history.h"
#include "imufit/io/calibration.h"
#include "imufit/store/store.h"
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

// `text` (CSV) without its column `drop` (cells split at commas outside quotes).
std::string WithoutColumn(const std::string& text, int drop) {
  std::string out, cell;
  int column = 0;
  bool quoted = false;
  for (char c : text) {
    if (c == '"') quoted = !quoted;
    if (quoted || (c != ',' && c != '\n')) {
      cell += c;
      continue;
    }
    if (column != drop) out += (column > 0 && !(drop == 0 && column == 1) ? "," : "") + cell;
    cell.clear();
    column = c == '\n' ? 0 : column + 1;
    if (c == '\n') out += '\n';
  }
  return out;
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

  // `imufit lot --store` gives the unsharded batch's own summary from its store, byte for byte,
  // and the same from the shards' store but for the time each unit was calibrated.
  const std::string batch_summary = testing::ReadBytes((folder_ / "out_whole" / "lot_summary.csv").string());
  const testing::RunResult from_whole =
      Imufit(folder_, {"lot", "--store", whole, "--lot", "LOT-S", "--csv", (folder_ / "whole.csv").string()},
             "lot_whole");
  ASSERT_EQ(from_whole.status, 0) << from_whole.err;
  EXPECT_EQ(testing::ReadBytes((folder_ / "whole.csv").string()), batch_summary);
  const testing::RunResult from_shards =
      Imufit(folder_,
             {"lot", "--store", sharded, "--lot", "LOT-S", "--csv", (folder_ / "shards.csv").string(),
              "--html", (folder_ / "lot.html").string(), "--limits", (folder_ / "limits.yaml").string()},
             "lot_shards");
  ASSERT_EQ(from_shards.status, 0) << from_shards.err;
  const std::string shards_summary = testing::ReadBytes((folder_ / "shards.csv").string());
  constexpr int kCalibratedColumn = 5;  // unit,serial,status,verdict,message,calibrated_utc,...
  EXPECT_EQ(WithoutColumn(shards_summary, kCalibratedColumn),
            WithoutColumn(batch_summary, kCalibratedColumn));
  EXPECT_EQ(std::count(shards_summary.begin(), shards_summary.end(), '\n'), kUnits + 1);
  for (int i = 0; i < kUnits; ++i) {
    const std::string row = "\nunit-" + std::to_string(100 + i) + ",";
    EXPECT_NE(shards_summary.find(row), std::string::npos) << row;
  }
  const std::string page = testing::ReadBytes((folder_ / "lot.html").string());
  EXPECT_NE(page.find("<tr data-history-lot=\"LOT-S\" class=\"current\">"), std::string::npos);
  EXPECT_NE(page.find("MEMS-A acceptance"), std::string::npos);
  const testing::RunResult missing = Imufit(
      folder_, {"lot", "--store", sharded, "--lot", "LOT-X", "--csv", (folder_ / "x.csv").string()}, "lot_x");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("no lot named \"LOT-X\""), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(folder_ / "x.csv"));
}

// Guarded acceptance with the gyro bias X limit at a good unit's value: every good unit lies within
// U of it (conditional). The lot built from the shards' store counts the conditional units as the
// one from the unsharded batch's store does, and as the batch judged them.
TEST_F(ShardTest, TheStoreBuiltLotCountsConditionalVerdictsAsTheUnshardedBatch) {
  const std::string probe = FreshStore("shard_probe");
  ASSERT_EQ(Imufit(folder_, Batch("out_probe", probe), "probe").status, 3);
  double bias_x = 0.0;
  {
    ResultsStore store(probe);
    const StoredFit good = store.LatestOfLot("LOT-S").at(1);  // unit-101: a good one
    const StoredFigure* x = FindFigure(good.figures, "gyro_bias_dps.x");
    ASSERT_NE(x, nullptr);
    ASSERT_GT(x->expanded_u, 0.0);
    bias_x = std::abs(x->value);
  }
  char limit[64];
  std::snprintf(limit, sizeof limit, "%.17g", bias_x);
  WriteText(folder_ / "limits.yaml", std::string(kLimits) + "  - {quantity: gyro_bias_dps, max_abs: " +
                                         limit + ", axes: [x]}\ndecision_rule: guarded\n");
  const std::string whole = FreshStore("guarded_whole"), sharded = FreshStore("guarded_two");
  const testing::RunResult one = Imufit(folder_, Batch("out_whole", whole), "whole");
  ASSERT_EQ(one.status, 3) << one.err;
  for (int i = 0; i < 2; ++i) {
    std::vector<std::string> shard = Batch("out_shards", sharded);
    shard.insert(shard.end(), {"--shard", std::to_string(i) + "/2"});
    const testing::RunResult r = Imufit(folder_, shard, "shard" + std::to_string(i));
    EXPECT_TRUE(r.status == 0 || r.status == 3) << r.status << r.err;
  }
  const Limits limits = ReadLimits((folder_ / "limits.yaml").string());
  ResultsStore a(whole), b(sharded);
  const LotSummary from_whole = MakeLotSummary("LOT-S", StoredLot(&a, "LOT-S"), "test", limits);
  const LotSummary from_shards = MakeLotSummary("LOT-S", StoredLot(&b, "LOT-S"), "test", limits);
  EXPECT_GE(from_whole.conditional, kUnits - kUnits / 5);
  EXPECT_EQ(from_shards.conditional, from_whole.conditional);
  EXPECT_EQ(from_shards.passed, from_whole.passed);
  EXPECT_EQ(from_shards.failed, from_whole.failed);
  // as the batch judged them: guarded acceptance rejects each unit within U of the bias limit
  const std::string batch_summary = testing::ReadBytes((folder_ / "out_whole" / "lot_summary.csv").string());
  int rejected_on_bias = 0;
  for (size_t at = batch_summary.find("|gyro_bias_dps.x| "); at != std::string::npos;
       at = batch_summary.find("|gyro_bias_dps.x| ", at + 1))
    ++rejected_on_bias;
  EXPECT_EQ(from_whole.conditional, rejected_on_bias);
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

// The units of shard `index` of kShards.
int UnitsOfShard(int index) {
  int units = 0;
  for (int i = 0; i < kUnits; ++i)
    units += ShardOf("unit-" + std::to_string(100 + i), kShards) == index ? 1 : 0;
  return units;
}

// Starts `args` as a process of its own, its output into `log`; its process id.
pid_t Start(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> all = {IMUFIT_EXE};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  pid_t pid = -1;
  const int status = posix_spawn(&pid, IMUFIT_EXE, &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  return status == 0 ? pid : -1;
}

TEST_F(ShardTest, AShardKilledMidBatchAndRunAgainCompletesWithEveryUnitOnce) {
  constexpr auto kPatience = std::chrono::seconds(120);  // for the first unit to be recorded
  const std::string store = FreshStore("shard_killed");
  { ResultsStore create(store); }
  std::vector<std::string> args = Batch("out_killed", store);
  args.insert(args.end(), {"--jobs", "1", "--shard", "2/4"});
  const int expected = UnitsOfShard(2);
  ASSERT_GT(expected, 2);
  const pid_t batch = Start(args, folder_ / "killed.log");
  ASSERT_GT(batch, 0);
  const auto give_up = std::chrono::steady_clock::now() + kPatience;
  int64_t recorded = 0;
  while (recorded == 0 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    recorded = ResultsStore(store, StoreAccess::kRead).CountFits();
  }
  ASSERT_EQ(kill(batch, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(batch, &status, 0), batch);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the batch ended before it was killed";
  const int64_t at_kill = ResultsStore(store, StoreAccess::kRead).CountFits();
  EXPECT_GE(at_kill, 1);
  EXPECT_LT(at_kill, expected);  // killed mid-batch

  const testing::RunResult again = Imufit(folder_, args, "after_kill");
  EXPECT_TRUE(again.status == 0 || again.status == 3) << again.status << again.err;
  ResultsStore done(store, StoreAccess::kRead);
  EXPECT_EQ(done.CountFits(), expected);
  const std::vector<StoredFit> units = done.LatestOfLot("LOT-S");
  ASSERT_EQ(units.size(), static_cast<size_t>(expected));
  for (const StoredFit& unit : units) {
    // Every unit's calibration is whole: the file the store holds, and it reads.
    const fs::path calibration = folder_ / "out_killed" / unit.unit / "calibration.yaml";
    ASSERT_TRUE(fs::exists(calibration)) << calibration;
    EXPECT_EQ(testing::ReadBytes(calibration.string()), unit.calibration_yaml) << unit.unit;
    EXPECT_NO_THROW(ReadCalibration(calibration.string())) << unit.unit;
  }
}

}  // namespace
}  // namespace imufit
