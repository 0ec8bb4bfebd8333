// The fixture of the end-to-end tests of the factory commands and options (library
// imufit_cli_factory_util): `imufit batch` (cli_batch_test.cc), `imufit report` and the printed
// certificate (cli_report_test.cc), `imufit fit --limits/--report/--store` (cli_fit_factory_test.cc)
// and `imufit allan` on raw counts (cli_allan_test.cc), each on a simulated lot of five small units
// made with `imufit simulate` from fixtures/mems_truth.yaml (10 Hz, 3 s dwells, 4 temperatures):
//   unit-01, unit-02  good units with their own plan (serials SN-01, SN-02)
//   unit-03           a good unit with samples only: fitted with the shared --plan
//   unit-04           g-sensitivity xx of 0.089 deg/s/g, outside the 0.05 deg/s/g limit (SN-04)
//   unit-05           a corrupt samples file (a number "1.2.3" in the middle)
// The program is run as a user runs it (IMUFIT_EXE); outputs are read back from the files. Every
// test is FactoryCliTest.NAME, whichever program holds it.
#ifndef IMUFIT_TESTS_CLI_FACTORY_UTIL_H_
#define IMUFIT_TESTS_CLI_FACTORY_UTIL_H_

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"

namespace imufit {

inline const std::string kFixtures = IMUFIT_FIXTURES_DIR;
// The exit statuses of docs/spec.md section 4.
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNotDone = 1;
inline constexpr int kExitFailedLimits = 3;
inline constexpr int kUnits = 5;
// A passing unit's certificate prints on at most this many pages (five since it states its
// uncertainty budget and decision rule).
inline constexpr int kMostPagesOfAPassingCertificate = 5;

// The acceptance limits of the lot (limits.yaml in the test's folder).
inline constexpr const char* kLimits = R"(format: imufit-limits
version: 1
name: MEMS-A acceptance
nominal: {gyro_scale: 939.65, accel_scale: 208.838}
criteria:
  - {quantity: gyro_bias_dps, max_abs: 5}
  - {quantity: gyro_scale_error_pct, max_abs: 2}
  - {quantity: gyro_misalignment_mrad, max_abs: 10}
  - {quantity: gyro_g_sensitivity_dpsg, max_abs: 0.05}
  - {quantity: gyro_bias_dps, statistic: sigma, max_abs: 0.01}
  - {quantity: fit_temp_range_c, covers: [-20, 60]}
)";

// A station file (reference equipment due in 2099).
inline constexpr const char* kStation = R"(format: imufit-station
version: 1
station: Rate table bench 2
station_id: CB-02
location: Building 4, room 112
operator: J. Smith
rate_table: {model: Acutronic AC1120S, serial: RT-2291}
chamber: {model: Espec SU-262, serial: CH-0117}
reference_calibration_due: 2099-12-31
notes: Rate table calibrated by the national lab, certificate NL-2026-0412.
)";

std::string ReadBytes(const std::filesystem::path& path);

// A CSV split into rows of cells (no quoted commas in the cells the tests read).
std::vector<std::map<std::string, std::string>> ReadCsv(const std::string& text);

// The value of data-value on the element with data-figure="name" in a report.
std::string ReportFigure(const std::string& html, const std::string& name);

// Runs `sql` on the SQLite store at `path` with Python's sqlite3 (another reader than ours): one
// line per row, cells joined by "|".
std::string Query(const std::filesystem::path& path, const std::string& sql);

// Runs `sql` on the SQLite database at `path` (the test's own change to a store).
void ExecuteSql(const std::string& path, const std::string& sql);

// The line of `text` from where `start` is found to its end ("" when it is not found).
std::string LineWith(const std::string& text, const std::string& start);

// The files in `folder` whose names contain ".tmp-" (an output never committed).
std::vector<std::string> Temporaries(const std::filesystem::path& folder);

class FactoryCliTest : public testing::TempDirTest {
 protected:
  // Writes limits.yaml and the lot (MakeLot).
  void SetUp() override;

  testing::RunResult Run(const std::vector<std::string>& args) const;

  // Simulates a unit's run with a fixed seed and a little white noise.
  void Simulate(const std::string& plan, const std::string& truth, const std::string& samples, int seed);

  // units/UNIT/plan.yaml: fixtures/plan_6pos.yaml with `serial`; returns its path.
  std::string UnitPlan(const std::string& unit, const std::string& serial);

  // The five units of the lot under units/ (see the top of this file).
  void MakeLot();

  // `imufit batch` of the lot into `out` with the limits, the shared plan, store.db and lot LOT-A.
  std::vector<std::string> BatchArgs(const std::string& out) const;

  // Prints `html` to PDF with headless Chromium on paper `size` ("A4", "letter"; the printer's page
  // size: an @page rule added to a copy), rasterises every page with pdftoppm and checks it: not
  // blank, "page x of y" in its footer, text no smaller than kMinimumWordHeightPt. Returns the
  // number of pages (0 when the tools are missing: the caller skips).
  int PrintToPdf(const std::string& html, const std::string& name, const std::string& size);

  // Expects docs/troubleshooting.md to quote `said`, a line the program printed (its final newline
  // and this test's folder left out, as the page shortens paths), between backquotes.
  void ExpectTroubleshootingQuotes(std::string said) const;

  // OUT/lot_summary.csv's rows by unit.
  std::map<std::string, std::map<std::string, std::string>> Summary(const std::string& out) const;
};

}  // namespace imufit

#endif  // IMUFIT_TESTS_CLI_FACTORY_UTIL_H_
