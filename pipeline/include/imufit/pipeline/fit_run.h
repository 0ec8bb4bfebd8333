// imufit — fitting one unit's run from its files: what `imufit fit` does, as a library call, so
// that batch tooling fits units through the same code path instead of shelling out.
//
// FitRun() reads the plan and the samples (and a held-out run, if given), fits, validates when
// asked, and builds the calibration to write (with its `sigma` tree and the fit's record, the
// `fit:` block of io/fit_record.h). It writes nothing. The samples file is read once (twice without
// a segment column, run_windows.h); what a certificate needs of it (the hash, the segmentation, the
// noise stretch, static_stretch.h) comes with the result, so that nobody reads it again. Bad input throws
// InputError; a run that does not determine the model, or a fit that does not converge, is reported
// through `fit.status` (then `calibration` is not set). A samples file without a segment column is
// labelled from the plan first (segment_run.h); when it does not match the plan, PlanMismatchError
// is thrown. So it is when a labelled file's labels contradict the plan (run/label_check.h), and
// when a converged fit is inconsistent with the run's noise (consistency.h) unless
// FitRunOptions::write_inconsistent.
#ifndef IMUFIT_PIPELINE_FIT_RUN_H_
#define IMUFIT_PIPELINE_FIT_RUN_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/fit/thermal_fit.h"
#include "imufit/fit/validation.h"
#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/pipeline/run_windows.h"

namespace imufit {

struct FitRunOptions {
  FitOptions fit;
  WindowOptions windows;
  // Files without a temp_c or segment column (the held-out run is read the same way).
  SamplesInput input;
  // Leave each interior temperature out in turn and report the errors on it.
  bool validate = false;
  // A held-out run (and its plan; empty: the fitted run's plan) to report the errors on.
  std::string check_samples;
  std::string check_plan;
  // Written into the calibration's `software` key, e.g. "imufit 0.1.0".
  std::string software;
  // The unit's serial (--serial); empty: the samples header's `# serial:` line, else the plan's
  // `serial` (unit_serial.h: a disagreement is a warning, or an error).
  std::string serial;
  // How messages name `serial`: "--serial", or a batch unit's serial.txt.
  std::string serial_source = "--serial";
  // Write the calibration of a fit the consistency gate refuses (consistency.h), marked as such in
  // its `fit:` block (`inconsistent`), on the summary and on the certificate (--write-inconsistent).
  bool write_inconsistent = false;
  // Fit even when `serial` contradicts the samples header's serial (then a warning; --allow-mismatch).
  bool allow_serial_mismatch = false;
  // SHA-256 of the plan file, recorded in the calibration's `fit:` block (with the samples', which
  // is computed while they are read) so that a certificate can tell that a calibration and a run
  // belong together; computed when empty.
  std::string plan_sha256;
  // Keep the run's noise stretch (result.run.static_stretch) for a certificate's noise section;
  // changes nothing else.
  bool keep_static_stretch = false;
  // Which static stretch that is (static_stretch.h; --noise-segment).
  NoiseStretchOptions noise_stretch;

  // An empty string when usable, else what is wrong.
  std::string Validate() const;
  // Every option of FitRunOptionTable() that can change what a fit of the same files gives (the
  // calibration, its validation, an error), as one line of "key=value" items; not the threads, the
  // software, the serial or the hashes. The held values of a prior are named by a SHA-256 of their
  // numbers, so that a prior file that is edited counts as changed and a copy elsewhere does not.
  // The batch manifest compares it to decide whether a unit is unchanged.
  std::string Describe() const;
};

// Every option a user sets of a unit's fit (those of FitOptions, WindowOptions and SamplesInput
// included, then the prior, validation, check run and serial mismatch), described once
// (model/option_table.h; run_options.cc): `imufit fit`, `batch`, the Python keywords of
// imufit.fit() and Describe() derive from it. Not in it: software, serial and the hashes, which
// the caller fills.
const OptionTable<FitRunOptions>& FitRunOptionTable();

struct FitRunResult {
  // The unit's serial as FitRunOptions::serial resolves it (also when the fit fails); empty when
  // nothing names the unit.
  std::string serial;
  // Sources of the serial that disagree with it, one message each (unit_serial.h).
  std::vector<std::string> serial_warnings;
  // What the run lacks that the fit went on without, one message each: plan segments without a
  // single usable window (never visited, or every visit too short). The calibration's record lists
  // them too (fit record `segments_without_windows`).
  std::vector<std::string> run_warnings;
  Plan plan;
  std::string plan_sha256;  // the samples' is run.samples_sha256
  RunWindows run;
  FitSummary fit;
  // Why the fit is inconsistent (consistency.h): "" when it is not; set only with
  // FitRunOptions::write_inconsistent (without it FitRun throws PlanMismatchError).
  std::string inconsistency;
  // The calibration's `fit:` block, also when the fit is not usable (then without the hashes).
  FitRecord record;
  std::vector<HeldOutGroup> folds;         // with options.validate
  std::vector<ErrorStats> check_errors;    // per segment, then all ("segment" -1); with check_samples
  std::optional<Calibration> calibration;  // when fit.IsSolutionUsable()
};

FitRunResult FitRun(const std::string& plan_path, const std::string& samples_path,
                    const FitRunOptions& options);
// The same of a plan already read (plan.path names it; `plan_sha256` is that of the text it was
// read from) and samples held in memory (Python's imufit.fit on arrays): what the files of the
// same plan and samples give, without writing them.
FitRunResult FitRun(Plan plan, std::string plan_sha256, const SamplesInMemory& samples,
                    const FitRunOptions& options);
// A plan already read, and a samples file.
FitRunResult FitRun(Plan plan, std::string plan_sha256, const std::string& samples_path,
                    const FitRunOptions& options);

// The fit a calibration's `fit:` record describes, as FitRun records it: the temperature orders,
// the groups fitted (the rest held) and the robust loss, read back by the one table that writes
// them (fit_run.cc). Everything else, the weighting by bias stability included, is FitOptions'
// default. Throws InputError, located at the record's key (fit.fitted, fit.loss), for a set of
// groups no fit estimates or a loss no fit knows (ReadCalibration refuses an unknown group or loss
// name already, at its line and column).
FitOptions FitOptionsOfRecord(const FitRecord& record);

// Why a run does not determine the model, as one line (the CLI's error, Python's exception):
// "<samples>: the run does not determine the model: <findings, "; "-separated> (the run: <counts>)".
// `result.fit.status` is FitStatus::kUndetermined.
std::string UndeterminedMessage(const std::string& samples, const FitRunOptions& options,
                                const FitRunResult& result);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_FIT_RUN_H_
