#include "imufit/factory/store.h"

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <thread>

#include "imufit/io/error.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) statement_ = nullptr;
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool ok() const { return statement_ != nullptr; }
  void Bind(int index, const std::string& text) {
    sqlite3_bind_text(statement_, index, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
  }
  void Bind(int index, double value) { sqlite3_bind_double(statement_, index, value); }
  void Bind(int index, int64_t value) { sqlite3_bind_int64(statement_, index, value); }
  // SQLITE_ROW, SQLITE_DONE or an error code.
  int Step() { return sqlite3_step(statement_); }
  std::string Text(int column) const {
    const unsigned char* text = sqlite3_column_text(statement_, column);
    return text ? reinterpret_cast<const char*>(text) : "";
  }
  double Double(int column) const { return sqlite3_column_double(statement_, column); }
  int64_t Integer(int column) const { return sqlite3_column_int64(statement_, column); }
  void Reset() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

constexpr const char* kSchema = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE fits (
  id INTEGER PRIMARY KEY,
  serial TEXT NOT NULL, unit TEXT NOT NULL, lot TEXT NOT NULL, time_utc TEXT NOT NULL, software TEXT NOT NULL,
  plan_sha256 TEXT NOT NULL, samples_sha256 TEXT NOT NULL, limits_sha256 TEXT NOT NULL,
  status TEXT NOT NULL, verdict TEXT NOT NULL, message TEXT NOT NULL, calibration_yaml TEXT NOT NULL);
CREATE INDEX fits_serial ON fits (serial, time_utc);
CREATE INDEX fits_lot ON fits (lot, unit);
CREATE TABLE figures (
  fit_id INTEGER NOT NULL REFERENCES fits (id), name TEXT NOT NULL, coefficient TEXT NOT NULL,
  unit TEXT NOT NULL, value REAL NOT NULL, sigma REAL NOT NULL, PRIMARY KEY (fit_id, name));
)sql";

}  // namespace

ResultsStore::ResultsStore(const std::string& path, StoreAccess access) : path_(path) {
  struct stat status;
  const bool exists = ::stat(path.c_str(), &status) == 0;
  if (!exists && access == StoreAccess::kRead) {
    throw InputError(path, "no such results store (imufit fit --store and imufit batch --store create one)");
  }
  // As for outputs (output_file.h): a file without write permission is not written, even by root.
  if (exists && access == StoreAccess::kRecord &&
      ((status.st_mode & 0222) == 0 || ::access(path.c_str(), W_OK) != 0)) {
    throw InputError(path,
                     "the results store is read-only: imufit records every fit in it (make it "
                     "writable, or give another --store)");
  }
  const int flags =
      access == StoreAccess::kRead ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  if (sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw InputError(path, "cannot open the results store: " + message);
  }
  try {
    if (access == StoreAccess::kRecord && sqlite3_db_readonly(db_, "main") == 1) {
      throw InputError(path,
                       "the results store cannot be written (a read-only file system?): imufit "
                       "records every fit in it (give another --store)");
    }
    Open(access);
  } catch (...) {
    sqlite3_close(db_);  // the destructor does not run for a constructor that throws
    db_ = nullptr;
    throw;
  }
}

void ResultsStore::Open(StoreAccess access) {
  sqlite3_busy_timeout(db_, kStoreBusyWaitSeconds * 1000);
  if (access == StoreAccess::kRead) {
    CheckVersion();
    return;
  }
  // Changing the journal mode takes the database exclusively and does not wait on its own.
  ExecuteWaiting("PRAGMA journal_mode = WAL");
  Execute("PRAGMA synchronous = NORMAL");  // durable across a process crash; WAL keeps it consistent
  Execute("PRAGMA foreign_keys = ON");
  ExecuteWaiting("BEGIN IMMEDIATE");  // another process creating the schema finishes first
  Statement tables(db_, "SELECT count(*) FROM sqlite_master WHERE type = 'table'");
  if (!tables.ok() || tables.Step() != SQLITE_ROW) Fail("not an SQLite database");
  if (tables.Integer(0) == 0) {
    Execute(kSchema);
    Execute("INSERT INTO schema_version (version) VALUES (" + std::to_string(kStoreSchemaVersion) + ")");
    Execute("PRAGMA user_version = " + std::to_string(kStoreSchemaVersion));
  }
  CheckVersion();
  Execute("COMMIT");
}

void ResultsStore::CheckVersion() {
  const auto refuse = [&](int64_t found) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // harmless outside a transaction
    throw InputError(path_, "results store schema version " + std::to_string(found) +
                                " is not supported (this imufit reads and writes version " +
                                std::to_string(kStoreSchemaVersion) + "; use the imufit that wrote it)");
  };
  Statement user_version(db_, "PRAGMA user_version");
  if (!user_version.ok() || user_version.Step() != SQLITE_ROW) Fail("not an SQLite database");
  if (user_version.Integer(0) > kStoreSchemaVersion) refuse(user_version.Integer(0));
  Statement version(db_, "SELECT version FROM schema_version");
  if (!version.ok() || version.Step() != SQLITE_ROW) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw InputError(path_, "not an imufit results store (no schema_version table)");
  }
  const int64_t found = version.Integer(0);
  if (found > kStoreSchemaVersion || found < 1) refuse(found);
}

void ResultsStore::ExecuteWaiting(const std::string& sql) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(kStoreBusyWaitSeconds);
  for (;;) {
    const int code = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr);
    if (code == SQLITE_OK) return;
    if (code != SQLITE_BUSY && code != SQLITE_LOCKED) Fail("results store");
    if (std::chrono::steady_clock::now() > give_up) {
      Fail("results store (held by another process for " + std::to_string(kStoreBusyWaitSeconds) + " s)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

ResultsStore::~ResultsStore() { sqlite3_close(db_); }

void ResultsStore::Fail(const std::string& what) {
  const std::string message = what + ": " + sqlite3_errmsg(db_);
  sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // harmless when no transaction is open
  throw InputError(path_, message);
}

void ResultsStore::Execute(const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    if (sql != "ROLLBACK") sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw InputError(path_, "results store: " + message);
  }
}

int64_t ResultsStore::Record(const StoredFit& fit, const std::function<void()>& before_commit) {
  const std::lock_guard<std::mutex> lock(record_mutex_);
  ExecuteWaiting("BEGIN IMMEDIATE");
  int64_t id = 0;
  {
    Statement insert(db_,
                     "INSERT INTO fits (serial, unit, lot, time_utc, software, plan_sha256, samples_sha256, "
                     "limits_sha256, status, verdict, message, calibration_yaml) "
                     "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)");
    if (!insert.ok()) Fail("preparing the insert");
    const std::string* texts[] = {&fit.serial,         &fit.unit,          &fit.lot,
                                  &fit.time_utc,       &fit.software,      &fit.plan_sha256,
                                  &fit.samples_sha256, &fit.limits_sha256, &fit.status,
                                  &fit.verdict,        &fit.message,       &fit.calibration_yaml};
    for (int i = 0; i < 12; ++i) insert.Bind(i + 1, *texts[i]);
    if (insert.Step() != SQLITE_DONE) Fail("recording the fit");
    id = sqlite3_last_insert_rowid(db_);
    Statement figure(db_,
                     "INSERT INTO figures (fit_id, name, coefficient, unit, value, sigma) VALUES (?1, ?2, "
                     "?3, ?4, ?5, ?6)");
    if (!figure.ok()) Fail("preparing the insert");
    for (const Figure& f : fit.figures) {
      figure.Bind(1, id);
      figure.Bind(2, f.name);
      figure.Bind(3, f.coefficient);
      figure.Bind(4, f.unit);
      figure.Bind(5, f.value);
      figure.Bind(6, f.sigma);
      if (figure.Step() != SQLITE_DONE) Fail("recording figure " + f.name);
      figure.Reset();
    }
  }
  std::optional<SignalsDeferred> deferred;  // the files and the row: both, even on Ctrl-C
  if (before_commit) {
    deferred.emplace();
    try {
      before_commit();
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
  }
  Execute("COMMIT");
  return id;
}

bool ResultsStore::HasUnit(const std::string& lot, const std::string& unit) {
  Statement query(db_, "SELECT 1 FROM fits WHERE lot = ?1 AND unit = ?2 LIMIT 1");
  if (!query.ok()) Fail("querying fits");
  query.Bind(1, lot);
  query.Bind(2, unit);
  return query.Step() == SQLITE_ROW;
}

std::vector<StoredFit> ResultsStore::BySerial(const std::string& serial) {
  std::vector<StoredFit> fits;
  Statement query(
      db_,
      "SELECT id, serial, unit, lot, time_utc, software, plan_sha256, samples_sha256, limits_sha256, "
      "status, verdict, message, calibration_yaml FROM fits WHERE serial = ?1 ORDER BY time_utc, id");
  if (!query.ok()) Fail("querying fits");
  query.Bind(1, serial);
  while (query.Step() == SQLITE_ROW) {
    StoredFit f;
    f.id = query.Integer(0);
    std::string* texts[] = {
        &f.serial,         &f.unit,          &f.lot,    &f.time_utc, &f.software, &f.plan_sha256,
        &f.samples_sha256, &f.limits_sha256, &f.status, &f.verdict,  &f.message,  &f.calibration_yaml};
    for (int i = 0; i < 12; ++i) *texts[i] = query.Text(i + 1);
    fits.push_back(std::move(f));
  }
  for (StoredFit& f : fits) {
    Statement figures(
        db_, "SELECT name, coefficient, unit, value, sigma FROM figures WHERE fit_id = ?1 ORDER BY rowid");
    if (!figures.ok()) Fail("querying figures");
    figures.Bind(1, f.id);
    while (figures.Step() == SQLITE_ROW) {
      f.figures.push_back(
          {figures.Text(0), figures.Text(1), figures.Text(2), figures.Double(3), figures.Double(4)});
    }
  }
  return fits;
}

std::vector<LotYield> ResultsStore::Yield(const std::string& lot) {
  // Each unit of a lot counts once, by its latest fit (a unit refitted after a fix counts as fixed).
  Statement query(
      db_,
      "SELECT lot, count(*), sum(verdict = 'PASS'), sum(verdict = 'FAIL'), sum(status != 'fitted') "
      "FROM fits f WHERE id = (SELECT max(id) FROM fits g WHERE g.lot = f.lot AND g.unit = f.unit) "
      "AND lot != '' AND (?1 = '' OR lot = ?1) GROUP BY lot ORDER BY min(time_utc), lot");
  if (!query.ok()) Fail("querying the yield");
  query.Bind(1, lot);
  std::vector<LotYield> yields;
  while (query.Step() == SQLITE_ROW) {
    yields.push_back({query.Text(0), static_cast<int>(query.Integer(1)), static_cast<int>(query.Integer(2)),
                      static_cast<int>(query.Integer(3)), static_cast<int>(query.Integer(4))});
  }
  return yields;
}

std::vector<TrendPoint> ResultsStore::Trend(const std::string& figure, const std::string& serial) {
  Statement query(
      db_,
      "SELECT f.time_utc, f.serial, f.lot, g.value, g.sigma, g.unit FROM figures g JOIN fits f ON f.id = "
      "g.fit_id "
      "WHERE (g.name = ?1 OR g.coefficient = ?1) AND (?2 = '' OR f.serial = ?2) ORDER BY f.time_utc, f.id");
  if (!query.ok()) Fail("querying the trend");
  query.Bind(1, figure);
  query.Bind(2, serial);
  std::vector<TrendPoint> points;
  while (query.Step() == SQLITE_ROW) {
    points.push_back(
        {query.Text(0), query.Text(1), query.Text(2), query.Double(3), query.Double(4), query.Text(5)});
  }
  return points;
}

std::vector<LotValue> ResultsStore::LotValues(const std::string& figure) {
  Statement query(
      db_,
      "SELECT f.lot, f.unit, g.value, g.sigma, g.unit FROM fits f JOIN figures g ON g.fit_id = f.id "
      "WHERE f.id = (SELECT max(id) FROM fits h WHERE h.lot = f.lot AND h.unit = f.unit) "
      "AND f.lot != '' AND f.status = 'fitted' AND (g.name = ?1 OR g.coefficient = ?1) "
      "ORDER BY f.lot, f.unit");
  if (!query.ok()) Fail("querying a figure per lot");
  query.Bind(1, figure);
  std::vector<LotValue> values;
  while (query.Step() == SQLITE_ROW) {
    values.push_back({query.Text(0), query.Text(1), query.Double(2), query.Double(3), query.Text(4)});
  }
  return values;
}

}  // namespace imufit
