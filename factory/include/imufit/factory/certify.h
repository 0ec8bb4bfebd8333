// imufit — one unit judged, certified, committed and recorded: what `imufit fit --limits --report
// --store` does after its fit, and what `imufit batch` does for every unit it fits, in one place.
//
// CertifyUnit() takes a unit FitRun() has fitted and, in this order,
//   certifies it: its certificate (certificate.h) when a report is asked for, the noise section
//     from the static stretch the run's reading kept (FitRunOptions::keep_static_stretch), so
//     that the samples file is not read again;
//   judges it: its key figures, and its verdict against the acceptance limits with the noise
//     figures the certificate measured (acceptance.h);
//   commits and records it: the calibration, the certificate, the caller's further outputs (a
//     batch's manifest) and one row in the results store (store.h, when there is one) in one
//     transaction: all of them or none (the files are renamed inside the store's transaction,
//     before its commit; signals wait for both, output_file.h SignalsDeferred).
// The certificate names the software that made the calibration (the calibration's `software`)
// and the software that certifies it (CertifySettings::software: the program's version, which
// the program passes in).
#ifndef IMUFIT_FACTORY_CERTIFY_H_
#define IMUFIT_FACTORY_CERTIFY_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/verdict.h"
#include "imufit/factory/acceptance.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/io/station.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/static_stretch.h"
#include "imufit/report/pdf.h"
#include "imufit/store/store.h"

namespace imufit {

struct Certificate;  // certificate.h

// One unit: its inputs, its fit and what became of it.
struct UnitOutcome {
  std::string unit;    // the batch unit folder; "" for `imufit fit`
  std::string serial;  // serial.txt's, the samples header's, the plan's, else the unit folder name
  // Sources of the serial that disagree (unit_serial.h); shown on the certificate. Not kept for a
  // skipped unit.
  std::vector<std::string> warnings;
  UnitStatus status = UnitStatus::kNotFitted;
  // The verdict against the acceptance limits, criterion by criterion; nullopt when the unit was
  // not fitted, or without limits.
  std::optional<Verdict> verdict;
  std::string message;  // the failed criteria, or why it was not fitted
  std::vector<Figure> figures;
  std::string calibrated_utc;  // when the calibration was made (its created_utc); fitted units
  std::string plan_path;
  std::string samples_path;
  std::string plan_sha256;
  std::string samples_sha256;
  bool skipped = false;  // unchanged since a previous run: nothing redone
  double seconds = 0.0;
  // The fit's result and the calibration (not filled for skipped units).
  std::optional<FitRunResult> fit;
  std::string calibration_yaml;  // the calibration file's text (fitted units)
  // The files committed with the unit (calibration, certificate), by path and SHA-256: the store's
  // attachments rows.
  std::vector<StoredAttachment> attachments;

  // As the manifest, the store and lot_summary.csv write them (base/verdict.h): "fitted",
  // "not-fitted", "error"; "PASS", "FAIL", "" (no verdict).
  const char* StatusText() const { return NameOf(kUnitStatusNames, status); }
  const char* VerdictText() const { return verdict ? VerdictName(verdict->pass) : ""; }
};

// What every unit is certified with: the one unit of `imufit fit`, or each unit of a batch.
struct CertifySettings {
  // The program that certifies and records, e.g. "imufit 0.1.0".
  std::string software;
  // How the runs were read into windows (the certificate shows it).
  WindowOptions windows;
  SamplesInput samples_input;
  // Acceptance limits (none: no verdict) and the SHA-256 of their file.
  std::optional<Limits> limits;
  std::string limits_sha256;
  // Where and by whom (none: the signers fill it in) and the SHA-256 of the station file.
  std::optional<Station> station;
  std::string station_sha256;
  // Whom the certificates are issued to (--customer, --order); "" when not given.
  std::string customer, order;
  // The results store units are recorded in (none: not recorded; not owned), and their lot
  // ("" for a single fit).
  ResultsStore* store = nullptr;
  std::string lot;
  // What the units are fitted with (FitRunOptions::Describe(), as the batch manifest records it):
  // the store's fits.fit_options. "" for a calibration certified as it is (imufit report).
  std::string fit_options;
  // The static stretch the noise section is measured on when the run's reading kept none
  // (imufit report's --noise-segment).
  NoiseStretchOptions noise_stretch;
};

// Reads the limits and the station file into `settings` (either path may be empty), with their
// hashes: a bad file is reported (InputError) before any unit is fitted.
void ReadLimitsAndStation(const std::string& limits_path, const std::string& station_path,
                          CertifySettings* settings);

// Where a unit's outputs go.
struct UnitFiles {
  // Where the calibration is written; with calibration_is_input, the file it was read from.
  std::string calibration;
  std::string report;  // the certificate; "" for none
  std::string pdf;     // the certificate printed (pdf.h), with `report`; "" for none
  Paper paper = Paper::kA4;
  // Further outputs written into the unit's transaction once it is judged (a batch's manifest).
  std::function<void(const UnitOutcome&, OutputTransaction*)> more;
  // The calibration is an input certified as it is (imufit report: unit->fit holds it with the
  // run read again, not a fit): its file is hashed, not written, and the certificate takes the
  // samples header's run details where its record lacks them (a calibration of an older imufit).
  bool calibration_is_input = false;
};

// Certifies, judges, commits and records `unit`: unit->fit holds FitRun's result with a calibration
// (the serial it is to carry set), or for a calibration that is an input (UnitFiles::
// calibration_is_input) that calibration with its plan and run; unit->plan_path, samples_path and
// their hashes are filled (a hash may be "": then the file is hashed).
// `imufit fit`, `imufit report` and every unit of `imufit batch` are certified here.
// Sets the unit's status (fitted), figures, verdict and calibration text. Throws InputError when
// an output cannot be written (then none is, and nothing is recorded). Returns RecordUnit()'s
// answer (false: the store refused the row; then no output was written either).
bool CertifyUnit(const CertifySettings& settings, const UnitFiles& files, UnitOutcome* unit);

// The unit's key figures with their U, and its verdict against settings.limits: `certified`'s (a
// certificate's: U from its uncertainty budget, judged with the noise and window errors it
// measured) when given, else the calibration's alone (U = k x sigma).
void JudgeUnit(const CertifySettings& settings, const Calibration& calibration, const Certificate* certified,
               UnitOutcome* unit);

// Whether CertifyUnit() judges the unit through its certificate (computed whether or not its page is
// written): with a report, limits or a store, i.e. whenever a U or a verdict is stated anywhere.
bool JudgedAsCertified(const CertifySettings& settings, const UnitFiles& files);

// A key figure as the store keeps it, not yet judged: its value, 1-sigma and U (Figure::expanded).
StoredFigure StoredFigureOf(const Figure& figure);

// Records `unit`, whatever its status, in settings.store when there is one (safe from several
// threads at once), committing `outputs` (may be null) with the row: both or neither. Returns
// false when the store refuses it: then the unit is an error whose message says why, and no
// output is written. An output that cannot be written throws (InputError); then nothing is recorded.
bool RecordUnit(const CertifySettings& settings, UnitOutcome* unit, OutputTransaction* outputs = nullptr);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_CERTIFY_H_
