// imufit — the results store: every fit of a unit, on one of two backends behind this one class:
// an embedded SQLite file (the default, one per station) or a PostgreSQL database (a URL such as
// postgresql://host/db or a libpq keyword/value string; the password from ~/.pgpass or
// PGPASSFILE, never from the command line). docs/factory.md and docs/scale.md.
//
// Schema (version kStoreSchemaVersion; the same tables on both backends):
//   schema_version(version)                                one row
//   stations(station, first_seen_utc)                      where runs were acquired
//   units(serial, part_number, lot)                        one row per serial
//   runs(run_key, serial, unit, lot, station, acquired_utc, plan_sha256, samples_sha256)
//        run_key: UUIDv5 of the serial and the input hashes, so a run is one row however often
//        and from wherever it is imported
//   fits(id, fit_key, run_key, time_utc, software, fit_options, limits_sha256, status, verdict,
//        message, calibration_yaml)                        fit_key: UUIDv5 of the run and the fit
//   figures(fit_id, name, coefficient, unit, value, sigma, expanded_u, limit_abs, outcome, judgement)
//   attachments(fit_id, kind, path, sha256)                the certificate and its files, by reference
//   latest_fits(lot, unit, fit_id, time_utc)               each unit's latest fit (latest time_utc,
//        then highest id), kept in Record()'s transaction; yield and the lot pages read it
//   latest_figures(name, lot, unit, figure_unit, value)  the figures of each fitted unit's latest
//        fit, kept with latest_fits; the lot statistics (LotStats()) read it
// Record() writes one fit, its run, unit, station, figures and attachments in one transaction with
// INSERT ... ON CONFLICT DO NOTHING: re-recording the same fit (a re-run, a merge, two writers at
// once) changes nothing. A version 1 SQLite store, and a version 2 or 3 store of either backend, is
// migrated in place, in one transaction, when opened (3: adds latest_figures and
// figures.judgement, '' in the rows it keeps). Errors (cannot
// open or connect, not an imufit store, a newer schema, may not be written) are InputErrors naming the file
// or database, raised when the store is opened: before any work. Several processes may open, create and write
// one store at once: a busy SQLite database is waited for (up to kStoreBusyWaitSeconds), never an error.
#ifndef IMUFIT_STORE_STORE_H_
#define IMUFIT_STORE_STORE_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/enum_names.h"

namespace imufit {

class SqlConnection;

inline constexpr int kStoreSchemaVersion = 4;
// How long opening or writing an SQLite store waits for another process that holds it.
inline constexpr int kStoreBusyWaitSeconds = 60;

// How a store is opened: to record fits (created when missing; refused when it may not be
// written), or to read an existing one (`imufit history`, `lot`, the sources of a merge): a read
// never writes, creates nothing, and reads a store of an older schema through a migrated private
// copy. Either way a database that holds tables of another application is refused untouched.
enum class StoreAccess { kRecord, kRead };

// A key figure as stored: its value, its expanded uncertainty and how it was judged. A plain row:
// the store knows no documents; factory fills it from its judged figures.
struct StoredFigure {
  std::string name;         // quantity.axis of kKeyFigures (io/key_figures.h), e.g. "gyro_bias_dps.x"
  std::string coefficient;  // the calibration's path, e.g. "gyro.bias.x"; "fit.gyro_residual_rms"
  std::string unit;         // "deg/s", "mg", ...
  double value = 0.0;
  double sigma = -1.0;       // 1-sigma; < 0 when the calibration has none
  double expanded_u = -1.0;  // U = k sigma (k = kCoverageFactor, io/limits.h); < 0 without sigma
  double limit_abs = -1.0;   // the acceptance limit on |value|; < 0 without one
  // "pass", "fail" (accepted under the decision rule or not: kCriterionAcceptanceNames,
  // base/verdict.h), "" (not judged).
  std::string outcome;
  // Where the value lies against its limit with U (ILAC-G8; kOutcomeNames): "PASS", "conditional
  // pass", "conditional fail", "FAIL", "not resolved" (the run does not measure it), or "" (not
  // judged, or recorded before schema version 4: then `outcome` alone is known).
  std::string judgement;
};

// The stored figure called `name` (or with that coefficient path); nullptr when there is none.
const StoredFigure* FindFigure(const std::vector<StoredFigure>& figures, const std::string& name);

// A file that belongs to a fit (its certificate, the PDF, the calibration), by reference.
struct StoredAttachment {
  std::string kind;  // "calibration", "certificate", "report", "pdf", ...
  std::string path;
  std::string sha256;
};

struct StoredFit {
  int64_t id = 0;  // numbered by the store that holds it (differs between stores)
  std::string serial;
  std::string unit;          // the unit folder of a batch, or the samples file of `imufit fit`
  std::string lot;           // the batch's lot name; empty for a single fit
  std::string part_number;   // the unit's model or part number; "" when not known
  std::string station;       // the station's id (or name); "" when not given
  std::string acquired_utc;  // when the run was acquired (the samples file's time); "" unknown
  std::string time_utc;      // when it was fitted
  std::string software;
  std::string fit_options;  // the fit options' fingerprint
  std::string plan_sha256;
  std::string samples_sha256;
  std::string limits_sha256;  // empty without limits
  // The names of base/verdict.h: UnitStatus's ("fitted", "not-fitted": the run does not determine
  // the model, "error") and the unit's verdict ("PASS", "FAIL", "": no limits, or not fitted).
  std::string status;
  std::string verdict;
  std::string message;  // failed criteria, or why it was not fitted
  std::string calibration_yaml;
  std::vector<StoredFigure> figures;
  std::vector<StoredAttachment> attachments;
};

// The content keys (UUIDv5, lower-case text): a run's from its serial and input hashes, a fit's
// from its run and what the fit produced.
std::string RunKey(const StoredFit& fit);
std::string FitKey(const StoredFit& fit);

struct LotYield {
  std::string lot;
  int units = 0;  // distinct units, each counted by its latest fit
  int passed = 0;
  int failed = 0;
  int not_fitted = 0;  // not-fitted or error
};

struct TrendPoint {
  std::string time_utc;
  std::string serial;
  std::string lot;
  std::string station;  // "" when not given
  double value = 0.0;
  double sigma = -1.0;
  std::string unit;
  double expanded_u = -1.0;  // the U the fit was stated with (StoredFigure::expanded_u); < 0: none
};

// What yield is grouped by: the lot of a batch, the station a unit was calibrated at, or the month
// (YYYY-MM, UTC) it was calibrated in.
enum class YieldGroup { kLot, kStation, kMonth };
inline constexpr EnumName<YieldGroup> kYieldGroupNames[] = {
    {YieldGroup::kLot, "lot"}, {YieldGroup::kStation, "station"}, {YieldGroup::kMonth, "month"}};

struct GroupYield {
  std::string group;  // the lot, the station ("" not given) or the month
  int units = 0;      // distinct units, each counted by its latest fit (in the group of that fit)
  int passed = 0;
  int failed = 0;
  int not_fitted = 0;  // not-fitted or error
};

// One key figure of one unit of a lot.
struct LotValue {
  std::string lot;
  std::string unit;
  double value = 0.0;
  double sigma = -1.0;
  std::string figure_unit;  // "deg/s", ...
  std::string figure;       // the figure as asked for (LotValues())
};

// One key figure over the fitted units of one lot (LotStats()): how many, their mean and sample
// standard deviation (n - 1; 0 for one unit).
struct LotFigureStats {
  std::string lot;
  std::string figure;       // as asked for
  std::string figure_unit;  // "deg/s", ...
  int count = 0;
  double mean = 0.0;
  double sigma = 0.0;
};

class ResultsStore {
 public:
  // Opens the store `target` names: a PostgreSQL URL or connection string (IsPostgresStore()), or
  // else an SQLite file, created (with its schema) when it does not exist.
  explicit ResultsStore(const std::string& target, StoreAccess access = StoreAccess::kRecord);
  ~ResultsStore();
  ResultsStore(const ResultsStore&) = delete;
  ResultsStore& operator=(const ResultsStore&) = delete;

  const std::string& path() const { return path_; }
  const char* backend() const;  // "sqlite" or "postgresql"

  // Records one fit in one transaction; returns its id (the existing fit's when this store holds
  // it already). Safe from several threads and processes at once (the units of a batch, shards).
  // `before_commit` (may be empty) runs inside the transaction, after the row is written and before
  // it is committed: the outputs that belong to the row are committed there, so that the row and
  // the files appear together. When it throws, the row is rolled back and the exception passes on.
  int64_t Record(const StoredFit& fit, const std::function<void()>& before_commit = {});
  // Records every fit in one transaction; returns how many this store did not hold yet.
  int64_t RecordAll(const std::vector<StoredFit>& fits);
  // Every fit, oldest first, with figures and attachments (what `imufit store merge` copies).
  std::vector<StoredFit> All();
  // How many fits the store holds.
  int64_t CountFits();

  // Whether any fit of `unit` in `lot` is recorded.
  bool HasUnit(const std::string& lot, const std::string& unit);
  // The lot the run of `fit` (its serial, plan and samples: RunKey) is recorded in; nullopt when the
  // store does not hold that run. A run keeps the lot it was first recorded in.
  std::optional<std::string> LotOfRun(const StoredFit& fit);
  // Each unit of `lot` by its latest fit in the lot (the fit Yield() counts), with figures and
  // attachments, by unit name.
  std::vector<StoredFit> LatestOfLot(const std::string& lot);
  // Every fit of a serial, oldest first, with figures.
  std::vector<StoredFit> BySerial(const std::string& serial);
  // Yield per lot (one lot when `lot` is not empty), by each unit's latest fit in the lot.
  std::vector<LotYield> Yield(const std::string& lot);
  // Yield by lot (lots in the order of their first fit), station or month (in name order): every
  // unit (a lot's unit, or a single fit's samples file) counted once, by its latest fit, in the
  // group of that fit; lots leave out single fits (no lot).
  std::vector<GroupYield> YieldBy(YieldGroup by);
  // One key figure (a Figure name such as "gyro_bias_dps.x" or coefficient path "gyro.bias.x")
  // over time, oldest first; optionally of one serial, of one station (its drift).
  std::vector<TrendPoint> Trend(const std::string& figure, const std::string& serial,
                                const std::string& station = "");
  // One key figure (name or coefficient path, as Trend) of every unit of every lot, each unit by
  // its latest fit in the lot (the fit Yield() counts), fitted units only; by lot, then unit.
  std::vector<LotValue> LotValues(const std::string& figure);
  // The same for several figures in one pass (the lot page's trends), by lot, then unit.
  std::vector<LotValue> LotValues(const std::vector<std::string>& figures);
  // Per figure, per lot (lots in name order), the count, mean and sigma of the values LotValues()
  // gives, computed by the database (the lot page's trends): nothing per unit leaves it.
  std::vector<LotFigureStats> LotStats(const std::vector<std::string>& figures);

 private:
  void Open();                         // schema, version check, migration
  void Migrate(int64_t from_version);  // inside Open()'s transaction
  void MigrateFromVersion1();
  void MigrateFromVersion2();
  void MigrateFromVersion3();
  int64_t Insert(const StoredFit& fit, bool* added = nullptr);  // inside a transaction
  std::vector<StoredFit> Fits(const std::string& where, const std::vector<std::string>& parameters);

  std::string path_;
  StoreAccess access_;
  std::unique_ptr<SqlConnection> db_;
  std::mutex mutex_;  // one statement at a time on the connection
};

// True when `target` names a PostgreSQL database rather than an SQLite file.
bool IsPostgresStore(const std::string& target);

// What `imufit store merge` did with one source.
struct MergeResult {
  std::string source;
  int64_t fits = 0;   // fits the source holds
  int64_t added = 0;  // of them, new in the destination
};

// Copies every fit of each source store (SQLite files or PostgreSQL databases, which must exist)
// into `destination` (created when it is a missing SQLite file), one transaction per source.
// Idempotent: a fit the destination holds already (same content key) is left as it is. Every
// source is read (as `imufit history` reads: never written) before the destination is opened, so
// a refused source leaves the destination untouched, or uncreated; a source that is the
// destination itself is refused.
std::vector<MergeResult> MergeStores(const std::vector<std::string>& sources, const std::string& destination);

}  // namespace imufit

#endif  // IMUFIT_STORE_STORE_H_
