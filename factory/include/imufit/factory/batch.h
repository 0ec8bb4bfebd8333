// imufit — a batch: every unit of a lot fitted, judged and recorded (`imufit batch`).
//
// UNITS_DIR holds one folder per unit: plan.yaml + samples.csv (or samples.csv.gz, or the one file
// matching samples_glob, as the logger names it), or samples only when a shared plan is given; a
// unit's serial is its serial.txt, its samples header's or its plan's, else (a warning, shown on
// the certificate) the folder's name. Or a unit list (units_list) names each unit: its serial, its
// samples file and optionally its plan. Units are fitted in parallel (a pool of `jobs` threads, one
// unit each, one solver thread per unit); a unit's failure never stops the others. Each fitted
// unit is certified as `imufit fit` certifies one (certify.h). For each unit OUT_DIR/<unit>/
// receives calibration.yaml (when fitted) and report.html (with write_reports) together, then
// manifest.yaml last, after the unit is recorded in the store. The manifest
// holds the SHA-256 of the unit's inputs (plan, samples, limits, station), the fit options
// (FitRunOptions::Describe) and the software version; a re-run skips a unit whose manifest matches
// (and whose outputs are there), so a batch killed half way and run again redoes only the units
// that had not finished, and a batch run with other fit options redoes every unit. The lot summary
// OUT_DIR/lot_summary.csv is written at the end from every unit's outcome (fitted now or before).
#ifndef IMUFIT_FACTORY_BATCH_H_
#define IMUFIT_FACTORY_BATCH_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/certify.h"
#include "imufit/factory/shard.h"
#include "imufit/pipeline/fit_run.h"

namespace imufit {

struct BatchProgress {
  int done = 0;  // units finished (skipped ones included)
  int skipped = 0;
  int total = 0;
  double elapsed_s = 0.0;
  const UnitOutcome* last = nullptr;  // the unit that just finished
};

// The lot's options. BatchOptionTable() describes those a person gives (the command line of `imufit
// batch`, its help and validation messages); the defaults are these.
struct BatchOptions {
  std::string units_dir;   // a folder of unit folders; or:
  std::string units_list;  // a file listing the units: "serial, samples[, plan]" a line (CSV or blanks)
  // The samples file in each unit folder: the one file whose name matches this shell pattern
  // (fnmatch, e.g. "*_imu.csv.gz"); empty: samples.csv.gz or samples.csv (a folder with both is
  // refused: the unit's error).
  std::string samples_glob;
  std::string output_dir;
  std::string limits_path;      // empty: no verdicts
  std::string shared_plan;      // used by units without their own plan.yaml
  std::string store_path;       // empty: no results store
  std::string station_path;     // station file shown on every certificate; empty: none
  std::string customer, order;  // whom the certificates are issued to; "" when not given
  std::string lot;              // the lot's name in the store; empty: the units folder's name
  // Worker threads; 0: all cores.
  int jobs = 0;
  // Stop after this many units have been fitted in this run (0: no limit) — for tests of resuming.
  int max_units = 0;
  // This run's share of the lot (shard.h): the units whose folder name hashes to shard.index.
  // With more than one shard, shards may write to one output folder at once, and the lot's
  // outputs (lot_summary.csv, lot.html) are not written: the lot page comes from the store.
  Shard shard;
  // Every unit's fit (its `serial` is the unit's serial.txt; serial_source is set per unit).
  FitRunOptions fit;
  // Write OUT_DIR/<unit>/report.html for each fitted unit and OUT_DIR/lot.html (report.h).
  bool write_reports = true;
  // With write_reports: each certificate printed to OUT_DIR/<unit>/report.pdf and the lot page to
  // OUT_DIR/lot.pdf (pdf.h), on `paper`.
  bool write_pdf = false;
  Paper paper = Paper::kA4;
  // Called under a lock after each unit finishes (from whichever thread finished it).
  std::function<void(const BatchProgress&)> progress;

  std::string Validate() const;
};
// The folders and files, jobs, max_units and write_reports; not the fit (FitRunOptionTable()), the
// shard (parsed from the environment too), the customer or the paper (shared with fit and report).
const OptionTable<BatchOptions>& BatchOptionTable();

struct BatchResult {
  std::vector<UnitOutcome> units;  // in folder-name order
  int passed = 0, failed = 0, not_fitted = 0, errors = 0, skipped = 0;
  bool complete = true;  // false when max_units stopped the batch early

  // Appends `unit` and counts it.
  void Add(UnitOutcome unit) {
    skipped += unit.skipped ? 1 : 0;
    errors += unit.status == UnitStatus::kError ? 1 : 0;
    not_fitted += unit.status == UnitStatus::kNotFitted ? 1 : 0;
    passed += unit.verdict && unit.verdict->pass ? 1 : 0;
    failed += unit.verdict && !unit.verdict->pass ? 1 : 0;
    units.push_back(std::move(unit));
  }
};

// Throws InputError for a bad units folder, output folder, limits file or store; never for one
// unit's bad input (that unit's status is UnitStatus::kError).
BatchResult RunBatch(const BatchOptions& options);

// The unit's key figures in the lot summary, in column order.
extern const std::vector<std::string> kSummaryFigures;

}  // namespace imufit

#endif  // IMUFIT_FACTORY_BATCH_H_
