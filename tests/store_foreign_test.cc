// The store and databases that are not imufit's, on the backend under test: another application's
// database is refused untouched (no tables added, no journal mode changed), a read creates and
// writes nothing (and still reads a read-only store of an older schema), a merge refuses its own
// destination and a refused merge creates nothing, and no message ever holds a password.
#include <libpq-fe.h>
#include <sqlite3.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/io/error.h"
#include "imufit/store/store.h"
#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

// Runs `sql` on the store's database directly (not through imufit); returns the first column of
// every row it returns, as text.
std::vector<std::string> Sql(const std::string& target, const std::string& sql) {
  std::vector<std::string> rows;
  if (!IsPostgresStore(target)) {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open(target.c_str(), &db), SQLITE_OK);
    const auto collect = [](void* out, int, char** values, char**) {
      static_cast<std::vector<std::string>*>(out)->push_back(values[0] ? values[0] : "");
      return 0;
    };
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), collect, &rows, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    sqlite3_close(db);
    return rows;
  }
  PGconn* connection = PQconnectdb(target.c_str());
  EXPECT_EQ(PQstatus(connection), CONNECTION_OK) << PQerrorMessage(connection);
  PGresult* result = PQexec(connection, sql.c_str());
  const ExecStatusType status = PQresultStatus(result);
  EXPECT_TRUE(status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) << PQresultErrorMessage(result);
  for (int i = 0; status == PGRES_TUPLES_OK && i < PQntuples(result); ++i)
    rows.push_back(PQgetvalue(result, i, 0));
  PQclear(result);
  PQfinish(connection);
  return rows;
}

std::vector<std::string> Tables(const std::string& target) {
  return Sql(target, IsPostgresStore(target)
                         ? "SELECT table_name FROM information_schema.tables WHERE table_schema = "
                           "current_schema() ORDER BY 1"
                         : "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name");
}

// The message of the InputError that opening `target` with `access` throws ("" when it opens).
std::string OpenError(const std::string& target, StoreAccess access) {
  try {
    ResultsStore store(target, access);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(StoreForeignTest, AnotherApplicationsDatabaseIsRefusedUntouched) {
  const std::string target = FreshStore("foreign");
  Sql(target, "CREATE TABLE orders (id INTEGER PRIMARY KEY, item TEXT); INSERT INTO orders VALUES (1, 'x');");
  const std::vector<std::string> tables = Tables(target);
  const std::vector<std::string> journal =
      IsPostgresStore(target) ? std::vector<std::string>{} : Sql(target, "PRAGMA journal_mode");
  for (const StoreAccess access : {StoreAccess::kRecord, StoreAccess::kRead}) {
    const std::string error = OpenError(target, access);
    EXPECT_NE(error.find("not an imufit results store: it holds 1 table of another application (orders)"),
              std::string::npos)
        << error;
    EXPECT_NE(error.find("give another --store"), std::string::npos) << error;
  }
  EXPECT_EQ(Tables(target), tables);
  if (!IsPostgresStore(target)) {
    EXPECT_EQ(Sql(target, "PRAGMA journal_mode"), journal) << "the journal mode is the application's";
    EXPECT_FALSE(fs::exists(target + "-wal"));
  }
  EXPECT_EQ(Sql(target, "SELECT item FROM orders"), std::vector<std::string>{"x"});
}

TEST(StoreForeignTest, AReadCreatesNothingInAnEmptyDatabase) {
  const std::string target = FreshStore("empty_read");
  if (!IsPostgresStore(target)) Sql(target, "PRAGMA user_version = 0");  // an empty SQLite file
  const std::string error = OpenError(target, StoreAccess::kRead);
  EXPECT_NE(error.find("holds no results store: the database is empty"), std::string::npos) << error;
  EXPECT_TRUE(Tables(target).empty());
  // Recording into the same empty database is what it is for.
  ResultsStore store(target);
  store.Record(MakeFit("SN1", "lot-e", "2026-05-01T00:00:00Z", 1.0, "PASS"));
  EXPECT_EQ(ResultsStore(target, StoreAccess::kRead).CountFits(), 1);
}

// Schema versions 2 (no latest_fits, no latest_figures, no judgement) and 3 (no latest_figures, no
// judgement), read-only: queried through a private copy, the file left as it was (issue 29 item 6).
TEST(StoreForeignTest, AReadOfAnOlderSchemaLeavesItAsItWasAndAReadOnlyOneCanBeQueried) {
  for (const int version : {2, 3}) {
    SCOPED_TRACE("schema version " + std::to_string(version));
    const std::string target = FreshStore("old_read_" + std::to_string(version));
    {
      ResultsStore store(target);
      store.Record(MakeFit("SN1", "lot-r", "2026-05-01T00:00:00Z", 1.0, "PASS"));
      store.Record(MakeFit("SN2", "lot-r", "2026-05-01T00:01:00Z", 2.0, "FAIL"));
    }
    // As that schema version wrote it.
    Sql(target,
        std::string(version == 2 ? "DROP TABLE latest_fits; " : "") +
            "DROP TABLE latest_figures; ALTER TABLE figures DROP COLUMN judgement; "
            "UPDATE schema_version SET version = " +
            std::to_string(version) + ";" +
            (IsPostgresStore(target) ? "" : " PRAGMA user_version = " + std::to_string(version) + ";"));
    const std::vector<std::string> tables = Tables(target);
    if (!IsPostgresStore(target)) fs::permissions(target, fs::perms::owner_read | fs::perms::group_read);
    {
      ResultsStore store(target, StoreAccess::kRead);
      ASSERT_EQ(store.Yield("lot-r").size(), 1u);
      EXPECT_EQ(store.Yield("lot-r")[0].units, 2);
      EXPECT_EQ(store.Yield("lot-r")[0].passed, 1);
      ASSERT_EQ(store.LotStats({"gyro_bias_dps.x"}).size(), 1u);
      EXPECT_DOUBLE_EQ(store.LotStats({"gyro_bias_dps.x"})[0].mean, 1.5);
      EXPECT_EQ(store.LatestOfLot("lot-r").size(), 2u);
    }
    EXPECT_EQ(Tables(target), tables) << "a read migrates a private copy only";
    EXPECT_EQ(Sql(target, "SELECT version FROM schema_version"),
              std::vector<std::string>{std::to_string(version)});
    if (!IsPostgresStore(target)) {
      fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write);
      const std::string error = OpenError(target, StoreAccess::kRecord);
      EXPECT_EQ(error, "") << "recording migrates it for good";
      EXPECT_EQ(Sql(target, "SELECT version FROM schema_version"),
                std::vector<std::string>{std::to_string(kStoreSchemaVersion)});
    }
  }
}

TEST(StoreForeignTest, AMergeIntoItselfIsRefusedAndARefusedMergeCreatesNothing) {
  const std::string station = FreshSqliteStore("merge_self");
  ResultsStore(station).Record(MakeFit("SN1", "lot-s", "2026-05-01T00:00:00Z", 1.0, "PASS"));
  try {
    MergeStores({station}, station);
    ADD_FAILURE() << "a store merged into itself";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is the store merged into (--into)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ResultsStore(station, StoreAccess::kRead).CountFits(), 1);

  // A newer schema, then a truncated file: refused before the destination exists.
  const std::string newer = FreshSqliteStore("merge_newer");
  ResultsStore(newer).Record(MakeFit("SN2", "lot-s", "2026-05-01T00:01:00Z", 2.0, "PASS"));
  Sql(newer, "UPDATE schema_version SET version = 99; PRAGMA user_version = 99;");
  const std::string truncated = FreshSqliteStore("merge_truncated");
  {
    ResultsStore whole(truncated);
    for (int i = 0; i < 40; ++i) {
      whole.Record(MakeFit("SN" + std::to_string(10 + i), "lot-t", "2026-05-02T00:00:00Z", i, "PASS"));
    }
  }
  fs::resize_file(truncated, fs::file_size(truncated) / 2);
  for (const std::string& source : {newer, truncated}) {
    const std::string destination = FreshStore("merge_dest");
    const std::vector<std::string> before =
        IsPostgresStore(destination) ? Tables(destination) : std::vector<std::string>{};
    EXPECT_THROW(MergeStores({station, source}, destination), InputError) << source;
    if (IsPostgresStore(destination)) {
      EXPECT_EQ(Tables(destination), before) << source;
    } else {
      EXPECT_FALSE(fs::exists(destination)) << source;
    }
  }
}

TEST(StoreForeignTest, NoMessageHoldsAPassword) {
  for (const std::string target :
       {"postgresql://u:s3cretPW@[::1:5432/db", "postgresql://u:s3cretPW@/db?host=[bad", "password=s3cretPW",
        "host=/nonexistent password = 's3cret PW'"}) {
    const std::string error = OpenError(target, StoreAccess::kRead);
    EXPECT_NE(error, "") << target;
    EXPECT_EQ(error.find("s3cret"), std::string::npos) << error;
  }
}

// `history --lot NAME` with a lot the store does not hold is refused whatever is printed (as
// `--html` and `imufit lot` refuse it), naming the lots it holds.
TEST(StoreForeignTest, HistoryOfALotTheStoreDoesNotHoldIsRefusedInEveryForm) {
  const std::string target = FreshStore("history_unknown");
  ResultsStore(target).Record(MakeFit("SN1", "lot-h", "2026-05-01T00:00:00Z", 1.0, "PASS"));
  const std::string base = FreshSqliteStore("history_unknown_output");
  for (const std::vector<std::string>& form : {std::vector<std::string>{}, {"--csv"}}) {
    std::vector<std::string> args = {"history", target, "--lot", "LOT-UNKNOWN"};
    args.insert(args.end(), form.begin(), form.end());
    const testing::RunResult r = testing::RunProgram(IMUFIT_EXE, args, base + ".out", base + ".err");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("no lot named \"LOT-UNKNOWN\" (it holds: lot-h)"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
}

}  // namespace
}  // namespace imufit
