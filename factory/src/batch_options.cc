// BatchOptions: its option table (base/option_table.h) and its checks. `imufit batch` takes the
// lot's options, their help and defaults from here (every unit's fit options are
// FitRunOptionTable()'s, as `imufit fit` takes them).
#include "imufit/factory/batch.h"

namespace imufit {
namespace {

OptionTable<BatchOptions> MakeBatchOptionTable() {
  using O = BatchOptions;
  OptionTable<O> t;
  t.String("units_dir", "units_dir", "folder of unit folders (or --units-list)", &O::units_dir,
           /*path=*/true);
  t.String("units_list", "--units-list",
           "file listing the units instead of UNITS_DIR: a line per unit, \"serial, samples file[, plan]\" "
           "(CSV or blank-separated; paths relative to the list; a unit's outputs go to OUT_DIR/<serial>)",
           &O::units_list, /*path=*/true);
  t.String("samples_glob", "--samples-glob",
           "each unit folder's samples file as the logger names it: the one file matching this pattern "
           "(e.g. '*_imu.csv.gz'; default samples.csv.gz or samples.csv, not both)",
           &O::samples_glob);
  t.String("output_dir", "--output,-o", "output folder", &O::output_dir, /*path=*/true);
  t.String("limits_path", "--limits,-l", "acceptance limits YAML (format imufit-limits)", &O::limits_path,
           /*path=*/true);
  t.String("shared_plan", "--plan,-p", "plan for units without their own plan.yaml", &O::shared_plan,
           /*path=*/true);
  t.String("store_path", "--store",
           "results store to record every fit in: an SQLite file, or a PostgreSQL URL or connection string "
           "(postgresql://host/db; the password from ~/.pgpass or PGPASSFILE)",
           &O::store_path);
  t.String("station_path", "--station",
           "station file (format imufit-station: station, operator, equipment) shown on every certificate",
           &O::station_path, /*path=*/true);
  t.String("lot", "--lot", "the lot's name in the store (default: the units folder's name)", &O::lot);
  t.Number("jobs", "--jobs,-j", "units fitted in parallel (0: all cores)", "", &O::jobs, NonNegative());
  t.Number("max_units", "--max-units",
           "stop after fitting this many units (0: all); a later run resumes the lot", "", &O::max_units,
           NonNegative());
  t.Flag("write_reports", "--no-report", "write each fitted unit's report.html and the lot page",
         &O::write_reports, /*cli_negates=*/true);
  return t;
}

}  // namespace

const OptionTable<BatchOptions>& BatchOptionTable() {
  static const OptionTable<BatchOptions> table = MakeBatchOptionTable();
  return table;
}

}  // namespace imufit
