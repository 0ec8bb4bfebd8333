// The store's history across stations on the backend under test: yield by lot, station and month, a
// station's drift of a key figure, every calibration of a serial, from a store of known content
// (KnownStore; the command `imufit history` on it: cli_history_test).
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/store_history.h"
#include "imufit/store/store.h"
#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

constexpr double kExact = 1e-12;  // stored doubles come back bit-exact; a mean of two, to rounding

struct Counts {
  int units, passed, failed, not_fitted;
};

std::map<std::string, Counts> ByGroup(const std::vector<GroupYield>& yields) {
  std::map<std::string, Counts> counts;
  for (const GroupYield& y : yields) counts[y.group] = {y.units, y.passed, y.failed, y.not_fitted};
  return counts;
}

void ExpectCounts(const std::map<std::string, Counts>& got, const std::string& group, Counts want) {
  ASSERT_EQ(got.count(group), 1u) << group;
  const Counts& c = got.at(group);
  EXPECT_EQ(c.units, want.units) << group;
  EXPECT_EQ(c.passed, want.passed) << group;
  EXPECT_EQ(c.failed, want.failed) << group;
  EXPECT_EQ(c.not_fitted, want.not_fitted) << group;
}

TEST(HistoryTest, YieldByLotStationAndMonthCountsEachUnitOnceByItsLatestFit) {
  ResultsStore store(KnownStore("history_yield"));
  const std::vector<GroupYield> lots = store.YieldBy(YieldGroup::kLot);
  ASSERT_EQ(lots.size(), 2u);
  EXPECT_EQ(lots[0].group, "lot-a");  // in the order of their first fit
  ExpectCounts(ByGroup(lots), "lot-a", {3, 3, 0, 0});
  ExpectCounts(ByGroup(lots), "lot-b", {2, 1, 0, 1});
  const auto stations = ByGroup(store.YieldBy(YieldGroup::kStation));
  EXPECT_EQ(stations.size(), 2u);
  ExpectCounts(stations, "station-1", {1, 1, 0, 0});  // SN2 counts where it was last fitted
  ExpectCounts(stations, "station-2", {4, 3, 0, 1});
  const std::vector<GroupYield> months = store.YieldBy(YieldGroup::kMonth);
  ASSERT_EQ(months.size(), 3u);
  EXPECT_EQ(months[0].group, "2026-01");
  EXPECT_EQ(months[2].group, "2026-03");
  ExpectCounts(ByGroup(months), "2026-01", {1, 1, 0, 0});
  ExpectCounts(ByGroup(months), "2026-02", {2, 2, 0, 0});
  ExpectCounts(ByGroup(months), "2026-03", {2, 1, 0, 1});
  EXPECT_EQ(YieldPct(months[2]), 50.0);
  EXPECT_EQ(store.Yield("lot-b")[0].not_fitted, 1);  // the lot yield is the same count
}

TEST(HistoryTest, AStationsDriftIsItsMonthlyMeanOfEveryFit) {
  ResultsStore store(KnownStore("history_drift"));
  const std::vector<TrendPoint> two = store.Trend("gyro.bias.x", "", "station-2");
  ASSERT_EQ(two.size(), 3u);
  EXPECT_EQ(two[0].serial, "SN3");
  EXPECT_EQ(two[2].serial, "SN2");
  EXPECT_EQ(two[2].station, "station-2");
  const std::vector<MonthlyMean> means = MonthlyMeans(store.Trend("gyro_bias_dps.x", "", ""));
  ASSERT_EQ(means.size(), 3u);
  EXPECT_EQ(means[0].station, "station-1");
  EXPECT_EQ(means[0].count, 2);
  EXPECT_NEAR(means[0].mean, 2.0, kExact);  // SN1 1.0 and SN2's failing 3.0: every fit
  EXPECT_EQ(means[1].month, "2026-02");
  EXPECT_NEAR(means[1].mean, 1.75, kExact);
  EXPECT_EQ(means[2].month, "2026-03");
  EXPECT_EQ(means[2].mean, 1.2);
  EXPECT_EQ(store.Trend("gyro.bias.x", "SN2", "station-1").size(), 1u);
}

TEST(HistoryTest, EveryCalibrationOfASerialAcrossStations) {
  ResultsStore store(KnownStore("history_serial"));
  const std::vector<StoredFit> fits = store.BySerial("SN2");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].station, "station-1");
  EXPECT_EQ(fits[0].verdict, "FAIL");
  EXPECT_EQ(fits[1].station, "station-2");
  EXPECT_EQ(fits[1].verdict, "PASS");
}

}  // namespace
}  // namespace imufit
