// `imufit history` across stations on the backend under test: yield by lot, station and month, a
// station's drift of a key figure, every calibration of a serial; as numbers, CSV and HTML pages,
// from a store of known content.
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

StoredFit At(StoredFit fit, const std::string& station) {
  fit.station = station;
  return fit;
}

// Two stations, two lots, three months. SN2 fails at station-1 in January and passes a new run at
// station-2 in March (its latest fit); SN5 cannot be fitted.
//   station-1: SN1 lot-a 2026-01-05 PASS 1.0; SN2 lot-a 2026-01-06 FAIL 3.0
//   station-2: SN3 lot-a 2026-02-01 PASS 1.5; SN4 lot-b 2026-02-10 PASS 2.0;
//              SN5 lot-b 2026-03-01 not fitted; SN2 lot-a 2026-03-02 PASS 1.2
std::string KnownStore(const std::string& name) {
  const std::string target = FreshStore(name);
  ResultsStore store(target);
  store.Record(At(MakeFit("SN1", "lot-a", "2026-01-05T08:00:00Z", 1.0, "PASS"), "station-1"));
  store.Record(At(MakeFit("SN2", "lot-a", "2026-01-06T08:00:00Z", 3.0, "FAIL"), "station-1"));
  store.Record(At(MakeFit("SN3", "lot-a", "2026-02-01T08:00:00Z", 1.5, "PASS"), "station-2"));
  store.Record(At(MakeFit("SN4", "lot-b", "2026-02-10T08:00:00Z", 2.0, "PASS"), "station-2"));
  StoredFit not_fitted = At(MakeFit("SN5", "lot-b", "2026-03-01T08:00:00Z", 0.0, ""), "station-2");
  not_fitted.status = "not-fitted";
  not_fitted.figures.clear();
  store.Record(not_fitted);
  StoredFit rerun = At(MakeFit("SN2", "lot-a", "2026-03-02T08:00:00Z", 1.2, "PASS"), "station-2");
  rerun.samples_sha256 = std::string(64, '9');  // a new run of the unit
  store.Record(rerun);
  return target;
}

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

testing::RunResult History(const std::vector<std::string>& args) {
  const std::string base = FreshSqliteStore("history_output");
  std::vector<std::string> all = {"history"};
  all.insert(all.end(), args.begin(), args.end());
  return testing::RunProgram(IMUFIT_EXE, all, base + ".out", base + ".err");
}

size_t Lines(const std::string& text) {
  size_t n = 0;
  for (char c : text) n += c == '\n' ? 1 : 0;
  return n;
}

TEST(HistoryTest, TheCommandAnswersAsTableCsvAndHtml) {
  const std::string target = KnownStore("history_cli");
  testing::RunResult r = History({target, "--by", "station", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            "station,units,passed,failed,not_fitted,yield\n"
            "station-1,1,1,0,0,100.00\n"
            "station-2,4,3,0,1,75.00\n");
  r = History({target, "--by", "month"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2026-03"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("50.0%"), std::string::npos) << r.out;
  r = History({target, "--trend", "gyro.bias.x", "--station", "station-2", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Lines(r.out), 4u) << r.out;  // the header and three fits
  r = History({target, "--trend", "gyro.bias.x"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("mean per station and month"), std::string::npos) << r.out;
  r = History({target, "--serial", "SN2", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Lines(r.out), 3u) << r.out;
  EXPECT_NE(r.out.find(",station-1,"), std::string::npos) << r.out;

  const std::filesystem::path pages = std::filesystem::path(FreshSqliteStore("history_pages")).parent_path();
  r = History({target, "--by", "month", "--html", (pages / "months.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string months = testing::ReadBytes((pages / "months.html").string());
  EXPECT_NE(months.find("<tr data-group=\"2026-03\">"), std::string::npos);
  EXPECT_NE(months.find("data-yield=\"50\""), std::string::npos);
  EXPECT_NE(months.find("<svg"), std::string::npos);
  r = History({target, "--trend", "gyro.bias.x", "--html", (pages / "drift.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string drift = testing::ReadBytes((pages / "drift.html").string());
  EXPECT_NE(drift.find("data-station=\"station-2\" data-month=\"2026-02\""), std::string::npos);
  EXPECT_NE(drift.find("data-mean=\"1.75\""), std::string::npos);
  r = History({target, "--serial", "SN2", "--html", (pages / "sn2.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string sn2 = testing::ReadBytes((pages / "sn2.html").string());
  size_t rows = 0;
  for (size_t at = sn2.find("<tr data-fit="); at != std::string::npos; at = sn2.find("<tr data-fit=", at + 1))
    ++rows;
  EXPECT_EQ(rows, 2u);

  // Mistakes: one line each, as docs/troubleshooting.md quotes it.
  const std::string troubleshooting =
      testing::ReadBytes(std::string(IMUFIT_FIXTURES_DIR) + "/../docs/troubleshooting.md");
  for (const std::vector<std::string>& mistake : {std::vector<std::string>{target, "--by", "week"},
                                                  {target, "--station", "station-1", "--by", "lot"}}) {
    r = History(mistake);
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    const std::string said = r.err.substr(0, r.err.size() - 1);  // less its newline
    EXPECT_EQ(said.find('\n'), std::string::npos) << r.err;
    EXPECT_NE(troubleshooting.find("`" + said + "`"), std::string::npos) << said;
  }
}

}  // namespace
}  // namespace imufit
