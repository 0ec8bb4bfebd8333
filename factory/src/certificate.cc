#include "imufit/factory/certificate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "certificate_sections.h"
#include "imufit/factory/git_revision.h"
#include "imufit/factory/report.h"
#include "imufit/io/calibration.h"
#include "imufit/io/sha256.h"
#include "imufit/io/units.h"
#include "imufit/model/check.h"
#include "imufit/report/engineering_units.h"

namespace imufit {
namespace {

FitSettings Settings(const Calibration& calibration, const WindowOptions& windows) {
  FitSettings s;
  s.trim_s = windows.trim_s;
  s.window_temp_span_c = windows.max_temp_span_c;
  if (!calibration.fit || !calibration.fit->windows_used) return s;
  const FitRecord& fit = *calibration.fit;
  s.known = true;
  s.windows_used = *fit.windows_used;
  s.windows_downweighted = fit.windows_downweighted.value_or(s.windows_downweighted);
  s.iterations = fit.iterations.value_or(s.iterations);
  s.gyro_temp_order = fit.gyro_temp_order.value_or(s.gyro_temp_order);
  s.accel_temp_order = fit.accel_temp_order.value_or(s.accel_temp_order);
  s.gyro_reduced_chi2 = fit.gyro_reduced_chi2.value_or(s.gyro_reduced_chi2);
  s.accel_reduced_chi2 = fit.accel_reduced_chi2.value_or(s.accel_reduced_chi2);
  if (fit.gyro_bias_stability_radps) s.gyro_bias_stability_dph = DphFromRadps(*fit.gyro_bias_stability_radps);
  if (fit.accel_bias_stability_mps2) s.accel_bias_stability_ug = UgFromMps2(*fit.accel_bias_stability_mps2);
  s.g_sensitivity_fitted = fit.g_sensitivity_fitted.value_or(true);
  s.loss = fit.loss.value_or("");
  s.termination = fit.termination.value_or("");
  if (const size_t end = s.termination.find(". "); end != std::string::npos) s.termination.resize(end + 1);
  return s;
}

RunSummary SummariseRun(const Calibration& calibration, const Plan& plan, const RunWindows& run) {
  RunSummary r;
  r.plan_path = plan.path;
  r.segments = static_cast<int>(plan.segments.size());
  std::set<double> rates, angles;
  for (const TableSegment& s : plan.segments) {
    if (s.IsStatic()) {
      ++r.static_segments;
    } else if (s.IsTurn()) {
      ++r.turn_segments;
      angles.insert(std::abs(*s.angle_rad * kRadToDeg));
    } else {
      rates.insert(std::abs(DpsFromRadps(s.rate_radps)));
    }
  }
  r.rates_dps.assign(rates.begin(), rates.end());
  r.turn_angles_deg.assign(angles.begin(), angles.end());
  std::set<int> visited;
  for (const Window& w : run.windows) visited.insert(w.segment);
  for (const TableSegment& s : plan.segments) {
    if (visited.count(s.id) == 0) r.segments_without_windows.push_back(s.id);
  }
  r.gravity_mps2 = plan.site.gravity_mps2;
  if (plan.site.latitude_rad) r.latitude_deg = *plan.site.latitude_rad * kRadToDeg;
  r.samples = run.stats.samples;
  r.windows = static_cast<int>(run.windows.size());
  std::set<long> temps;
  for (const Window& w : run.windows) {
    temps.insert(std::lround(w.temp_c));
    r.time_s.push_back(0.5 * (w.start_s + w.end_s));
    r.window_temp_c.push_back(w.temp_c);
  }
  for (long t : temps) r.temperatures_c.push_back(static_cast<double>(t));
  r.temp_range_c = calibration.fit_temp_range_c;
  return r;
}

// Plan segments the run never visited: a warning each.
void CoverageWarnings(const RunSummary& run, std::vector<std::string>* warnings) {
  for (int id : run.segments_without_windows) {
    warnings->push_back("plan segment " + std::to_string(id) +
                        " has no usable window in the samples (never occurs, or every occurrence is shorter "
                        "than the trim and the minimum window)");
  }
}

// The station's reference equipment must have been within its calibration when the run was
// recorded (ISO dates compare as text); without an acquisition time, when the unit was fitted.
void StationWarnings(const Station& station, const Certificate& c, std::vector<std::string>* warnings) {
  if (station.reference_calibration_due.empty()) return;
  const std::string& time = !c.acquired_utc.empty()         ? c.acquired_utc
                            : c.calibrated_utc.size() >= 10 ? c.calibrated_utc
                                                            : c.written_utc;
  const std::string when = time.substr(0, 10);
  if (station.reference_calibration_due < when) {
    warnings->push_back("the station's reference equipment was due for calibration on " +
                        station.reference_calibration_due + ", before this unit's run was recorded (" + when +
                        (c.acquired_utc.empty() ? "; no '# acquired:' time: the fit's date" : "") + ")");
  }
}

// What the run header says, the calibration's record first.
void RunIdentity(const CertificateSources& sources, Certificate* c) {
  const std::optional<FitRecord>& fit = sources.calibration.fit;
  const RunHeader header_read = sources.header.value_or(RunHeader());
  const auto pick = [&](const std::optional<std::string> FitRecord::*recorded, const std::string& header) {
    return fit && (*fit.*recorded) && !(*fit.*recorded)->empty() ? *(*fit.*recorded) : header;
  };
  c->acquired_utc = pick(&FitRecord::acquired_utc, header_read.acquired_utc);
  c->unit_model = pick(&FitRecord::unit_model, header_read.model);
  c->unit_firmware = pick(&FitRecord::unit_firmware, header_read.firmware);
  c->ambient = pick(&FitRecord::ambient, header_read.ambient);
  c->customer = sources.customer;
  c->order = sources.order;
}

// Who, when, by what, from which files, and what the reader must be warned of.
void Identify(const CertificateSources& sources, Certificate* c) {
  const Calibration& cal = sources.calibration;
  c->serial = cal.serial;
  c->unit = sources.unit;
  c->calibrated_utc = cal.created_utc;
  c->written_utc = UtcNow();
  c->calibration_software = cal.software;
  c->report_software = sources.software;
  c->git_revision = GitRevision();
  c->reference_temp_c = cal.model.basis.center_c;
  for (const ReportInput& input : sources.inputs) {
    if (input.path.empty()) continue;
    IMUFIT_CHECK(!input.sha256.empty(), "every input comes with its SHA-256 (ReadCertificateFiles)");
    c->inputs.push_back(input);
  }
  IMUFIT_CHECK(!sources.station || std::any_of(c->inputs.begin(), c->inputs.end(),
                                               [](const ReportInput& in) { return in.role == "station"; }),
               "the station's file is among the inputs (ReadCertificateFiles)");
  if (c->serial.empty()) {
    c->warnings.push_back(
        "no serial: neither --serial, the calibration, the samples file's '# serial:' header line nor the "
        "plan names the unit");
  }
  if (cal.fit && cal.fit->inconsistent) {
    c->warnings.push_back(
        "written with --write-inconsistent: the fit is inconsistent with the run's noise: " +
        *cal.fit->inconsistent);
  }
  for (const std::string& w : sources.warnings) c->warnings.push_back(w);
  RunIdentity(sources, c);
  c->number = CertificateNumber(c->serial.empty() ? c->unit : c->serial,
                                c->acquired_utc.empty() ? c->calibrated_utc : c->acquired_utc, c->inputs,
                                c->customer, c->order);
  c->station = sources.station;
  if (c->station) StationWarnings(*c->station, *c, &c->warnings);
}

// The key figures at 25 degC, with their expanded uncertainty (the budget's, where it has the figure).
std::vector<KeyFigureRow> FigureRows(const Calibration& cal, const UncertaintyBudget& budget) {
  std::vector<KeyFigureRow> rows;
  for (const Figure& f : KeyFigures(cal, kFigureTempC, &budget)) {
    // Coefficients of the model, signed; the others are the fit's diagnostics (residual RMS,
    // segments missing) and noise figures.
    const KeyFigure* quantity = FindKeyFigure(f.name);
    const bool is_coefficient = quantity != nullptr && quantity->source == FigureSource::kCoefficient;
    rows.push_back({f.name, f.unit, is_coefficient, f.value, f.sigma, f.expanded, f.extrapolated});
  }
  return rows;
}

// The coefficients against temperature and the windows' errors before and after correction.
void DescribeErrors(const CertificateSources& sources, Certificate* c) {
  const Calibration& cal = sources.calibration;
  const std::vector<Window>& windows = sources.run.windows;
  const std::vector<WindowError> after =
      PredictWindows(cal.model, windows, sources.plan.site, sources.plan.segments);
  c->curves = internal::CoefficientCurves(cal, sources.plan, windows, after);
  const std::vector<WindowError> before =
      PredictWindows(internal::ScaleOnly(cal), windows, sources.plan.site, sources.plan.segments);
  c->residuals = internal::Residuals(cal, sources.plan, windows, after, before);
  c->residual_table = internal::ResidualTable(sources.plan, after, before);
  c->residual_table_printed = internal::PrintedResidualRows(c->residual_table, &c->residual_rows_omitted);
}

// The plan's predicted limiting coefficient on the run's windows, with the U of its key figure
// (the figure's U over its sigma, times the achieved sigma: the same in any unit).
LimitingPrediction LimitingOfRun(const CertificateSources& sources,
                                 const std::vector<KeyFigureRow>& figures) {
  std::map<std::string, double> tolerances;
  if (sources.limits) TolerancesFromLimits(*sources.limits, &tolerances);
  LimitingPrediction p = PredictLimiting(sources.calibration, sources.plan, sources.run.windows, tolerances);
  for (const KeyFigureRow& f : figures) {
    if (f.name == p.figure && f.sigma > 0.0 && f.expanded >= 0.0 && p.achieved_sigma >= 0.0) {
      p.achieved_expanded = p.achieved_sigma * f.expanded / f.sigma;
    }
  }
  return p;
}

std::vector<ValidationRow> ValidationRows(const std::vector<HeldOutGroup>& folds) {
  std::vector<ValidationRow> rows;
  for (const HeldOutGroup& g : folds) {
    ValidationRow row;
    row.temp_c = g.temp_c;
    row.fitted = g.fitted;
    row.why_not = g.why_not;
    row.windows = g.errors.windows;
    row.gyro_rms_dps = DpsFromRadps(g.errors.gyro_rms_radps);
    row.gyro_max_dps = DpsFromRadps(g.errors.gyro_max_radps);
    row.accel_rms_mg = MgFromMps2(g.errors.accel_rms_mps2);
    row.accel_max_mg = MgFromMps2(g.errors.accel_max_mps2);
    row.gyro_temp_order = g.gyro_temp_order;
    row.accel_temp_order = g.accel_temp_order;
    row.order_lowered = g.order_lowered;
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

void ReadCertificateFiles(CertificateSources* sources) {
  std::vector<ReportInput>& inputs = sources->inputs;
  if (sources->station && std::none_of(inputs.begin(), inputs.end(),
                                       [](const ReportInput& in) { return in.role == "station"; })) {
    inputs.push_back({"station", sources->station->path, ""});
  }
  for (ReportInput& input : inputs) {
    if (!input.path.empty() && input.sha256.empty()) input.sha256 = Sha256OfFile(input.path);
  }
  const std::optional<FitRecord>& fit = sources->calibration.fit;
  // A run read from its file (hashed on the way) brought its header along.
  if (!sources->header && !sources->run.samples_sha256.empty()) sources->header = sources->run.header;
  if (!sources->header && !(fit && fit->acquired_utc)) {
    for (const ReportInput& input : inputs) {
      if (input.role == "samples" && !input.path.empty()) sources->header = ReadRunHeader(input.path);
    }
  }
  // A session by hand has no static stretch to measure the noise on (MakeCertificate says so).
  if (sources->noise || sources->calibration.body_frame) return;
  // The stretch the run's reading kept (the file is not read again), else measured on the file.
  if (sources->run.static_stretch) {
    sources->noise = GyroNoise(sources->calibration, *sources->run.static_stretch);
    return;
  }
  for (const ReportInput& input : inputs) {
    if (input.role != "samples" || input.path.empty()) continue;
    sources->noise = MeasureGyroNoise(sources->calibration, sources->plan, input.path, sources->samples_input,
                                      sources->run.segmentation, sources->noise_stretch);
  }
}

namespace {

// The session of a calibration by hand, from its records.
FieldSession SummariseField(const Calibration& cal) {
  FieldSession f;
  f.body_frame = cal.body_frame.value_or("");
  f.temp_range_c = cal.fit_temp_range_c;
  if (!cal.fit) return f;
  const FitRecord& fit = *cal.fit;
  f.samples = fit.samples_read.value_or(-1);
  f.temp_order = std::max(fit.gyro_temp_order.value_or(0), fit.accel_temp_order.value_or(0));
  f.g_sensitivity_fitted = fit.g_sensitivity_fitted.value_or(true);
  f.iterations = fit.iterations.value_or(-1);
  f.termination = fit.termination.value_or("");
  if (const size_t end = f.termination.find(". "); end != std::string::npos) f.termination.resize(end + 1);
  if (!fit.field) return f;
  const FieldRecord& r = *fit.field;
  f.poses = r.poses.value_or(-1);
  f.turns = r.turns.value_or(-1);
  f.saturated_turns = r.saturated_turns.value_or(-1);
  f.gravity_mps2 = r.gravity_mps2.value_or(0.0);
  f.gravity_source = r.gravity_source.value_or("");
  // A calibration written before the record said where gravity came from: 9.80665 is the default.
  if (f.gravity_source.empty() && f.gravity_mps2 == kStandardGravityMps2) f.gravity_source = kGravityStandard;
  f.latitude_deg = r.latitude_deg;
  f.height_m = r.height_m;
  if (r.accel_norm_rms_mps2) f.accel_norm_rms_mg = MgFromMps2(*r.accel_norm_rms_mps2);
  if (r.gyro_static_rms_radps) f.gyro_static_rms_dps = DpsFromRadps(*r.gyro_static_rms_radps);
  if (r.gravity_direction_rms_rad) f.direction_rms_deg = *r.gravity_direction_rms_rad * kRadToDeg;
  f.reduced_chi2 = r.reduced_chi2.value_or(-1.0);
  f.noise_scale = {r.noise_scale_accel_rests.value_or(-1.0), r.noise_scale_gyro_rests.value_or(-1.0),
                   r.noise_scale_turns.value_or(-1.0)};
  return f;
}

// A calibration by hand: its session, its budget (no station's), its figures and verdict.
Certificate MakeFieldCertificate(const CertificateSources& sources) {
  const Calibration& cal = sources.calibration;
  Certificate c;
  Identify(sources, &c);
  c.field = SummariseField(cal);
  c.run.temp_range_c = c.field->temp_range_c;
  c.run.gravity_mps2 = c.field->gravity_mps2;
  c.run.latitude_deg = c.field->latitude_deg;
  c.run.samples = c.field->samples;
  c.settings = Settings(cal, sources.windows);
  if (sources.station && !sources.station->uncertainty.empty()) {
    c.warnings.push_back("the station file declares Type B sources (" +
                         std::to_string(sources.station->uncertainty.size()) +
                         "): they are a rate table's and a fixture's, and a calibration by hand used "
                         "neither, so U does not include them");
  }
  if (c.field->saturated_turns > 0) {
    c.warnings.push_back(std::to_string(c.field->saturated_turns) +
                         " turn(s) touched the gyro's converter limit and were left out of the fit");
  }
  c.budget = ComputeFieldBudget(cal);
  c.figures = FigureRows(cal, c.budget);
  c.noise.why_not =
      "a session by hand has no static stretch long enough for an Allan deviation (measure the noise on a "
      "static recording: imufit allan --noise-yaml)";
  c.verdict = sources.verdict;
  // The calibration's own figures (a `noise:` block measured by imufit allan, if any): nothing measured here.
  if (sources.limits) c.verdict = EvaluateLimits(*sources.limits, cal, {}, &c.budget);
  return c;
}

}  // namespace

Certificate MakeCertificate(const CertificateSources& sources) {
  const Calibration& cal = sources.calibration;
  if (cal.body_frame) return MakeFieldCertificate(sources);
  Certificate c;
  Identify(sources, &c);
  c.run = SummariseRun(cal, sources.plan, sources.run);
  CoverageWarnings(c.run, &c.warnings);
  c.settings = Settings(cal, sources.windows);
  c.budget =
      ComputeBudget(cal, sources.plan, sources.run.windows,
                    sources.station ? sources.station->uncertainty : std::vector<StationUncertainty>());
  c.figures = FigureRows(cal, c.budget);
  c.settings.limiting = LimitingOfRun(sources, c.figures);
  DescribeErrors(sources, &c);
  const bool samples_given = std::any_of(c.inputs.begin(), c.inputs.end(),
                                         [](const ReportInput& in) { return in.role == "samples"; });
  IMUFIT_CHECK(sources.noise || !samples_given,
               "the noise of a samples input is measured (ReadCertificateFiles)");
  if (sources.noise) {
    c.noise = *sources.noise;
  } else {
    c.noise.why_not = "no samples file given";
  }
  c.verdict = sources.verdict;
  if (sources.limits) c.verdict = EvaluateLimits(*sources.limits, cal, MeasuredFigures(c), &c.budget);
  c.validation = ValidationRows(sources.folds);
  return c;
}

std::string CertificateNumber(const std::string& serial, const std::string& date_utc,
                              const std::vector<ReportInput>& inputs, const std::string& customer,
                              const std::string& order) {
  std::string content;
  for (const ReportInput& input : inputs) content += input.role + " " + input.sha256 + "\n";
  content += "customer " + customer + "\norder " + order + "\n";
  // The serial as a file name would hold it: letters, digits, '.', '_' and '-'.
  std::string name;
  for (char ch : serial.empty() ? std::string("UNIT") : serial) {
    const bool plain = (ch >= '0' && ch <= '9') || (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') ||
                       ch == '.' || ch == '_' || ch == '-';
    name += plain ? ch : '_';
  }
  std::string date;
  for (char ch : date_utc.substr(0, 10)) {
    if (ch != '-') date += ch;
  }
  return name + "-" + date + "-" + Sha256Hex(content).substr(0, 8);
}

namespace {

// Why this run does not resolve a noise term, and how to supply it (Figure::unresolved).
std::string Unresolved(const NoiseSection& noise, const NoiseAxis* axis, const KeyFigure& quantity) {
  const bool arw = quantity.noise_term == kRandomWalk;
  const double needed_s = arw ? kMinAllanStretchS : kBiasInstabilityStretchS;
  std::string text =
      "not resolved by this run (needs a static stretch of " + FormatNumber("%g", needed_s) + " s";
  if (!noise.computed) {
    text += "; " + noise.why_not + ")";
  } else {
    text += "; the stretch measured is " + FormatNumber("%.0f", noise.duration_s) + " s";
    if (axis != nullptr && !axis->why_not.empty()) text += ", " + axis->why_not;
    if (axis != nullptr && axis->fitted) {
      text +=
          "; " + TermFigureText(arw ? axis->arw_deg_per_sqrt_hr : axis->bias_instability_dph, quantity.unit);
    }
    text += ")";
  }
  return text +
         ": add a static dwell of that length to the plan, or give the calibration a noise: block measured "
         "on such a stretch (imufit allan --noise-yaml)";
}

}  // namespace

std::vector<Figure> MeasuredFigures(const Certificate& certificate) {
  std::vector<Figure> figures;
  const NoiseSection& noise = certificate.noise;
  for (const char* axis_name : {"x", "y", "z"}) {
    const NoiseAxis* a = nullptr;
    for (const NoiseAxis& axis : noise.axes) {
      if (axis.axis == axis_name) a = &axis;
    }
    const std::string axis = axis_name;
    // Every noise figure of the key figures, from this certificate's own Allan deviation.
    for (const KeyFigure& quantity : kKeyFigures) {
      if (quantity.source != FigureSource::kNoise) continue;
      const bool arw = quantity.noise_term == kRandomWalk;
      Figure f = MakeFigure(std::string(quantity.name) + "." + axis,
                            "certificate.gyro_" + axis + (arw ? ".arw" : ".bias_instability"), quantity.unit);
      const NoiseTermFigure* term = a == nullptr || !a->fitted ? nullptr
                                    : arw                      ? &a->arw_deg_per_sqrt_hr
                                                               : &a->bias_instability_dph;
      if (term != nullptr && term->resolved) {
        f.value = term->value;
        f.sigma = term->sigma;
        f.expanded = f.sigma >= 0.0 ? kCoverageFactor * f.sigma : -1.0;
      } else {
        f.unresolved = Unresolved(noise, a, quantity);
      }
      figures.push_back(f);
    }
  }
  // The worst window after correction, at any temperature of the run (the per-segment table's "all").
  if (!certificate.residual_table.empty()) {
    const ResidualRow& all = certificate.residual_table.back();
    for (const KeyFigure& quantity : kKeyFigures) {
      if (quantity.source != FigureSource::kCertificate) continue;
      const bool gyro = IsGyroFigure(quantity);
      if (!gyro && all.accel_windows <= 0) continue;
      figures.push_back(MakeFigure(quantity.name, quantity.path, quantity.unit,
                                   gyro ? all.gyro_max_dps : all.accel_max_mg));
    }
  }
  return figures;
}

std::vector<std::string> InputMismatches(const Calibration& calibration, const std::string& plan_path,
                                         const std::string& samples_path) {
  std::vector<std::string> mismatches;
  const auto check = [&](const std::optional<std::string>& recorded, const char* role,
                         const std::string& path) {
    if (!recorded || recorded->empty() || path.empty()) return;
    const std::string actual = Sha256OfFile(path);
    if (actual != *recorded) {
      mismatches.push_back(std::string("the calibration was fitted to a ") + role + " with SHA-256 " +
                           recorded->substr(0, 16) + "..., not " + path + " (" + actual.substr(0, 16) +
                           "...)");
    }
  };
  if (!calibration.fit) return mismatches;
  check(calibration.fit->plan_sha256, "plan", plan_path);
  check(calibration.fit->samples_sha256, "samples file", samples_path);
  return mismatches;
}

}  // namespace imufit
