#include "imufit/factory/certify.h"

#include <sys/stat.h>

#include <ctime>
#include <exception>
#include <utility>

#include "imufit/factory/certificate.h"
#include "imufit/factory/report.h"
#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

// The unit's certificate, from its fit and the settings; every input hashed already.
Certificate MakeUnitCertificate(const CertifySettings& settings, const UnitFiles& files,
                                const UnitOutcome& unit) {
  const FitRunResult& fit = *unit.fit;
  CertificateSources sources;
  sources.unit = unit.unit;
  sources.software = settings.software;
  sources.calibration = *fit.calibration;
  sources.plan = fit.plan;
  sources.run = fit.run;
  sources.windows = settings.windows;
  sources.samples_input = settings.samples_input;
  sources.folds = fit.folds;
  sources.warnings = unit.warnings;
  sources.limits = settings.limits;  // judged with the noise the certificate measures
  // A calibration just fitted is not in place yet (it is committed with the certificate): hash
  // its text; an input is hashed from its file.
  sources.inputs = {
      {"calibration", files.calibration, files.calibration_is_input ? "" : Sha256Hex(unit.calibration_yaml)},
      {"plan", unit.plan_path, unit.plan_sha256},
      {"samples", unit.samples_path, unit.samples_sha256},
      {"limits", settings.limits ? settings.limits->path : "", settings.limits_sha256},
      {"station", settings.station ? settings.station->path : "", settings.station_sha256}};
  sources.station = settings.station;
  // A fit recorded what the samples header says; a calibration read from a file may not have.
  sources.header = files.calibration_is_input ? fit.run.header : RunHeader();
  sources.noise_stretch = settings.noise_stretch;
  sources.customer = settings.customer;
  sources.order = settings.order;
  ReadCertificateFiles(&sources);  // only what is not known yet: the run kept its static stretch
  return MakeCertificate(sources);
}

}  // namespace

void JudgeUnit(const CertifySettings& settings, const Calibration& calibration, const Certificate* certified,
               UnitOutcome* unit) {
  unit->figures = certified != nullptr ? KeyFigures(calibration, kFigureTempC, &certified->budget)
                                       : KeyFigures(calibration);
  unit->calibrated_utc = calibration.created_utc;
  if (!settings.limits) return;
  unit->verdict = certified != nullptr ? *certified->verdict : EvaluateLimits(*settings.limits, calibration);
  unit->message = unit->verdict->FailedSummary();
}

bool JudgedAsCertified(const CertifySettings& settings, const UnitFiles& files) {
  return !files.report.empty() || settings.limits || settings.store != nullptr;
}

void ReadLimitsAndStation(const std::string& limits_path, const std::string& station_path,
                          CertifySettings* settings) {
  if (!limits_path.empty()) {
    settings->limits = ReadLimits(limits_path);
    settings->limits_sha256 = Sha256OfFile(limits_path);
  }
  if (!station_path.empty()) {
    settings->station = ReadStation(station_path);
    settings->station_sha256 = Sha256OfFile(station_path);
  }
}

bool CertifyUnit(const CertifySettings& settings, const UnitFiles& files, UnitOutcome* unit) {
  IMUFIT_CHECK(unit->fit && unit->fit->calibration, "CertifyUnit() certifies a fitted unit");
  const Calibration& calibration = *unit->fit->calibration;
  unit->status = UnitStatus::kFitted;
  if (!files.calibration_is_input) unit->calibration_yaml = CalibrationToYaml(calibration);
  // One judgement whatever is printed: the certificate's figures, U and verdict, also when no page
  // is written (--no-report, fit --limits without --report), so that every output says the same.
  std::optional<Certificate> certificate;
  if (JudgedAsCertified(settings, files)) certificate = MakeUnitCertificate(settings, files, *unit);
  JudgeUnit(settings, calibration, certificate ? &*certificate : nullptr, unit);
  // The calibration, the certificate, the caller's further outputs and the store's row: all or none.
  OutputTransaction outputs;
  unit->attachments.clear();
  if (!files.calibration_is_input) {
    WriteFileAtomically(files.calibration, unit->calibration_yaml, &outputs);
    unit->attachments.push_back({"calibration", files.calibration, Sha256Hex(unit->calibration_yaml)});
  }
  if (!files.report.empty()) {
    const std::string html = CertificateHtml(*certificate);
    WriteFileAtomically(files.report, html, &outputs);
    unit->attachments.push_back({"certificate", files.report, Sha256Hex(html)});
    if (!files.pdf.empty())
      unit->attachments.push_back(
          {"certificate_pdf", files.pdf, WritePdf(html, files.pdf, files.paper, &outputs)});
  }
  if (files.more) files.more(*unit, &outputs);
  return RecordUnit(settings, unit, &outputs);
}

namespace {

// The last-modified time of a file as "YYYY-MM-DDTHH:MM:SSZ"; "" when it cannot be read.
std::string FileTimeUtc(const std::string& path) {
  struct stat info {};
  if (path.empty() || stat(path.c_str(), &info) != 0) return "";
  std::tm utc{};
  if (gmtime_r(&info.st_mtime, &utc) == nullptr) return "";
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace

StoredFigure StoredFigureOf(const Figure& figure) {
  StoredFigure g;
  g.name = figure.name;
  g.coefficient = figure.coefficient;
  g.unit = figure.unit;
  g.value = figure.value;
  g.sigma = figure.sigma;
  g.expanded_u = figure.sigma >= 0.0 ? figure.expanded : -1.0;
  return g;
}

bool RecordUnit(const CertifySettings& settings, UnitOutcome* unit, OutputTransaction* outputs) {
  if (settings.store == nullptr) {
    if (outputs != nullptr) outputs->Commit();
    return true;
  }
  StoredFit row;
  row.unit = unit->unit.empty() ? unit->samples_path : unit->unit;
  row.serial = unit->serial.empty() ? row.unit : unit->serial;
  row.lot = settings.lot;
  // When the calibration was made: a unit skipped as unchanged keeps its original fit time (the
  // same fit recorded again is the same row, also after a merge); a unit not fitted, now.
  const bool fitted = unit->status == UnitStatus::kFitted;
  row.time_utc = fitted && unit->fit && unit->fit->calibration ? unit->fit->calibration->created_utc
                 : fitted && !unit->calibrated_utc.empty()     ? unit->calibrated_utc
                                                               : UtcNow();
  row.fit_options = settings.fit_options;
  row.attachments = unit->attachments;
  row.software = settings.software;
  row.plan_sha256 = unit->plan_sha256;
  row.samples_sha256 = unit->samples_sha256;
  row.limits_sha256 = settings.limits_sha256;
  row.status = unit->StatusText();
  row.verdict = unit->VerdictText();
  row.message = unit->message;
  row.calibration_yaml = unit->calibration_yaml;
  if (settings.station)
    row.station = settings.station->id.empty() ? settings.station->name : settings.station->id;
  // When the run was recorded and what the unit is: the samples header's, else the file's time.
  const RunHeader* header = unit->fit ? &unit->fit->run.header : nullptr;
  row.acquired_utc =
      header && !header->acquired_utc.empty() ? header->acquired_utc : FileTimeUtc(unit->samples_path);
  if (header) row.part_number = header->model;
  const std::vector<CriterionResult> not_judged;
  const std::vector<CriterionResult>& criteria = unit->verdict ? unit->verdict->criteria : not_judged;
  for (const Figure& figure : unit->figures) {
    StoredFigure g = StoredFigureOf(figure);
    for (const CriterionResult& c : criteria) {
      if (c.name != "|" + g.name + "|") continue;
      g.limit_abs = c.limit;
      g.outcome = NameOf(kCriterionAcceptanceNames, c.pass);
      g.judgement = OutcomeName(c.outcome);
    }
    if (!figure.unresolved.empty()) g.judgement = kNotResolved;
    row.figures.push_back(std::move(g));
  }
  std::exception_ptr output_error;  // the outputs' failure passes on; the store's is the unit's
  const auto commit_outputs = [&] {
    if (outputs == nullptr) return;
    try {
      outputs->Commit();
    } catch (...) {
      output_error = std::current_exception();
      throw;
    }
  };
  try {
    settings.store->Record(row, commit_outputs);
  } catch (const std::exception& e) {
    if (output_error) std::rethrow_exception(output_error);
    unit->status = UnitStatus::kError;
    unit->verdict.reset();
    unit->message = std::string(e.what()) + ": the fit is not recorded in the results store";
    return false;
  }
  return true;
}

}  // namespace imufit
