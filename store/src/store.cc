#include "imufit/store/store.h"

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <thread>

#include "imufit/base/verdict.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "sql_connection.h"

namespace imufit {
namespace {

// A name of a name table (base/verdict.h) as an SQL string literal: the store's columns hold these
// names, and its queries compare with them, never with a literal typed again. (The names are plain
// words: nothing to escape.)
template <typename E, size_t N>
std::string SqlName(const EnumName<E> (&names)[N], E value) {
  return std::string("'") + NameOf(names, value) + "'";
}

InputError UnsupportedVersion(const std::string& name, int64_t found) {
  return InputError(name, "results store schema version " + std::to_string(found) +
                              " is not supported (this imufit reads and writes version " +
                              std::to_string(kStoreSchemaVersion) + "; use the imufit that wrote it)");
}

// Why a database that holds other tables is not used: it is not imufit's.
std::string ForeignDatabaseMessage(const std::vector<std::string>& tables) {
  constexpr size_t kNamed = 4;  // tables named in the message; the rest are counted
  std::string names;
  for (size_t i = 0; i < tables.size() && i < kNamed; ++i) names += (i ? ", " : "") + tables[i];
  if (tables.size() > kNamed) names += ", ...";
  return "not an imufit results store: it holds " + std::to_string(tables.size()) +
         (tables.size() == 1 ? " table" : " tables") + " of another application (" + names +
         "), left as they are; imufit creates its store only in a new file or an empty database (give "
         "another --store)";
}

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

 private:
  sqlite3_stmt* statement_ = nullptr;
};

class SqliteRow : public SqlRow {
 public:
  explicit SqliteRow(const Statement& statement) : statement_(statement) {}
  std::string Text(int column) const override { return statement_.Text(column); }
  double Double(int column) const override { return statement_.Double(column); }
  int64_t Integer(int column) const override { return statement_.Integer(column); }

 private:
  const Statement& statement_;
};

// The embedded backend: one SQLite file in WAL mode. Several processes may open, create and write
// one file at once: a busy database is waited for (up to kStoreBusyWaitSeconds), never an error.
class SqliteConnection : public SqlConnection {
 public:
  SqliteConnection(const std::string& path, StoreAccess access) : path_(path) {
    struct stat status;
    const bool exists = ::stat(path.c_str(), &status) == 0;
    if (!exists && access == StoreAccess::kRead) {
      throw InputError(path,
                       "no such results store (imufit fit --store and imufit batch --store create one)");
    }
    // As for outputs (output_file.h): a file without write permission is not written, even by root.
    const bool writable = exists && (status.st_mode & 0222) != 0 && ::access(path.c_str(), W_OK) == 0;
    if (exists && !writable && access == StoreAccess::kRecord) {
      throw InputError(path,
                       "the results store is read-only: imufit records every fit in it (make it "
                       "writable, or give another --store)");
    }
    // Read access writes only to migrate an older store, when the file may be written.
    const int flags = access == StoreAccess::kRecord ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE
                      : writable                     ? SQLITE_OPEN_READWRITE
                                                     : SQLITE_OPEN_READONLY;
    if (sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
      const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw InputError(path, "cannot open the results store: " + message);
    }
    try {
      sqlite3_busy_timeout(db_, kStoreBusyWaitSeconds * 1000);
      if (access == StoreAccess::kRecord && sqlite3_db_readonly(db_, "main") == 1) {
        throw InputError(path,
                         "the results store cannot be written (a read-only file system?): imufit "
                         "records every fit in it (give another --store)");
      }
      CheckUserVersion();
      writable_ = flags != SQLITE_OPEN_READONLY;
      Execute("PRAGMA foreign_keys = ON");
    } catch (...) {
      sqlite3_close(db_);  // the destructor does not run for a constructor that throws
      throw;
    }
  }
  ~SqliteConnection() override { sqlite3_close(db_); }

  bool Writable() const override { return writable_; }

  void Ready() override {
    if (!writable_) return;
    // Changing the journal mode takes the database exclusively and does not wait on its own.
    ExecuteWaiting("PRAGMA journal_mode = WAL");
    Execute("PRAGMA synchronous = NORMAL");  // durable across a process crash; WAL keeps it consistent
  }

  // The whole file copied into an in-memory database (SQLite's online backup), which the reader
  // then migrates and queries; the file is not written.
  void Detach() override {
    sqlite3* memory = nullptr;
    if (sqlite3_open_v2(":memory:", &memory, SQLITE_OPEN_READWRITE | SQLITE_OPEN_FULLMUTEX, nullptr) !=
        SQLITE_OK) {
      sqlite3_close(memory);
      throw InputError(path_, "results store: cannot open an in-memory copy to read it");
    }
    sqlite3_backup* backup = sqlite3_backup_init(memory, "main", db_, "main");
    const int step = backup ? sqlite3_backup_step(backup, -1) : SQLITE_ERROR;
    sqlite3_backup_finish(backup);
    if (step != SQLITE_DONE) {
      const std::string message = sqlite3_errmsg(memory);
      sqlite3_close(memory);
      throw InputError(path_, "results store: cannot copy it to read it: " + message);
    }
    sqlite3_close(db_);
    db_ = memory;
    writable_ = false;  // the copy is never written back: no WAL for it either
    Execute("PRAGMA foreign_keys = ON");
  }

  std::vector<std::string> Tables() override {
    std::vector<std::string> tables;
    Query("SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%' ORDER BY name",
          {}, [&](const SqlRow& row) { tables.push_back(row.Text(0)); });
    return tables;
  }

  const std::string& name() const override { return path_; }
  const char* backend() const override { return "sqlite"; }
  const char* AutoIdType() const override { return "INTEGER PRIMARY KEY"; }
  const char* TextType() const override { return "TEXT"; }

  void Execute(const std::string& sql) override {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      const std::string message = error ? error : "unknown error";
      sqlite3_free(error);
      if (sql != "ROLLBACK") Rollback();
      throw InputError(path_, "results store: " + message);
    }
  }

  void Query(const std::string& sql, const std::vector<SqlValue>& parameters,
             const std::function<void(const SqlRow&)>& row) override {
    Statement statement(db_, sql);
    if (!statement.ok()) Fail("preparing a statement");
    for (size_t i = 0; i < parameters.size(); ++i) {
      std::visit([&](const auto& value) { statement.Bind(static_cast<int>(i) + 1, value); }, parameters[i]);
    }
    const SqliteRow current(statement);
    for (;;) {
      const int step = statement.Step();
      if (step == SQLITE_DONE) return;
      if (step != SQLITE_ROW) Fail("running a statement");
      row(current);
    }
  }

  // Another process's transaction (creating the schema, recording a unit) finishes first.
  void Begin(bool /*exclusive*/) override { ExecuteWaiting("BEGIN IMMEDIATE"); }
  void SchemaWritten(int version) override { Execute("PRAGMA user_version = " + std::to_string(version)); }
  void Commit() override { Execute("COMMIT"); }
  void Rollback() override { sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr); }

  bool HasTable(const std::string& table) override {
    bool found = false;
    Query("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?1", {table},
          [&](const SqlRow&) { found = true; });
    return found;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    const std::string message = what + ": " + sqlite3_errmsg(db_);
    Rollback();
    throw InputError(path_, "results store: " + message);
  }

  // Execute(), waiting while another process holds the database (SQLITE_BUSY, SQLITE_LOCKED).
  void ExecuteWaiting(const std::string& sql) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(kStoreBusyWaitSeconds);
    for (;;) {
      const int code = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr);
      if (code == SQLITE_OK) return;
      if (code != SQLITE_BUSY && code != SQLITE_LOCKED) Fail("results store");
      if (std::chrono::steady_clock::now() > give_up) {
        Fail("held by another process for " + std::to_string(kStoreBusyWaitSeconds) + " s");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  // SQLite's user_version holds the schema version too: a store of a newer imufit is refused
  // before anything reads its tables.
  void CheckUserVersion() {
    Statement version(db_, "PRAGMA user_version");
    if (!version.ok() || version.Step() != SQLITE_ROW) Fail("not an SQLite database");
    const int64_t found = version.Integer(0);
    if (found > kStoreSchemaVersion) throw UnsupportedVersion(path_, found);
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  bool writable_ = false;
};

// The schema, once for both backends: TEXT and the numbered id are the backend's (TextType(),
// AutoIdType()).
constexpr const char* kSchema = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE stations (station TEXT PRIMARY KEY, first_seen_utc TEXT NOT NULL);
CREATE TABLE units (serial TEXT PRIMARY KEY, part_number TEXT NOT NULL, lot TEXT NOT NULL);
CREATE TABLE runs (
  run_key TEXT PRIMARY KEY, serial TEXT NOT NULL REFERENCES units (serial), unit TEXT NOT NULL,
  lot TEXT NOT NULL, station TEXT NOT NULL, acquired_utc TEXT NOT NULL, plan_sha256 TEXT NOT NULL,
  samples_sha256 TEXT NOT NULL);
CREATE TABLE fits (
  id AUTO_ID, fit_key TEXT NOT NULL UNIQUE, run_key TEXT NOT NULL REFERENCES runs (run_key),
  time_utc TEXT NOT NULL, software TEXT NOT NULL, fit_options TEXT NOT NULL, limits_sha256 TEXT NOT NULL,
  status TEXT NOT NULL, verdict TEXT NOT NULL, message TEXT NOT NULL, calibration_yaml TEXT NOT NULL);
CREATE TABLE figures (
  fit_id BIGINT NOT NULL REFERENCES fits (id), position INTEGER NOT NULL, name TEXT NOT NULL,
  coefficient TEXT NOT NULL, unit TEXT NOT NULL, value DOUBLE PRECISION NOT NULL,
  sigma DOUBLE PRECISION NOT NULL, expanded_u DOUBLE PRECISION NOT NULL,
  limit_abs DOUBLE PRECISION NOT NULL, outcome TEXT NOT NULL, judgement TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (fit_id, name));
CREATE TABLE attachments (
  fit_id BIGINT NOT NULL REFERENCES fits (id), kind TEXT NOT NULL, path TEXT NOT NULL,
  sha256 TEXT NOT NULL, PRIMARY KEY (fit_id, kind, path));
CREATE INDEX units_lot ON units (lot);
CREATE INDEX runs_serial ON runs (serial);
CREATE INDEX runs_lot ON runs (lot, unit);
CREATE INDEX runs_station ON runs (station, acquired_utc);
CREATE INDEX fits_run ON fits (run_key, time_utc);
CREATE INDEX fits_time ON fits (time_utc);
CREATE INDEX figures_name ON figures (name, fit_id);
CREATE INDEX figures_coefficient ON figures (coefficient, fit_id);
)sql";

// Each unit's latest fit, kept as fits are recorded (kRecordLatest): the questions about units
// (yield, a lot's page, the values across lots) read it instead of ranking every fit. Added in
// version 3.
constexpr const char* kLatestFitsSchema = R"sql(
CREATE TABLE latest_fits (
  lot TEXT NOT NULL, unit TEXT NOT NULL, fit_id BIGINT NOT NULL REFERENCES fits (id),
  time_utc TEXT NOT NULL, PRIMARY KEY (lot, unit));
)sql";

// The figures of each fitted unit's latest fit, by name and lot (LotStats() reads it in index
// order, one lot after another, instead of 100,000 look-ups per figure): kept with latest_fits in
// the recording transaction (kRefreshLatestFigures; its key serves the unit's refresh). Added in
// version 4. `unit` is the lot's unit (as in latest_fits), `figure_unit` the figure's physical unit.
constexpr const char* kLatestFiguresSchema = R"sql(
CREATE TABLE latest_figures (
  name TEXT NOT NULL, lot TEXT NOT NULL, unit TEXT NOT NULL, figure_unit TEXT NOT NULL,
  value DOUBLE PRECISION NOT NULL, PRIMARY KEY (lot, unit, name));
CREATE INDEX latest_figures_values ON latest_figures (name, lot, value, figure_unit);
)sql";

// The figures of the unit of run ?1 as its latest fit now holds them: removed, then copied from
// that fit when it is fitted (a unit whose latest fit failed has none).
constexpr const char* kDropLatestFigures =
    "DELETE FROM latest_figures WHERE lot = (SELECT lot FROM runs WHERE run_key = ?1) AND "
    "unit = (SELECT unit FROM runs WHERE run_key = ?1)";
const std::string kLatestFiguresSelect =
    "SELECT g.name, l.lot, l.unit, g.unit, g.value FROM latest_fits l JOIN fits f ON f.id = l.fit_id "
    "JOIN figures g ON g.fit_id = l.fit_id WHERE f.status = " +
    SqlName(kUnitStatusNames, UnitStatus::kFitted);
const std::string kRefreshLatestFigures =
    "INSERT INTO latest_figures (name, lot, unit, figure_unit, value) " + kLatestFiguresSelect +
    " AND l.lot = (SELECT lot FROM runs WHERE run_key = ?1) AND l.unit = (SELECT unit FROM runs WHERE "
    "run_key = ?1)";
// Every unit's: how a version 2 or 3 store's latest_figures is filled.
const std::string kFillLatestFigures =
    "INSERT INTO latest_figures (name, lot, unit, figure_unit, value) " + kLatestFiguresSelect;

// A unit's latest fit is its fit with the latest time_utc, of those the one recorded last (the
// highest id); a unit is its run's (lot, unit). One statement, safe with concurrent writers: the
// row is replaced only by a later fit. ?1 the new fit's id, ?2 its time, ?3 its run.
constexpr const char* kRecordLatest =
    "INSERT INTO latest_fits (lot, unit, fit_id, time_utc) SELECT r.lot, r.unit, CAST(?1 AS BIGINT), ?2 "
    "FROM runs r WHERE r.run_key = ?3 ON CONFLICT (lot, unit) DO UPDATE SET fit_id = excluded.fit_id, "
    "time_utc = excluded.time_utc WHERE excluded.time_utc > latest_fits.time_utc OR "
    "(excluded.time_utc = latest_fits.time_utc AND excluded.fit_id > latest_fits.fit_id)";

// The same answer computed from every fit: how a version 2 store's latest_fits is filled.
constexpr const char* kFillLatest =
    "INSERT INTO latest_fits (lot, unit, fit_id, time_utc) SELECT lot, unit, id, time_utc FROM "
    "(SELECT r.lot AS lot, r.unit AS unit, f.id AS id, f.time_utc AS time_utc, ROW_NUMBER() OVER "
    "(PARTITION BY r.lot, r.unit ORDER BY f.time_utc DESC, f.id DESC) AS n FROM fits f "
    "JOIN runs r ON r.run_key = f.run_key) ranked WHERE n = 1";

std::string SchemaFor(const SqlConnection& db, const std::string& schema) {
  std::string sql = schema;
  const auto replace_all = [&](const std::string& from, const std::string& to) {
    for (size_t at = sql.find(from); at != std::string::npos; at = sql.find(from, at + to.size())) {
      sql.replace(at, from.size(), to);
    }
  };
  replace_all(" TEXT", std::string(" ") + db.TextType());
  replace_all("AUTO_ID", db.AutoIdType());
  return sql;
}

// The columns of a fit with its run and unit, in StoredFit order (Fits()).
constexpr const char* kFitColumns =
    "SELECT f.id, r.serial, r.unit, r.lot, u.part_number, r.station, r.acquired_utc, f.time_utc, "
    "f.software, f.fit_options, r.plan_sha256, r.samples_sha256, f.limits_sha256, f.status, f.verdict, "
    "f.message, f.calibration_yaml FROM fits f JOIN runs r ON r.run_key = f.run_key "
    "JOIN units u ON u.serial = r.serial";

std::vector<std::string*> TextFields(StoredFit* f) {
  return {&f->serial,          &f->unit,          &f->lot,      &f->part_number, &f->station,
          &f->acquired_utc,    &f->time_utc,      &f->software, &f->fit_options, &f->plan_sha256,
          &f->samples_sha256,  &f->limits_sha256, &f->status,   &f->verdict,     &f->message,
          &f->calibration_yaml};
}

// Each unit by its latest fit (a unit refitted after a fix counts as fixed): n = 1. A unit is a
// lot's unit, or (lot "") a single fit's samples file.
constexpr const char* kLatestPerUnit =
    "WITH latest AS (SELECT f.id AS id, l.lot AS lot, l.unit AS unit, r.station AS station, "
    "substr(f.time_utc, 1, 7) AS month, f.time_utc AS time_utc, f.status AS status, f.verdict AS verdict "
    "FROM latest_fits l JOIN fits f ON f.id = l.fit_id JOIN runs r ON r.run_key = f.run_key) ";

// The counts of Yield() and YieldBy() over the units of `latest`, after the group's column.
const std::string kYieldCounts =
    ", count(*), sum(CASE WHEN verdict = " + SqlName(kVerdictNames, true) +
    " THEN 1 ELSE 0 END), sum(CASE WHEN verdict = " + SqlName(kVerdictNames, false) +
    " THEN 1 ELSE 0 END), sum(CASE WHEN status <> " + SqlName(kUnitStatusNames, UnitStatus::kFitted) +
    " THEN 1 ELSE 0 END) FROM latest ";

// The sums behind LotStats(), per lot and figure over each unit's latest fit: n, S1 = sum(x - k), S2 =
// sum((x - k)^2), shifted by k, one stored value of the figure, so that an offset common to every
// value (a scale factor of 16384 with a spread of 0.01) cancels before squaring: mean = k + S1 / n,
// variance = (S2 - S1^2 / n) / (n - 1). The same SQL on both backends (SQLite has no stddev_samp).
// kLotReference finds a figure's stored name (?1 a name or a coefficient) and its k.
constexpr const char* kLotReference =
    "SELECT name, value FROM figures WHERE name = ?1 OR coefficient = ?1 LIMIT 1";

// The statement of the sums over `names` stored names: ?1, ?3, ... the names, ?2, ?4, ... their k.
std::string LotSumsSql(size_t names) {
  std::string shift = "CASE name", list;
  for (size_t i = 0; i < names; ++i) {
    const std::string name = "?" + std::to_string(2 * i + 1), k = "?" + std::to_string(2 * i + 2);
    shift += " WHEN " + name + " THEN CAST(" + k + " AS DOUBLE PRECISION)";
    list += (i ? ", " : "") + name;
  }
  return "SELECT lot, name, max(figure_unit), count(*), sum(d), sum(d * d) FROM (SELECT lot, name, "
         "figure_unit, value - " +
         shift + " END AS d FROM latest_figures WHERE lot <> '' AND name IN (" + list +
         ")) v GROUP BY name, lot";
}

class Transaction {
 public:
  Transaction(SqlConnection* db, bool exclusive) : db_(db) { db_->Begin(exclusive); }
  ~Transaction() {
    if (!done_) db_->Rollback();
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void Commit() {
    db_->Commit();
    done_ = true;
  }

 private:
  SqlConnection* db_;
  bool done_ = false;
};

}  // namespace

const StoredFigure* FindFigure(const std::vector<StoredFigure>& figures, const std::string& name) {
  for (const StoredFigure& f : figures) {
    if (f.name == name || f.coefficient == name) return &f;
  }
  return nullptr;
}

// A figure from columns 1..5 of a row: name, coefficient, unit, value, sigma.
StoredFigure StoredFigureOfRow(const SqlRow& row) {
  StoredFigure figure;
  figure.name = row.Text(1);
  figure.coefficient = row.Text(2);
  figure.unit = row.Text(3);
  figure.value = row.Double(4);
  figure.sigma = row.Double(5);
  return figure;
}

std::unique_ptr<SqlConnection> OpenSqlite(const std::string& path, StoreAccess access) {
  return std::make_unique<SqliteConnection>(path, access);
}

ResultsStore::ResultsStore(const std::string& target, StoreAccess access)
    : path_(target),
      access_(access),
      db_(IsPostgresStore(target) ? ConnectPostgres(target) : OpenSqlite(target, access)) {
  path_ = db_->name();
  Open();
}

ResultsStore::~ResultsStore() = default;

const char* ResultsStore::backend() const { return db_->backend(); }

void ResultsStore::Open() {
  int64_t found = -1;
  {
    Transaction transaction(db_.get(), /*exclusive=*/true);
    if (!db_->HasTable("schema_version")) {
      // The schema goes only into a new file or an empty database, and never on a read: a database
      // of another application is refused before anything in it changes (its journal mode included).
      const std::vector<std::string> tables = db_->Tables();
      if (!tables.empty()) throw InputError(path_, ForeignDatabaseMessage(tables));
      if (access_ == StoreAccess::kRead) {
        throw InputError(path_,
                         "holds no results store: the database is empty (imufit fit --store and imufit "
                         "batch --store create one; a read creates nothing)");
      }
      db_->Execute(SchemaFor(*db_, std::string(kSchema) + kLatestFitsSchema + kLatestFiguresSchema));
      db_->Execute("INSERT INTO schema_version (version) VALUES (" + std::to_string(kStoreSchemaVersion) +
                   ")");
      db_->SchemaWritten(kStoreSchemaVersion);
    }
    db_->Query("SELECT version FROM schema_version", {}, [&](const SqlRow& row) { found = row.Integer(0); });
    if (found > kStoreSchemaVersion || found < 1) throw UnsupportedVersion(path_, found);
    if (found == kStoreSchemaVersion || access_ == StoreAccess::kRecord) {
      Migrate(found);
      transaction.Commit();
    }
  }
  if (found != kStoreSchemaVersion && access_ == StoreAccess::kRead) {
    // A read never writes, and a read-only store of an older schema can still be read: the
    // migration runs on a private copy.
    db_->Detach();
    Transaction transaction(db_.get(), /*exclusive=*/true);
    Migrate(found);
    transaction.Commit();
  }
  db_->Ready();
}

void ResultsStore::Migrate(int64_t from_version) {
  if (from_version == 1) MigrateFromVersion1();  // to the current schema
  if (from_version == 2) MigrateFromVersion2();
  if (from_version == 2 || from_version == 3) MigrateFromVersion3();
}

// Version 1 (SQLite only): fits(id, serial, unit, lot, time_utc, software, plan_sha256,
// samples_sha256, limits_sha256, status, verdict, message, calibration_yaml) and figures(fit_id,
// name, coefficient, unit, value, sigma). Every fit and figure is kept; runs, units and keys are
// derived from them.
void ResultsStore::MigrateFromVersion1() {
  std::vector<StoredFit> fits;
  std::map<int64_t, size_t> by_id;
  db_->Query(
      "SELECT id, serial, unit, lot, time_utc, software, plan_sha256, samples_sha256, limits_sha256, "
      "status, verdict, message, calibration_yaml FROM fits ORDER BY id",
      {}, [&](const SqlRow& row) {
        StoredFit f;
        f.id = row.Integer(0);
        std::string* texts[] = {
            &f.serial,         &f.unit,          &f.lot,    &f.time_utc, &f.software, &f.plan_sha256,
            &f.samples_sha256, &f.limits_sha256, &f.status, &f.verdict,  &f.message,  &f.calibration_yaml};
        for (int i = 0; i < 12; ++i) *texts[i] = row.Text(i + 1);
        by_id[f.id] = fits.size();
        fits.push_back(std::move(f));
      });
  db_->Query("SELECT fit_id, name, coefficient, unit, value, sigma FROM figures ORDER BY fit_id, rowid", {},
             [&](const SqlRow& row) {
               const auto it = by_id.find(row.Integer(0));
               if (it == by_id.end()) return;
               StoredFigure g = StoredFigureOfRow(row);
               if (g.sigma >= 0) g.expanded_u = kCoverageFactor * g.sigma;
               fits[it->second].figures.push_back(std::move(g));
             });
  db_->Execute("DROP TABLE figures; DROP TABLE fits; DROP TABLE schema_version;");
  db_->Execute(SchemaFor(*db_, std::string(kSchema) + kLatestFitsSchema + kLatestFiguresSchema));
  db_->Execute("INSERT INTO schema_version (version) VALUES (" + std::to_string(kStoreSchemaVersion) + ")");
  db_->SchemaWritten(kStoreSchemaVersion);
  for (const StoredFit& f : fits) Insert(f);
}

// Version 2: the same tables without latest_fits, which is created and filled from every fit.
void ResultsStore::MigrateFromVersion2() {
  db_->Execute(SchemaFor(*db_, kLatestFitsSchema));
  db_->Execute(kFillLatest);
}

// Version 3: without latest_figures (filled from every unit's latest fit) and without
// figures.judgement (every row keeps its outcome, with judgement '').
void ResultsStore::MigrateFromVersion3() {
  db_->Execute(SchemaFor(*db_, kLatestFiguresSchema));
  db_->Execute(kFillLatestFigures);
  db_->Execute(std::string("ALTER TABLE figures ADD COLUMN judgement ") + db_->TextType() +
               " NOT NULL DEFAULT ''");
  db_->Execute("UPDATE schema_version SET version = " + std::to_string(kStoreSchemaVersion));
  db_->SchemaWritten(kStoreSchemaVersion);
}

int64_t ResultsStore::Record(const StoredFit& fit, const std::function<void()>& before_commit) {
  const std::lock_guard<std::mutex> lock(mutex_);
  Transaction transaction(db_.get(), /*exclusive=*/false);
  const int64_t id = Insert(fit);
  std::optional<SignalsDeferred> deferred;  // the files and the row: both, even on Ctrl-C
  if (before_commit) {
    deferred.emplace();
    before_commit();  // when it throws, the transaction rolls back
  }
  transaction.Commit();
  return id;
}

bool ResultsStore::HasUnit(const std::string& lot, const std::string& unit) {
  const std::lock_guard<std::mutex> lock(mutex_);
  bool found = false;
  db_->Query("SELECT 1 FROM runs WHERE lot = ?1 AND unit = ?2 LIMIT 1", {lot, unit},
             [&](const SqlRow&) { found = true; });
  return found;
}

std::optional<std::string> ResultsStore::LotOfRun(const StoredFit& fit) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::optional<std::string> lot;
  db_->Query("SELECT lot FROM runs WHERE run_key = ?1", {RunKey(fit)},
             [&](const SqlRow& row) { lot = row.Text(0); });
  return lot;
}

int64_t ResultsStore::RecordAll(const std::vector<StoredFit>& fits) {
  const std::lock_guard<std::mutex> lock(mutex_);
  Transaction transaction(db_.get(), /*exclusive=*/false);
  int64_t added = 0;
  for (const StoredFit& fit : fits) {
    bool inserted = false;
    Insert(fit, &inserted);
    if (inserted) ++added;
  }
  transaction.Commit();
  return added;
}

int64_t ResultsStore::Insert(const StoredFit& fit, bool* added) {
  const std::string run_key = RunKey(fit), fit_key = FitKey(fit);
  const auto ignore = [](const SqlRow&) {};
  if (!fit.station.empty()) {
    db_->Query("INSERT INTO stations (station, first_seen_utc) VALUES (?1, ?2) ON CONFLICT DO NOTHING",
               {fit.station, fit.time_utc}, ignore);
  }
  db_->Query(
      "INSERT INTO units (serial, part_number, lot) VALUES (?1, ?2, ?3) ON CONFLICT (serial) DO UPDATE SET "
      "part_number = excluded.part_number WHERE units.part_number = '' AND excluded.part_number <> ''",
      {fit.serial, fit.part_number, fit.lot}, ignore);
  db_->Query(
      "INSERT INTO runs (run_key, serial, unit, lot, station, acquired_utc, plan_sha256, samples_sha256) "
      "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8) ON CONFLICT DO NOTHING",
      {run_key, fit.serial, fit.unit, fit.lot, fit.station, fit.acquired_utc, fit.plan_sha256,
       fit.samples_sha256},
      ignore);
  int64_t id = 0;
  bool inserted = false;
  db_->Query(
      "INSERT INTO fits (fit_key, run_key, time_utc, software, fit_options, limits_sha256, status, verdict, "
      "message, calibration_yaml) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10) "
      "ON CONFLICT (fit_key) DO NOTHING RETURNING id",
      {fit_key, run_key, fit.time_utc, fit.software, fit.fit_options, fit.limits_sha256, fit.status,
       fit.verdict, fit.message, fit.calibration_yaml},
      [&](const SqlRow& row) {
        id = row.Integer(0);
        inserted = true;
      });
  if (added) *added = inserted;
  if (!inserted) {  // recorded before: a re-run or a merge
    db_->Query("SELECT id FROM fits WHERE fit_key = ?1", {fit_key},
               [&](const SqlRow& row) { id = row.Integer(0); });
    return id;
  }
  db_->Query(kRecordLatest, {id, fit.time_utc, run_key}, ignore);
  for (size_t i = 0; i < fit.figures.size(); ++i) {
    const StoredFigure& g = fit.figures[i];
    db_->Query(
        "INSERT INTO figures (fit_id, position, name, coefficient, unit, value, sigma, expanded_u, "
        "limit_abs, outcome, judgement) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)",
        {id, static_cast<int64_t>(i), g.name, g.coefficient, g.unit, g.value, g.sigma, g.expanded_u,
         g.limit_abs, g.outcome, g.judgement},
        ignore);
  }
  db_->Query(kDropLatestFigures, {run_key}, ignore);  // after the figures: the latest fit may be this
  db_->Query(kRefreshLatestFigures, {run_key}, ignore);
  for (const StoredAttachment& a : fit.attachments) {
    db_->Query("INSERT INTO attachments (fit_id, kind, path, sha256) VALUES (?1, ?2, ?3, ?4)",
               {id, a.kind, a.path, a.sha256}, ignore);
  }
  return id;
}

std::vector<StoredFit> ResultsStore::Fits(const std::string& where,
                                          const std::vector<std::string>& parameters) {
  const std::vector<SqlValue> values(parameters.begin(), parameters.end());
  std::vector<StoredFit> fits;
  std::map<int64_t, size_t> by_id;
  db_->Query(std::string(kFitColumns) + " WHERE " + where + " ORDER BY f.time_utc, f.id", values,
             [&](const SqlRow& row) {
               StoredFit f;
               f.id = row.Integer(0);
               const std::vector<std::string*> texts = TextFields(&f);
               for (size_t i = 0; i < texts.size(); ++i) *texts[i] = row.Text(static_cast<int>(i) + 1);
               by_id[f.id] = fits.size();
               fits.push_back(std::move(f));
             });
  const std::string of_these =
      " JOIN fits f ON f.id = g.fit_id JOIN runs r ON r.run_key = f.run_key JOIN units u ON u.serial = "
      "r.serial WHERE " +
      where;
  db_->Query(
      "SELECT g.fit_id, g.name, g.coefficient, g.unit, g.value, g.sigma, g.expanded_u, g.limit_abs, "
      "g.outcome, g.judgement FROM figures g" +
          of_these + " ORDER BY g.fit_id, g.position",
      values, [&](const SqlRow& row) {
        StoredFigure g = StoredFigureOfRow(row);
        g.expanded_u = row.Double(6);
        g.limit_abs = row.Double(7);
        g.outcome = row.Text(8);
        g.judgement = row.Text(9);
        fits[by_id.at(row.Integer(0))].figures.push_back(std::move(g));
      });
  db_->Query("SELECT g.fit_id, g.kind, g.path, g.sha256 FROM attachments g" + of_these +
                 " ORDER BY g.fit_id, g.kind, g.path",
             values, [&](const SqlRow& row) {
               fits[by_id.at(row.Integer(0))].attachments.push_back({row.Text(1), row.Text(2), row.Text(3)});
             });
  return fits;
}

std::vector<StoredFit> ResultsStore::BySerial(const std::string& serial) {
  const std::lock_guard<std::mutex> lock(mutex_);
  return Fits("r.serial = ?1", {serial});
}

std::vector<StoredFit> ResultsStore::LatestOfLot(const std::string& lot) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StoredFit> fits =
      Fits("r.lot = ?1 AND f.id IN (SELECT fit_id FROM latest_fits WHERE lot = ?1)", {lot});
  std::sort(fits.begin(), fits.end(), [](const StoredFit& a, const StoredFit& b) { return a.unit < b.unit; });
  return fits;
}

std::vector<StoredFit> ResultsStore::All() {
  const std::lock_guard<std::mutex> lock(mutex_);
  return Fits("1 = 1", {});
}

int64_t ResultsStore::CountFits() {
  const std::lock_guard<std::mutex> lock(mutex_);
  int64_t count = 0;
  db_->Query("SELECT count(*) FROM fits", {}, [&](const SqlRow& row) { count = row.Integer(0); });
  return count;
}

std::vector<LotYield> ResultsStore::Yield(const std::string& lot) {
  std::vector<LotYield> yields;
  for (const GroupYield& y : YieldBy(YieldGroup::kLot)) {
    if (lot.empty() || y.group == lot) yields.push_back({y.group, y.units, y.passed, y.failed, y.not_fitted});
  }
  return yields;
}

std::vector<GroupYield> ResultsStore::YieldBy(YieldGroup by) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const char* column = NameOf(kYieldGroupNames, by);
  const std::string sql =
      std::string(kLatestPerUnit) + "SELECT " + column + kYieldCounts +
      (by == YieldGroup::kLot ? "WHERE lot <> '' GROUP BY lot ORDER BY min(time_utc), lot"
                              : std::string("GROUP BY ") + column + " ORDER BY " + column);
  std::vector<GroupYield> yields;
  db_->Query(sql, {}, [&](const SqlRow& row) {
    yields.push_back({row.Text(0), static_cast<int>(row.Integer(1)), static_cast<int>(row.Integer(2)),
                      static_cast<int>(row.Integer(3)), static_cast<int>(row.Integer(4))});
  });
  return yields;
}

std::vector<TrendPoint> ResultsStore::Trend(const std::string& figure, const std::string& serial,
                                            const std::string& station) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TrendPoint> points;
  db_->Query(
      "SELECT f.time_utc, r.serial, r.lot, r.station, g.value, g.sigma, g.unit, g.expanded_u FROM figures g "
      "JOIN fits f ON f.id = g.fit_id JOIN runs r ON r.run_key = f.run_key "
      "WHERE (g.name = ?1 OR g.coefficient = ?1) AND (?2 = '' OR r.serial = ?2) "
      "AND (?3 = '' OR r.station = ?3) ORDER BY f.time_utc, f.id",
      {figure, serial, station}, [&](const SqlRow& row) {
        points.push_back({row.Text(0), row.Text(1), row.Text(2), row.Text(3), row.Double(4), row.Double(5),
                          row.Text(6), row.Double(7)});
      });
  return points;
}

std::vector<LotValue> ResultsStore::LotValues(const std::string& figure) {
  return LotValues(std::vector<std::string>{figure});
}

std::vector<LotValue> ResultsStore::LotValues(const std::vector<std::string>& figures) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::string list;  // ?1, ?2, ...: one pass over the units' latest fits for every figure
  for (size_t i = 0; i < figures.size(); ++i) list += (i ? ", ?" : "?") + std::to_string(i + 1);
  std::vector<LotValue> values;
  if (figures.empty()) return values;
  db_->Query(
      // latest_fits in its key's order: no runs to join, nothing to sort.
      "SELECT l.lot, l.unit, g.value, g.sigma, g.unit, g.name, g.coefficient FROM latest_fits l "
      "JOIN fits f ON f.id = l.fit_id JOIN figures g ON g.fit_id = l.fit_id WHERE l.lot <> '' AND "
      "f.status = " +
          SqlName(kUnitStatusNames, UnitStatus::kFitted) + " AND (g.name IN (" + list +
          ") OR g.coefficient IN (" + list + ")) ORDER BY l.lot, l.unit",
      std::vector<SqlValue>(figures.begin(), figures.end()), [&](const SqlRow& row) {
        const std::string name = row.Text(5), coefficient = row.Text(6);
        for (const std::string& figure : figures) {
          if (figure != name && figure != coefficient) continue;
          values.push_back({row.Text(0), row.Text(1), row.Double(2), row.Double(3), row.Text(4), figure});
        }
      });
  return values;
}

std::vector<LotFigureStats> ResultsStore::LotStats(const std::vector<std::string>& figures) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::map<std::string, double> reference;           // by stored name: k
  std::multimap<std::string, std::string> asked_as;  // stored name -> the figure as asked
  for (const std::string& figure : figures) {
    db_->Query(kLotReference, {figure}, [&](const SqlRow& row) {
      reference.emplace(row.Text(0), row.Double(1));
      asked_as.emplace(row.Text(0), figure);
    });
  }
  // One statement reads latest_figures in index order (name, lot): no look-up per unit.
  std::vector<LotFigureStats> stats;
  if (reference.empty()) return stats;
  std::vector<SqlValue> parameters;
  for (const auto& [name, k] : reference) parameters.insert(parameters.end(), {name, k});
  db_->Query(LotSumsSql(reference.size()), parameters, [&](const SqlRow& row) {
    LotFigureStats s;
    s.lot = row.Text(0);
    s.figure_unit = row.Text(2);
    s.count = static_cast<int>(row.Integer(3));
    const double k = reference.at(row.Text(1)), s1 = row.Double(4), s2 = row.Double(5);
    s.mean = k + s1 / s.count;
    s.sigma = s.count > 1 ? std::sqrt(std::max(0.0, (s2 - s1 * s1 / s.count) / (s.count - 1))) : 0.0;
    const auto [first, last] = asked_as.equal_range(row.Text(1));
    for (auto it = first; it != last; ++it) {
      s.figure = it->second;
      stats.push_back(s);
    }
  });
  return stats;
}

}  // namespace imufit
