// imufit — the results store: every fit of a unit recorded in an embedded SQLite database.
//
// Schema (version kStoreSchemaVersion, docs/factory.md):
//   schema_version(version)                       one row
//   fits(id, serial, unit, lot, time_utc, software, plan_sha256, samples_sha256, limits_sha256,
//        status, verdict, message, calibration_yaml)
//   figures(fit_id -> fits.id, name, coefficient, unit, value, sigma)   the key figures at 25 degC
// The database runs in WAL mode; Record() writes one fit and its figures in one transaction, so a
// crash loses at most the fit being written and never leaves half a fit. Errors (the file cannot
// be opened, is not an imufit store, has a newer schema, may not be written) are InputErrors naming
// the file, raised when the store is opened: before any work. The schema version is kept twice:
// in schema_version and in SQLite's user_version (a store of a newer imufit is refused by either).
// Several processes may open and create one store at once: a busy database is waited for (up to
// kStoreBusyWaitSeconds), never an error.
#ifndef IMUFIT_FACTORY_STORE_H_
#define IMUFIT_FACTORY_STORE_H_

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "imufit/factory/acceptance.h"

struct sqlite3;

namespace imufit {

inline constexpr int kStoreSchemaVersion = 1;
// How long opening or writing the store waits for another process that holds it.
inline constexpr int kStoreBusyWaitSeconds = 60;

// How a store is opened: to record fits (created when missing; refused when it may not be
// written), or only to read an existing one (`imufit history`).
enum class StoreAccess { kRecord, kRead };

struct StoredFit {
  int64_t id = 0;
  std::string serial;
  std::string unit;  // the unit folder of a batch, or the samples file of `imufit fit`
  std::string lot;   // the batch's lot name; empty for a single fit
  std::string time_utc;
  std::string software;
  std::string plan_sha256;
  std::string samples_sha256;
  std::string limits_sha256;  // empty without limits
  std::string status;         // "fitted", "not-fitted" (the run does not determine the model), "error"
  std::string verdict;        // "PASS", "FAIL", "" (no limits, or not fitted)
  std::string message;        // failed criteria, or why it was not fitted
  std::string calibration_yaml;
  std::vector<Figure> figures;
};

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
  double value = 0.0;
  double sigma = -1.0;
  std::string unit;
};

// One key figure of one unit of a lot.
struct LotValue {
  std::string lot;
  std::string unit;
  double value = 0.0;
  double sigma = -1.0;
  std::string figure_unit;  // "deg/s", ...
};

class ResultsStore {
 public:
  // Opens the database at `path`; to record, creating it (and its schema) when it does not exist.
  explicit ResultsStore(const std::string& path, StoreAccess access = StoreAccess::kRecord);
  ~ResultsStore();
  ResultsStore(const ResultsStore&) = delete;
  ResultsStore& operator=(const ResultsStore&) = delete;

  const std::string& path() const { return path_; }

  // Records one fit in one transaction; returns its id. Safe from several threads at once (the
  // units of a batch). `before_commit` (may be empty) runs inside the transaction, after the row is
  // written and before it is committed: the outputs that belong to the row are committed there, so
  // that the row and the files appear together. When it throws, the row is rolled back and the
  // exception passes on.
  int64_t Record(const StoredFit& fit, const std::function<void()>& before_commit = {});

  // Whether any fit of `unit` in `lot` is recorded.
  bool HasUnit(const std::string& lot, const std::string& unit);
  // Every fit of a serial, oldest first, with figures.
  std::vector<StoredFit> BySerial(const std::string& serial);
  // Yield per lot (one lot when `lot` is not empty), by each unit's latest fit in the lot.
  std::vector<LotYield> Yield(const std::string& lot);
  // One key figure (a Figure name such as "gyro_bias_dps.x" or coefficient path "gyro.bias.x")
  // over time, oldest first; optionally of one serial.
  std::vector<TrendPoint> Trend(const std::string& figure, const std::string& serial);
  // One key figure (name or coefficient path, as Trend) of every unit of every lot, each unit by
  // its latest fit in the lot (the fit Yield() counts), fitted units only; by lot, then unit.
  std::vector<LotValue> LotValues(const std::string& figure);

 private:
  void Open(StoreAccess access);  // pragmas, schema, version checks
  void CheckVersion();
  void Execute(const std::string& sql);
  // Execute(), waiting while another process holds the database (SQLITE_BUSY, SQLITE_LOCKED).
  void ExecuteWaiting(const std::string& sql);
  [[noreturn]] void Fail(const std::string& what);

  std::string path_;
  sqlite3* db_ = nullptr;
  std::mutex record_mutex_;  // one Record() at a time
};

}  // namespace imufit

#endif  // IMUFIT_FACTORY_STORE_H_
