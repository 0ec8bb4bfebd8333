// imufit — what a unit's calibration certificate says, computed in one place.
//
// MakeCertificate() turns a calibration, the run it was fitted to, the fit's validation, the
// acceptance verdict and the noise measured on the run into a Certificate: every number a quality
// engineer reads, already in engineering units (engineering_units.h) and rounded nowhere. It reads
// no file: the caller hands in the inputs' hashes and the noise section (ReadCertificateFiles()
// reads them). The renderer (certificate_page.h) only formats and draws it; tests assert on this
// struct. A batch's lot page is lot_summary.h's.
//
// Figures are quoted at 25 degC through the model's polynomial (whatever the calibration's
// reference temperature); expanded uncertainties are k = 2 times the 1-sigma. Curves against
// temperature take the polynomial's terms as independent for their band (the file holds no
// correlations): indicative, exact at the reference temperature.
#ifndef IMUFIT_FACTORY_CERTIFICATE_H_
#define IMUFIT_FACTORY_CERTIFICATE_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/acceptance.h"
#include "imufit/factory/batch.h"
#include "imufit/factory/gyro_noise.h"
#include "imufit/factory/uncertainty_budget.h"
#include "imufit/fit/validation.h"
#include "imufit/io/calibration.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/io/run_header.h"
#include "imufit/io/station.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/plan/plan_prediction.h"

namespace imufit {

struct ReportInput {
  std::string role;    // "calibration", "plan", "samples", "limits", "station"
  std::string path;    // empty: not listed
  std::string sha256;  // ReadCertificateFiles() computes it from the file when empty
};

// Everything a certificate is computed from.
struct CertificateSources {
  std::string unit;  // the batch unit folder, or empty
  // The program that writes the certificate, e.g. "imufit 0.1.0" (the calibration names the one
  // that made it).
  std::string software;
  Calibration calibration;
  Plan plan;
  // run.segmentation: the labels of a file without a segment column; run.static_stretch: the noise
  // section's samples, kept while the run was read (else ReadCertificateFiles reads the file).
  RunWindows run;
  WindowOptions windows;              // how the run was cut into windows (trim, ...)
  SamplesInput samples_input;         // how the samples file is read (--temp-c for a file without temp_c)
  NoiseStretchOptions noise_stretch;  // which static stretch the noise is measured on (--noise-segment)
  std::vector<HeldOutGroup> folds;    // empty when validation was not run
  std::optional<Verdict> verdict;     // judged by the caller; replaced when `limits` is given
  // Acceptance limits: judged here, with the ARW and bias instability this certificate measures
  // taking the place of a `noise:` block's.
  std::optional<Limits> limits;
  // The files listed, each with its SHA-256 (MakeCertificate checks that every listed one has it).
  std::vector<ReportInput> inputs;
  std::vector<std::string> warnings;  // from the caller (e.g. a mismatch the user allowed)
  // Where and by whom (a station file, --station); its file is among the inputs (role "station").
  std::optional<Station> station;
  // What the samples header says of the run (acquired, model, firmware, ambient) where the
  // calibration's fit record does not say it; nullopt: not known, ReadCertificateFiles reads the
  // samples file's header (a calibration written before the record had them). A caller that has
  // just fitted the run sets it empty: the record holds what the header said.
  std::optional<RunHeader> header;
  // The customer and their order (--customer, --order); "" when not given.
  std::string customer, order;
  // The Allan section, measured on the static stretch the run's reading kept (GyroNoise), or on
  // the samples input (MeasureGyroNoise); nullopt only when no samples input is listed.
  std::optional<NoiseSection> noise;
};

// What MakeCertificate() takes from files, read into `sources`: the samples header's run header
// when the calibration does not record an acquisition time, the SHA-256 of every listed input
// that has none (the station's file added to the inputs when it is not among them), and, unless
// `noise` is given, the noise section measured on the samples input (MeasureGyroNoise).
void ReadCertificateFiles(CertificateSources* sources);

struct KeyFigureRow {
  std::string name;  // e.g. "gyro_bias_dps.x"
  std::string unit;
  // A coefficient of the model (signed: printed with its sign); else a quantity that cannot be
  // negative (a residual RMS, a noise figure, segments missing).
  bool is_coefficient = false;
  double value = 0.0;
  double sigma = -1.0;  // 1-sigma of the fit (Type A); < 0: none
  // U, k = 2, of the uncertainty budget (Type A and the station's Type B sources); < 0: none
  double expanded = -1.0;
  bool extrapolated = false;  // evaluated at 25 degC outside the fitted range (Figure::extrapolated)
};

// One window's own estimate of a coefficient at the window's temperature T_w: the value of that
// one coefficient that explains the window's mean output exactly on the coefficient's row, every
// other coefficient at its fitted value (a partial residual; equations in coefficient_curves.cc). It
// scatters about the polynomial by the window's noise alone, so the points show what the data say
// where the curve only shows what the fit made of them.
struct CoefficientPoint {
  double temp_c = 0.0;
  double value = 0.0;  // in the group's unit
  double sigma = 0.0;  // 1-sigma from the window mean's own noise (no fit uncertainty in it)
  int segment = -1;
};

// One coefficient against temperature: the polynomial with its 1-sigma band, and the windows'
// own estimates.
struct CoefficientCurve {
  std::string axis;  // "x", "xy", ...
  std::vector<double> temp_c, value, lo, hi;
  std::vector<CoefficientPoint> points;
};
struct CoefficientGroup {
  std::string title;  // "Gyro bias"
  std::string unit;
  bool grid = false;  // draw each curve in its own panel (3x3 for g-sensitivity)
  std::vector<CoefficientCurve> curves;
};

// Per window, signed per-axis errors (corrected - true) before and after correction, in deg/s and
// mg, with the window mean's own noise (1-sigma from the samples' spread) for the band. The accel
// values of a window whose specific force is not known (a turn, a rate about a non-vertical axis)
// are NaN: not drawn, not in the histogram.
struct WindowResiduals {
  std::vector<double> time_s, temp_c;
  std::vector<int> segment;
  std::vector<bool> is_static;
  std::array<std::vector<double>, 3> gyro_dps, gyro_before_dps, gyro_noise_dps;
  std::array<std::vector<double>, 3> accel_mg, accel_before_mg, accel_noise_mg;
  // Histogram of the normalised errors (error / noise) after correction, all axes.
  std::vector<double> histogram_center;
  std::vector<double> gyro_histogram, accel_histogram;
  double normalised_gyro_rms = 0.0, normalised_accel_rms = 0.0;  // ~1 when the model explains the run
};

// A plan with more segments than this prints only the segments with the largest errors after
// correction (the certificate stays within its pages); the complete table is in the struct.
inline constexpr int kMostResidualRowsPrinted = 20;

struct ResidualRow {
  int segment = -1;    // -1: all
  std::string up;      // "+z", or "[0.6, 0, 0.8]" when not along an axis
  std::string motion;  // "static", "+100 deg/s" (about +x when not about up), "turn 360 deg about +x"
  double rate_dps = 0.0;
  int windows = 0;
  int accel_windows = 0;  // with a known specific force: the accel figures are over these (0: none)
  double gyro_rms_before_dps = 0.0, gyro_rms_dps = 0.0, gyro_max_dps = 0.0;
  double accel_rms_before_mg = 0.0, accel_rms_mg = 0.0, accel_max_mg = 0.0;
};

struct ValidationRow {
  double temp_c = 0.0;
  bool fitted = false;
  std::string why_not;
  int windows = 0;
  double gyro_rms_dps = 0.0, gyro_max_dps = 0.0, accel_rms_mg = 0.0, accel_max_mg = 0.0;
  // The held-out fit's temperature orders; lowered when the other temperatures determine no more.
  int gyro_temp_order = 0, accel_temp_order = 0;
  bool order_lowered = false;
};

// The fit's settings and diagnostics, from the calibration's fit record (Calibration::fit; known =
// false without).
struct FitSettings {
  bool known = false;
  std::string loss;
  // Why the solver stopped: the first sentence of Ceres's message ("Function tolerance reached.");
  // the tolerances it quotes after it are in the calibration's fit record.
  std::string termination;
  int iterations = 0, windows_used = 0, windows_downweighted = 0;
  int gyro_temp_order = 3, accel_temp_order = 3;
  bool g_sensitivity_fitted = true;
  double gyro_reduced_chi2 = 0.0, accel_reduced_chi2 = 0.0;
  double gyro_bias_stability_dph = 0.0, accel_bias_stability_ug = 0.0;  // 0: not in the sigmas
  double trim_s = 0.0, window_temp_span_c = 0.0;
  // `plan check`'s limiting coefficient on this run's windows (the limits' tolerances), its predicted
  // sigma next to the one the fit achieved (plan_prediction.h).
  LimitingPrediction limiting;
};

struct RunSummary {
  std::string plan_path;
  int segments = 0, static_segments = 0, turn_segments = 0;
  std::vector<double> rates_dps;        // distinct |rate| of the rate segments
  std::vector<double> turn_angles_deg;  // distinct |angle| of the turns
  // Plan segments with no usable window in the run (never visited, or every visit too short).
  std::vector<int> segments_without_windows;
  double gravity_mps2 = 0.0;
  std::optional<double> latitude_deg;
  long long samples = 0;
  int windows = 0;
  std::vector<double> temperatures_c;  // distinct window temperatures, rounded to 1 degC
  std::array<double, 2> temp_range_c{0.0, 0.0};
  std::vector<double> time_s, window_temp_c;  // temperature against time, per window
};

// A calibration by hand (fit --field, docs/field.md): the session, in place of a plan and a table run.
// From the calibration's `fit:` and `fit: field:` records (a number the record lacks stays < 0).
struct FieldSession {
  std::string body_frame;  // kBodyFrameAccelerometerXy
  int poses = -1, turns = -1, saturated_turns = -1;
  double gravity_mps2 = 0.0;
  std::string gravity_source;  // kGravityStated, kGravityFromLatitude, kGravityStandard; "" not recorded
  std::optional<double> latitude_deg, height_m;
  long long samples = -1;
  std::array<double, 2> temp_range_c{0.0, 0.0};  // the session's readings, degC
  int temp_order = 0;                            // of the biases and scale factors (0: constant)
  bool g_sensitivity_fitted = true;
  // After correction: | |a| - g | RMS over the poses (mg), the corrected gyro at rest (RMS over poses
  // and axes, deg/s), gravity's direction after the turns (RMS, deg), reduced chi-square.
  double accel_norm_rms_mg = -1.0, gyro_static_rms_dps = -1.0, direction_rms_deg = -1.0, reduced_chi2 = -1.0;
  // The rests' accelerometer, the rests' gyro and the turns' noise as multiples of the log's white noise.
  std::array<double, 3> noise_scale{-1.0, -1.0, -1.0};
  int iterations = -1;
  std::string termination;
};

// What a certificate of a calibration by hand says of its references, in words (on the page and in
// the tests): no table, no known rate; gravity and the integrated turns instead.
inline constexpr const char* kFieldReferenceStatement =
    "Calibrated by hand, without a reference table or a known rate: the accelerometer's scale and "
    "misalignment are referred to local gravity (|a| = g in every pose), the gyro's scale and misalignment "
    "to the turns between the poses as the gyro integrated them (gravity's direction before and after each "
    "turn), its bias and g-sensitivity to the poses at rest. The body frame is a convention, "
    "accelerometer_xy: x along the accelerometer's x axis, y in the plane of its x and y axes (docs/spec.md "
    "section 1); it is not a fixture's or a vehicle's frame.";

// The statement every certificate carries (ISO/IEC 17025 7.8.2.1 k).
inline constexpr const char* kItemOnlyStatement =
    "The results in this certificate apply only to the item calibrated, as received. This certificate "
    "shall not be reproduced except in full.";

struct Certificate {
  // Unique and reproducible: "<serial>-<YYYYMMDD of the acquisition, else of the fit>-<the first 8
  // hex digits of the SHA-256 of the inputs' roles and hashes, the customer and the order>"
  // (CertificateNumber); the same inputs give the same number, whenever the page is written.
  std::string number;
  std::string serial;  // empty: none known (then a warning says so)
  std::string unit;
  // When the run was recorded (the samples header's '# acquired:'); "" when not stated, then the
  // fit time (calibrated_utc) stands in for it where a date is judged (the page says so).
  std::string acquired_utc;
  // When the fit ran (the calibration's created_utc) and when this page was written.
  std::string calibrated_utc, written_utc;
  std::string unit_model, unit_firmware, ambient;  // the run header's; "" when not stated
  std::string customer, order;
  std::string calibration_software, report_software, git_revision;
  double reference_temp_c = 25.0;
  std::vector<ReportInput> inputs;  // with their hashes
  std::vector<std::string> warnings;
  std::optional<Station> station;  // none: the signers fill in where and by whom
  RunSummary run;
  FitSettings settings;
  std::optional<Verdict> verdict;
  // The uncertainty budget of the coefficient key figures: what `figures`' U are, what U covers.
  UncertaintyBudget budget;
  std::vector<KeyFigureRow> figures;
  std::vector<CoefficientGroup> curves;
  WindowResiduals residuals;
  std::vector<ResidualRow> residual_table;  // per segment, then all
  // The rows printed: all of residual_table, or (more than kMostResidualRowsPrinted segments) the
  // kMostResidualRowsPrinted - 1 segments whose larger of gyro and accel RMS after correction,
  // each over the run's, is largest, in segment order, then all; residual_rows_omitted counts the others.
  std::vector<ResidualRow> residual_table_printed;
  int residual_rows_omitted = 0;
  NoiseSection noise;
  std::vector<ValidationRow> validation;  // empty: not run
  // A calibration by hand: its session, in place of the run, the plan, the residuals and the curves
  // (empty) and the noise section (not measured: a session by hand has no long static stretch).
  std::optional<FieldSession> field;
};

// Computes the certificate from `sources` alone (no file is read). A calibration by hand (its
// body_frame set) is certified from its own records: sources.plan and sources.run are not used, its
// U is ComputeFieldBudget()'s (a station's Type B sources are a table's: not applied, a warning says
// so), and limits are judged with the calibration's figures (its `noise:` block, if any). A listed input
// without its SHA-256, or a samples input without the noise section, is a programmer error (aborts): call
// ReadCertificateFiles() first.
Certificate MakeCertificate(const CertificateSources& sources);

// The certificate number (Certificate::number) of a unit `serial` (or its folder's name),
// recorded on `date_utc` ("YYYY-MM-DD..."), from `inputs` (with their hashes), customer and order.
std::string CertificateNumber(const std::string& serial, const std::string& date_utc,
                              const std::vector<ReportInput>& inputs, const std::string& customer,
                              const std::string& order);

// The figures the certificate measured itself: ARW and bias instability per gyro axis (a term the
// run does not resolve as a Figure::unresolved, saying what stretch it needs), and the worst window
// error after correction (gyro_residual_max_dps, accel_residual_max_mg).
std::vector<Figure> MeasuredFigures(const Certificate& certificate);

// Where a calibration says it was fitted to other files than the ones given (SHA-256 in its `fit:`
// block): one message per mismatch, empty when they belong together or the calibration does not say.
std::vector<std::string> InputMismatches(const Calibration& calibration, const std::string& plan_path,
                                         const std::string& samples_path);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_CERTIFICATE_H_
