// imufit — the calibration certificate of one unit: a single self-contained HTML file (inline
// CSS, plots as inline SVG drawn by gnuplot's svg terminal, no network; prints to PDF).
//
// It holds: serial, dates, software version and git revision, the SHA-256 of every input file,
// the plan summary and the temperature range covered, every coefficient at 25 degC with 1-sigma
// in familiar units (acceptance.h gives the conversions), each coefficient group against
// temperature with a 1-sigma band, the residuals of the calibration per plan segment and
// temperature, the gyro Allan deviation with ARW and bias instability over the longest static
// stretch (at least 60 s), the leave-one-temperature-out validation errors (when run), and the acceptance
// verdict criterion by criterion. Key numbers carry machine-readable attributes
// (data-figure="gyro_bias_dps.x" data-value="..."), so tests and tools can read them back.
//
// Plots need gnuplot on PATH; without it the report says so in place of each plot.
#ifndef IMUFIT_FACTORY_REPORT_H_
#define IMUFIT_FACTORY_REPORT_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/acceptance.h"
#include "imufit/factory/batch.h"
#include "imufit/fit/validation.h"
#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/pipeline/run_windows.h"

namespace imufit {

struct ReportInput {
  std::string role;  // "plan", "samples", "calibration", "limits"
  std::string path;
  std::string sha256;
};

struct UnitReport {
  std::string unit;  // the batch unit folder, or empty
  std::string created_utc;
  std::string software;
  std::string git_revision;
  std::vector<ReportInput> inputs;
  Calibration calibration;
  Plan plan;
  RunWindows run;
  std::vector<HeldOutGroup> folds;  // empty when validation was not run
  std::optional<Verdict> verdict;   // with limits
};

// Builds a report from a calibration and the run it was fitted to. Hashes the named files
// (empty paths are left out). Throws InputError when a file cannot be read.
UnitReport MakeUnitReport(const Calibration& calibration, const Plan& plan, RunWindows run,
                          const std::vector<ReportInput>& inputs, const std::optional<Verdict>& verdict);
// From a batch unit just fitted (its FitRunResult is in unit.fit).
UnitReport MakeUnitReport(const UnitOutcome& unit, const std::string& limits_path);

// The HTML text. Runs gnuplot for the plots.
std::string UnitReportHtml(const UnitReport& report);
// Writes it atomically.
void WriteUnitReport(const std::string& path, const UnitReport& report);

// The lot page: yield, the distribution of the key figures over the units (strip plots) and the
// outliers (robust z = 0.6745 (x - median) / MAD beyond kOutlierRobustZ), with links to the
// units' reports.
inline constexpr double kOutlierRobustZ = 3.5;
struct RobustZ {
  double z = 0.0;
  bool outlier = false;
};
// Robust z-scores of `values` (all 0 and no outliers with fewer than 3 values or a zero MAD).
std::vector<RobustZ> RobustZScores(const std::vector<double>& values);
std::string LotReportHtml(const std::string& lot, const BatchResult& batch, const std::string& software);

// Runs gnuplot on `script` (which must `set output` to each of `outputs` in turn, as given,
// inside a private temporary folder: write '@OUT0@', '@OUT1@', ... for them) and returns the SVG
// texts. Throws std::runtime_error when gnuplot is missing or fails.
std::vector<std::string> RunGnuplotSvg(const std::string& script, int outputs);

// Escapes text for HTML.
std::string HtmlEscape(const std::string& text);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_REPORT_H_
