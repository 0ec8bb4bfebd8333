// The results store on both backends against real databases: SQLite files, and a throwaway
// PostgreSQL cluster (tests/postgres_fixture.sh). Run as
//   store_test --backend sqlite
//   store_test --backend postgresql --state FILE   (FILE: the fixture's connection string)
// With PostgreSQL unavailable it prints why and exits 77 (ctest SKIP).
#include <libpq-fe.h>
#include <sqlite3.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/certify.h"
#include "imufit/factory/lot_history.h"
#include "imufit/factory/store_history.h"
#include "imufit/io/error.h"
#include "imufit/io/sha256.h"
#include "imufit/store/store.h"
#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

TEST(StoreTest, RecordsFiguresAndAttachmentsAndAnswers) {
  ResultsStore store(FreshStore("answers"));
  EXPECT_STREQ(store.backend(), StoreBackend().c_str());
  StoredFit fit = MakeFit("SN1", "lot-a", "2026-01-01T00:00:00Z", 1.5, "PASS");
  fit.attachments = {{"certificate", "lot-a/SN1/certificate.html", std::string(64, 'a')}};
  fit.figures[0].limit_abs = 2.0;
  fit.figures[0].outcome = "pass";
  EXPECT_GT(store.Record(fit), 0);
  store.Record(MakeFit("SN2", "lot-a", "2026-01-01T00:01:00Z", 2.5, "FAIL"));
  StoredFit recalibrated = MakeFit("SN1", "lot-b", "2026-02-01T00:00:00Z", 1.25, "PASS");
  recalibrated.samples_sha256 = std::string(64, '3');  // a new run of the unit
  store.Record(recalibrated);
  const std::vector<StoredFit> fits = store.BySerial("SN1");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].station, "station-1");
  EXPECT_EQ(fits[0].part_number, "IMU-9");
  ASSERT_EQ(fits[0].figures.size(), 2u);
  EXPECT_EQ(fits[0].figures[0].value, 1.5);  // bit-exact through text on PostgreSQL too
  EXPECT_EQ(fits[0].figures[0].expanded_u, 0.02);
  EXPECT_EQ(fits[0].figures[0].limit_abs, 2.0);
  EXPECT_EQ(fits[0].figures[0].outcome, "pass");
  EXPECT_EQ(fits[0].figures[1].name, "gyro_bias_dps.y");  // in the order recorded
  ASSERT_EQ(fits[0].attachments.size(), 1u);
  EXPECT_EQ(fits[0].attachments[0].path, "lot-a/SN1/certificate.html");
  const std::vector<LotYield> yields = store.Yield("");
  ASSERT_EQ(yields.size(), 2u);
  EXPECT_EQ(yields[0].lot, "lot-a");
  EXPECT_EQ(yields[0].units, 2);
  EXPECT_EQ(yields[0].passed, 1);
  EXPECT_EQ(yields[0].failed, 1);
  EXPECT_EQ(store.Trend("gyro.bias.x", "").size(), 3u);
  EXPECT_EQ(store.Trend("gyro_bias_dps.x", "SN1").back().value, 1.25);
  EXPECT_EQ(store.LotValues("gyro.bias.x").size(), 3u);
}

TEST(StoreTest, TheSameFitRecordedTwiceIsOneRowAndARefitOfTheSameRunSharesItsRun) {
  const std::string target = FreshStore("rerun");
  {
    ResultsStore store(target);
    const StoredFit fit = MakeFit("SN1", "lot-a", "2026-01-01T00:00:00Z", 1.5, "PASS");
    const int64_t id = store.Record(fit);
    EXPECT_EQ(store.Record(fit), id);  // a re-run changes nothing
    StoredFit refit = fit;
    refit.time_utc = "2026-01-02T00:00:00Z";
    refit.verdict = "FAIL";
    EXPECT_NE(store.Record(refit), id);
    EXPECT_EQ(RunKey(refit), RunKey(fit));
    EXPECT_NE(FitKey(refit), FitKey(fit));
  }
  ResultsStore store(target);  // reopened
  EXPECT_EQ(store.CountFits(), 2);
  EXPECT_EQ(store.Yield("lot-a")[0].failed, 1);  // the latest fit counts
}

TEST(StoreTest, ARunKeepsTheLotItWasFirstRecordedIn) {
  ResultsStore store(FreshStore("first_lot"));
  const StoredFit fit = MakeFit("SN1", "lot-a", "2026-01-01T00:00:00Z", 1.5, "PASS");
  const int64_t id = store.Record(fit);
  StoredFit again = fit;  // the same run re-imported under another lot
  again.lot = "lot-z";
  EXPECT_EQ(store.Record(again), id);
  StoredFit refit = again;  // a refit of the same run, recorded under another lot
  refit.time_utc = "2026-01-02T00:00:00Z";
  store.Record(refit);
  const std::vector<StoredFit> fits = store.BySerial("SN1");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].lot, "lot-a");
  EXPECT_EQ(fits[1].lot, "lot-a");
  EXPECT_TRUE(store.Yield("lot-z").empty());
  EXPECT_EQ(store.LatestOfLot("lot-a").size(), 1u);
  EXPECT_EQ(store.LatestOfLot("lot-a")[0].time_utc, "2026-01-02T00:00:00Z");
}

TEST(StoreTest, RunKeysAreVersion5Uuids) {
  const std::string key = RunKey(MakeFit("SN1", "lot-a", "2026-01-01T00:00:00Z", 1.5, "PASS"));
  ASSERT_EQ(key.size(), 36u);
  EXPECT_EQ(key[14], '5');
  EXPECT_NE(std::string("89ab").find(key[19]), std::string::npos) << key;
}

TEST(StoreTest, ConcurrentWritersRecordEveryFitOnce) {
  const std::string target = FreshStore("concurrent");
  { ResultsStore create(target); }
  constexpr int kWriters = 4, kUnits = 40;
  std::vector<std::thread> writers;
  std::atomic<int> failures{0};
  for (int w = 0; w < kWriters; ++w) {
    writers.emplace_back([&, w] {
      try {
        ResultsStore store(target);  // a connection of its own, as a shard has
        // Every writer records every unit: each fit must end up once.
        for (int u = 0; u < kUnits; ++u) {
          const int unit = (u + w * 7) % kUnits;
          store.Record(MakeFit("SN" + std::to_string(unit), "lot-c", "2026-03-01T00:00:00Z", unit, "PASS"));
        }
      } catch (const std::exception& e) {
        std::fprintf(stderr, "writer %d: %s\n", w, e.what());
        ++failures;
      }
    });
  }
  for (std::thread& t : writers) t.join();
  EXPECT_EQ(failures.load(), 0);
  ResultsStore store(target);
  EXPECT_EQ(store.CountFits(), kUnits);
  ASSERT_EQ(store.Yield("lot-c").size(), 1u);
  EXPECT_EQ(store.Yield("lot-c")[0].units, kUnits);
}

TEST(StoreTest, APasswordOnTheCommandLineIsRefused) {
  for (const std::string target :
       {"postgresql://imufit:secret@localhost/imufit", "host=localhost dbname=imufit password=secret"}) {
    try {
      ResultsStore store(target);
      ADD_FAILURE() << "accepted " << target;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("put it in ~/.pgpass or PGPASSFILE"), std::string::npos)
          << e.what();
      EXPECT_EQ(std::string(e.what()).find("secret"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(IsPostgresStore("postgresql://host/db"));
  EXPECT_TRUE(IsPostgresStore("host=/tmp dbname=x"));
  EXPECT_FALSE(IsPostgresStore("results.db"));
}

TEST(StoreTest, AVersion1SqliteStoreIsMigratedKeepingEveryRow) {
  if (StoreBackend() != "sqlite") GTEST_SKIP() << "version 1 stores were SQLite only";
  const std::string path = FreshStore("v1");
  WriteVersion1Store(path);
  ResultsStore store(path);
  EXPECT_EQ(store.CountFits(), 3);
  const std::vector<StoredFit> fits = store.BySerial("SN1");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[0].lot, "lot-a");
  EXPECT_EQ(fits[0].calibration_yaml, "yaml 1");
  EXPECT_EQ(fits[1].verdict, "FAIL");
  EXPECT_EQ(fits[1].message, "|gyro_bias_dps.x| 9 > 2 deg/s");
  ASSERT_EQ(fits[1].figures.size(), 2u);
  EXPECT_EQ(fits[1].figures[1].name, "gyro_bias_dps.y");
  EXPECT_EQ(fits[1].figures[0].value, 9.0);
  EXPECT_EQ(fits[1].figures[0].sigma, 0.25);
  EXPECT_EQ(store.BySerial("SN2").size(), 1u);
  EXPECT_EQ(store.Yield("lot-a")[0].units, 2);
  ResultsStore again(path);  // opening a migrated store changes nothing
  EXPECT_EQ(again.CountFits(), 3);
}

// Runs `sql` on the store `target` directly, as an older imufit would have left it.
void ExecuteOnStore(const std::string& target, const std::string& sql) {
  if (StoreBackend() == "sqlite") {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(target.c_str(), &db), SQLITE_OK);
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    sqlite3_close(db);
    return;
  }
  PGconn* connection = PQconnectdb(target.c_str());
  ASSERT_EQ(PQstatus(connection), CONNECTION_OK) << PQerrorMessage(connection);
  PGresult* result = PQexec(connection, sql.c_str());
  EXPECT_EQ(PQresultStatus(result), PGRES_COMMAND_OK) << PQresultErrorMessage(result);
  PQclear(result);
  PQfinish(connection);
}

// One line per answer, in the order given: what YieldBy(), LatestOfLot() and LotValues() say.
// A lot's statistics of a figure, to the digits the lot page prints.
std::string LotStatsLine(const std::string& lot, const LotFigureStats& st) {
  char text[160];
  std::snprintf(text, sizeof text, "stats %s: %d %.6g %.6g\n", lot.c_str(), st.count, st.mean, st.sigma);
  return text;
}

std::string Answers(ResultsStore* store, const std::vector<std::string>& lots) {
  std::ostringstream out;
  for (YieldGroup by : {YieldGroup::kLot, YieldGroup::kStation, YieldGroup::kMonth}) {
    for (const GroupYield& y : store->YieldBy(by)) {
      out << NameOf(kYieldGroupNames, by) << " " << y.group << ": " << y.units << " " << y.passed << " "
          << y.failed << " " << y.not_fitted << "\n";
    }
  }
  for (const std::string& lot : lots) {
    for (const StoredFit& f : store->LatestOfLot(lot))
      out << "latest " << lot << " " << f.unit << " " << f.id << "\n";
  }
  for (const LotValue& v : store->LotValues("gyro_bias_dps.x"))
    out << "value " << v.lot << " " << v.unit << " " << v.value << "\n";
  for (const LotFigureStats& st : store->LotStats({"gyro_bias_dps.x"})) out << LotStatsLine(st.lot, st);
  return out.str();
}

// The same answers recomputed from every fit: each (lot, unit) by its fit of the latest time, of
// those the highest id.
std::string RecomputedAnswers(ResultsStore* store, const std::vector<std::string>& lots) {
  std::map<std::pair<std::string, std::string>, StoredFit> latest;
  for (StoredFit& f : store->All()) {
    const auto key = std::make_pair(f.lot, f.unit);
    const auto it = latest.find(key);
    if (it == latest.end() || std::tie(f.time_utc, f.id) > std::tie(it->second.time_utc, it->second.id)) {
      latest[key] = std::move(f);
    }
  }
  std::ostringstream out;
  for (YieldGroup by : {YieldGroup::kLot, YieldGroup::kStation, YieldGroup::kMonth}) {
    std::map<std::string, GroupYield> groups;
    std::map<std::string, std::string> first;  // a lot's earliest latest fit: lots are listed by it
    for (const auto& [key, f] : latest) {
      const std::string group = by == YieldGroup::kLot       ? f.lot
                                : by == YieldGroup::kStation ? f.station
                                                             : f.time_utc.substr(0, 7);
      if (by == YieldGroup::kLot && group.empty()) continue;
      GroupYield& y = groups[group];
      y.group = group;
      ++y.units;
      y.passed += f.verdict == "PASS";
      y.failed += f.verdict == "FAIL";
      y.not_fitted += f.status != "fitted";
      if (first[group].empty() || f.time_utc < first[group]) first[group] = f.time_utc;
    }
    std::vector<GroupYield> ordered;
    for (const auto& [group, y] : groups) ordered.push_back(y);
    if (by == YieldGroup::kLot) {
      std::stable_sort(ordered.begin(), ordered.end(), [&](const GroupYield& a, const GroupYield& b) {
        return first[a.group] < first[b.group];
      });
    }
    for (const GroupYield& y : ordered) {
      out << NameOf(kYieldGroupNames, by) << " " << y.group << ": " << y.units << " " << y.passed << " "
          << y.failed << " " << y.not_fitted << "\n";
    }
  }
  for (const std::string& lot : lots) {
    for (const auto& [key, f] : latest) {
      if (key.first == lot) out << "latest " << lot << " " << f.unit << " " << f.id << "\n";
    }
  }
  for (const auto& [key, f] : latest) {
    const StoredFigure* x = FindFigure(f.figures, "gyro_bias_dps.x");
    if (!key.first.empty() && f.status == "fitted" && x)
      out << "value " << key.first << " " << key.second << " " << x->value << "\n";
  }
  std::map<std::string, std::vector<double>> values;  // by lot
  for (const auto& [key, f] : latest) {
    const StoredFigure* x = FindFigure(f.figures, "gyro_bias_dps.x");
    if (!key.first.empty() && f.status == "fitted" && x) values[key.first].push_back(x->value);
  }
  for (const auto& [lot, v] : values) {
    const MeanSigma m = MeanAndSigma(v);
    LotFigureStats st;
    st.count = m.count;
    st.mean = m.mean;
    st.sigma = m.sigma;
    out << LotStatsLine(lot, st);
  }
  return out.str();
}

// Fits of three lots and single files, at two stations, recorded out of time order, with equal
// times (the later record wins), refits of the same run, re-records and a run re-imported under
// another lot. Fixed seed.
std::vector<StoredFit> ShuffledHistory() {
  std::mt19937 random(20);
  const std::vector<std::string> lots = {"lot-a", "lot-b", "lot-c", ""};
  std::vector<StoredFit> fits;
  for (int i = 0; i < 80; ++i) {
    const int unit = static_cast<int>(random() % 12);
    const std::string lot = lots[unit % 4];
    const std::string time =
        "2026-0" + std::to_string(1 + random() % 3) + "-0" + std::to_string(1 + random() % 2) + "T00:00:00Z";
    const char* verdicts[] = {"PASS", "FAIL", ""};
    StoredFit fit =
        MakeFit("SN" + std::to_string(unit), lot, time, static_cast<double>(i), verdicts[random() % 3]);
    if (fit.verdict.empty()) fit.status = random() % 2 ? "not-fitted" : "error";
    fit.station = random() % 2 ? "station-1" : "station-2";
    fit.samples_sha256 = std::string(63, '2') + std::to_string(random() % 3);  // one of three runs per unit
    fits.push_back(fit);
    if (random() % 5 == 0) fits.push_back(fit);  // recorded again: a re-run or a merge
    if (random() % 7 == 0) {
      fit.lot = "lot-z";  // the same run re-imported under another lot keeps its first lot
      fits.push_back(fit);
    }
  }
  return fits;
}

const std::vector<std::string> kShuffledLots = {"lot-a", "lot-b", "lot-c", "lot-z", ""};

TEST(StoreTest, LatestFitAnswersEqualARecomputationFromEveryFitWhateverTheRecordingOrder) {
  ResultsStore store(FreshStore("latest"));
  const std::vector<StoredFit> fits = ShuffledHistory();
  for (size_t i = 0; i < fits.size(); ++i) {
    if (i % 2 == 0) {
      store.Record(fits[i]);
    } else {
      store.RecordAll({fits[i]});
    }
    if (i % 10 == 9 || i + 1 == fits.size()) {
      ASSERT_EQ(Answers(&store, kShuffledLots), RecomputedAnswers(&store, kShuffledLots))
          << "after " << i + 1;
    }
  }
  EXPECT_NE(Answers(&store, kShuffledLots).find("lot-c"), std::string::npos);
}

// How far the store's lot statistics may lie from MeanAndSigma() over the same values, relative to
// the sigma: round-off of the shifted sums, far below what a sum of squares without the shift loses
// on these values (about 1e6 * 1e6 * 2e-16 / 1e-6 = 2e-4 of the variance, and sign errors).
constexpr double kLotStatsRelTol = 1e-8;

TEST(StoreTest, LotStatsEqualMeanAndSigmaOfTheLotValuesDespiteALargeCommonOffset) {
  ResultsStore store(FreshStore("lot_stats"));
  std::mt19937 random(7);
  std::normal_distribution<double> spread(0.0, 1e-3);
  constexpr double kOffset = 1e6;
  for (const std::string lot : {"lot-a", "lot-b", "lot-c"}) {
    for (int u = 0; u < 7; ++u) {
      StoredFit fit = MakeFit(lot + "-SN" + std::to_string(u), lot, "2026-02-01T00:00:00Z",
                              kOffset + (lot == "lot-b" ? 5e-3 : 0.0) + spread(random), "PASS");
      store.Record(fit);
      if (u == 3) {  // refitted later: the refit counts, the first fit not
        fit.time_utc = "2026-03-01T00:00:00Z";
        fit.figures[0].value = kOffset + spread(random);
        store.Record(fit);
      }
    }
  }
  store.Record(MakeFit("single-SN", "lot-single", "2026-02-01T00:00:00Z", kOffset + 1e-3, "PASS"));
  StoredFit not_fitted = MakeFit("lot-a-SN9", "lot-a", "2026-02-01T00:00:00Z", 0.0, "");
  not_fitted.status = "not-fitted";
  store.Record(not_fitted);
  for (const std::string figure : {"gyro_bias_dps.x", "gyro.bias.x"}) {
    std::map<std::string, std::vector<double>> values;
    for (const LotValue& v : store.LotValues(figure)) values[v.lot].push_back(v.value);
    const std::vector<LotFigureStats> stats = store.LotStats({figure});
    ASSERT_EQ(stats.size(), values.size()) << figure;
    for (const LotFigureStats& s : stats) {
      SCOPED_TRACE(figure + " " + s.lot);
      const MeanSigma expected = MeanAndSigma(values.at(s.lot));
      EXPECT_EQ(s.figure, figure);
      EXPECT_EQ(s.figure_unit, "deg/s");
      EXPECT_EQ(s.count, expected.count);
      EXPECT_NEAR(s.mean, expected.mean, kLotStatsRelTol * 1e-3);
      EXPECT_NEAR(s.sigma, expected.sigma, kLotStatsRelTol * std::max(expected.sigma, 1e-3));
      if (s.lot != "lot-single") {
        EXPECT_GT(s.sigma, 1e-4);
      }
    }
  }
  EXPECT_TRUE(store.LotStats({"no_such_figure"}).empty());
}

TEST(StoreTest, AFiguresJudgementIsKeptAndTheStoredLotCountsConditionalUnitsAsTheBatchDid) {
  const std::string target = FreshStore("judgement");
  ResultsStore store(target);
  const auto judged = [](StoredFit fit, const std::string& outcome, const std::string& judgement) {
    fit.figures[0].limit_abs = 5.0;
    fit.figures[0].outcome = outcome;
    fit.figures[0].judgement = judgement;
    return fit;
  };
  store.Record(
      judged(MakeFit("SN1", "lot-j", "2026-05-01T00:00:00Z", 4.999, "PASS"), "pass", "conditional pass"));
  store.Record(
      judged(MakeFit("SN2", "lot-j", "2026-05-01T00:00:00Z", 5.001, "FAIL"), "fail", "conditional fail"));
  store.Record(judged(MakeFit("SN3", "lot-j", "2026-05-01T00:00:00Z", 1.0, "PASS"), "pass", "PASS"));
  StoredFit unresolved = MakeFit("SN4", "lot-j", "2026-05-01T00:00:00Z", 1.0, "PASS");
  unresolved.figures[1].judgement = kNotResolved;
  store.Record(unresolved);
  const std::vector<StoredFit> fits = store.LatestOfLot("lot-j");
  ASSERT_EQ(fits.size(), 4u);
  EXPECT_EQ(fits[0].figures[0].judgement, "conditional pass");
  EXPECT_EQ(fits[1].figures[0].judgement, "conditional fail");
  EXPECT_EQ(fits[3].figures[1].judgement, kNotResolved);
  const BatchResult lot = StoredLot(&store, "lot-j");
  ASSERT_EQ(lot.units.size(), 4u);
  ASSERT_TRUE(lot.units[0].verdict && lot.units[1].verdict && lot.units[2].verdict);
  EXPECT_EQ(lot.units[0].verdict->Conditional(), 1);
  EXPECT_EQ(lot.units[0].verdict->criteria[0].outcome, Outcome::kConditionalPass);
  EXPECT_TRUE(lot.units[0].verdict->criteria[0].pass);
  EXPECT_EQ(lot.units[1].verdict->criteria[0].outcome, Outcome::kConditionalFail);
  EXPECT_EQ(lot.units[2].verdict->Conditional(), 0);
  // and a merge carries it
  const std::string copy = FreshSqliteStore("judgement_copy");
  MergeStores({target}, copy);
  ResultsStore merged(copy);
  EXPECT_EQ(merged.LatestOfLot("lot-j")[1].figures[0].judgement, "conditional fail");
}

TEST(StoreTest, AVersion2StoreGainsItsLatestFitsKeepingEveryRowAndEveryAnswer) {
  const std::string target = FreshStore("v2");
  std::vector<StoredFit> before;
  std::string answers;
  {
    ResultsStore store(target);
    for (const StoredFit& fit : ShuffledHistory()) store.Record(fit);
    before = store.All();
    answers = RecomputedAnswers(&store, kShuffledLots);
  }
  // The store as version 2 wrote it: no latest_fits, latest_figures or judgement.
  ExecuteOnStore(target,
                 std::string("DROP TABLE latest_fits; DROP TABLE latest_figures; ALTER TABLE "
                             "figures DROP COLUMN judgement; UPDATE schema_version SET version = 2;") +
                     (StoreBackend() == "sqlite" ? " PRAGMA user_version = 2;" : ""));
  ResultsStore store(target);
  const std::vector<StoredFit> after = store.All();
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(after[i].id, before[i].id);
    EXPECT_EQ(FitKey(after[i]), FitKey(before[i]));
    EXPECT_EQ(after[i].figures.size(), before[i].figures.size());
  }
  EXPECT_EQ(Answers(&store, kShuffledLots), answers);
  store.Record(MakeFit("SN0", "lot-a", "2026-12-01T00:00:00Z", 7.0, "PASS"));  // and it keeps them
  EXPECT_EQ(Answers(&store, kShuffledLots), RecomputedAnswers(&store, kShuffledLots));
}

TEST(StoreTest, MergeIsIdempotent) {
  const std::string into = FreshStore("merge_into");
  const std::vector<std::string> sources = TwoStationStores();
  const std::vector<MergeResult> first = MergeStores(sources, into);
  ASSERT_EQ(first.size(), 2u);
  EXPECT_EQ(first[0].fits, 2);
  EXPECT_EQ(first[0].added, 2);
  EXPECT_EQ(first[1].added, 1);  // SN2's fit came from station a already
  const std::vector<StoredFit> before = ResultsStore(into).All();
  ASSERT_EQ(before.size(), 3u);
  const std::vector<MergeResult> second = MergeStores(sources, into);
  EXPECT_EQ(second[0].added + second[1].added, 0);
  const std::vector<StoredFit> after = ResultsStore(into).All();
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(FitKey(after[i]), FitKey(before[i]));
    EXPECT_EQ(after[i].id, before[i].id);
    EXPECT_EQ(after[i].figures.size(), before[i].figures.size());
  }
  EXPECT_EQ(ResultsStore(into).Yield("lot-m")[0].units, 3);
}

}  // namespace
}  // namespace imufit

namespace imufit {
namespace {

// Issue 29 item 6: a unit's row as the factory records it, on both backends: fits.fit_options
// filled, the committed files as attachments, the figures' U as stated (not 2 sigma), and a unit
// recorded without its fit in hand (a batch's unchanged unit) at its calibration's time, so that
// recording it again (a new store, then a merge) is the same fit. The run's lot is known.
TEST(StoreTest, AUnitsRowHoldsItsFitOptionsAttachmentsUAndCalibrationTime) {
  const std::string target = FreshStore("certified");
  constexpr double kStatedU = 0.019;  // above 2 x sigma: the budget's, with Type B
  const auto record = [&](const std::string& into) {
    ResultsStore store(into);
    CertifySettings settings;
    settings.store = &store;
    settings.lot = "lot-c";
    settings.software = "imufit test";
    settings.fit_options = "fitted=gyro.bias,gyro.scale; loss=huber";
    UnitOutcome unit;
    unit.unit = "u1";
    unit.serial = "SN-C";
    unit.status = UnitStatus::kFitted;
    unit.skipped = true;
    unit.calibrated_utc = "2026-03-01T10:00:00Z";
    unit.calibration_yaml = "calibration of SN-C\n";
    unit.plan_sha256 = std::string(64, '1');
    unit.samples_sha256 = std::string(64, '4');
    unit.attachments = {{"calibration", "out/u1/calibration.yaml", Sha256Hex(unit.calibration_yaml)}};
    Figure figure = MakeFigure("gyro_scale_per_dps.x", "gyro.scale.x", "raw/(deg/s)", 939.6, 0.0015);
    figure.expanded = kStatedU;
    unit.figures = {figure};
    EXPECT_TRUE(RecordUnit(settings, &unit)) << unit.message;
  };
  record(target);
  ResultsStore store(target);
  const std::vector<StoredFit> fits = store.BySerial("SN-C");
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0].fit_options, "fitted=gyro.bias,gyro.scale; loss=huber");
  EXPECT_EQ(fits[0].time_utc, "2026-03-01T10:00:00Z") << "the calibration's time, not the recording's";
  ASSERT_EQ(fits[0].attachments.size(), 1u);
  EXPECT_EQ(fits[0].attachments[0].kind, "calibration");
  EXPECT_EQ(fits[0].attachments[0].sha256, Sha256Hex("calibration of SN-C\n"));
  ASSERT_EQ(fits[0].figures.size(), 1u);
  EXPECT_EQ(fits[0].figures[0].expanded_u, kStatedU);
  ASSERT_EQ(store.Trend("gyro_scale_per_dps.x", "SN-C").size(), 1u);
  EXPECT_EQ(store.Trend("gyro_scale_per_dps.x", "SN-C")[0].expanded_u, kStatedU);
  EXPECT_EQ(store.LotOfRun(fits[0]).value_or(""), "lot-c");
  StoredFit elsewhere = fits[0];
  elsewhere.samples_sha256 = std::string(64, '5');
  EXPECT_FALSE(store.LotOfRun(elsewhere).has_value());
  // Recorded again (the same unchanged unit, later): the same fit, one row.
  record(target);
  EXPECT_EQ(ResultsStore(target).CountFits(), 1);
}

}  // namespace
}  // namespace imufit
