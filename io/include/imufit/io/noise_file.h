// imufit — the files of the noise analysis (docs/allan.md): the Allan deviation CSV and the
// `noise:` YAML block (written by `imufit allan --noise-yaml`, appended to a calibration, read back
// by acceptance limits and certificates), with the engineer units of each IEEE 952 term.
//
//   allan.csv: column,estimator,tau_s,terms,dev,dev_lo,dev_hi — one row per column and tau.
//   noise:     format imufit-noise, version 1; the samples (and the calibration they were corrected
//              through, with its SHA-256, when there was one: optional); per column: kind, unit, fitted (or
//              reason), points_used, reduced_chi_square, every term as [value, 1-sigma] in SI and in engineer
//              units, `<term>_resolved: false` for a term the fit did not resolve, the graphical
//              read-outs; then Kalibr's continuous-time densities (the worst axis of each sensor).
//
// io owns the format: the records below are plain, and the caller fills them from its analysis
// (app/allan_command.cc from noise/column_analysis.h), so io does not depend on noise. Written
// through the one writer of machine-readable text (machine_text.h).
#ifndef IMUFIT_IO_NOISE_FILE_H_
#define IMUFIT_IO_NOISE_FILE_H_

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "imufit/base/noise_terms.h"
#include "imufit/io/output_file.h"

namespace imufit {

// How one noise term of one kind of column is named and scaled on output (io/units.h).
struct NoiseTermUnits {
  const char* si_key;  // YAML key of the SI value
  const char* si_unit;
  const char* engineer_key;  // YAML key in engineer units ("" = none)
  const char* engineer_unit;
  double engineer_per_si;
  const char* label;  // for people
};
const NoiseTermUnits& UnitsOf(ColumnKind kind, int term);

// One column's Allan-family deviation curve, as the CSV holds it.
struct AllanCurveRecord {
  struct Point {
    double tau_s = 0.0;
    long long terms = 0;
    double dev = 0.0;  // and its confidence interval (nan when unknown)
    double dev_lo = 0.0;
    double dev_hi = 0.0;
  };
  std::string column;
  std::string estimator;  // as the CSV names it: "oadev", ...
  std::vector<Point> points;
};

// Writes the Allan deviation CSV atomically, in `transaction` when not null.
void WriteAllanCsv(const std::string& path, const std::vector<AllanCurveRecord>& curves,
                   OutputTransaction* transaction = nullptr);

// One column of the noise block: the IEEE 952 terms fitted to its Allan variance, SI units of the
// column (noise/noise_model.h), or why there are none.
struct NoiseColumnRecord {
  std::string name;
  ColumnKind kind = ColumnKind::kOther;
  bool fitted = false;
  std::string reason;  // why not fitted
  int points_used = 0;
  double reduced_chi_square = std::nan("");  // not written when not finite
  // Each term's value and 1-sigma (a pair not written unless both are finite), and whether the fit
  // resolved it from zero.
  std::array<double, kNoiseTerms> value = {0, 0, 0, 0, 0};
  std::array<double, kNoiseTerms> sigma = {0, 0, 0, 0, 0};
  std::array<bool, kNoiseTerms> resolved = {false, false, false, false, false};
  // The graphical read-outs of the measured curve, in the units the file writes them: engineer
  // units (UnitsOf(kind, term).engineer_key) where the kind has them, else SI; the SI value times
  // engineer_per_si. nan when the curve has no such region (then not written).
  double readout_random_walk = std::nan("");
  double readout_bias_instability = std::nan("");
  double readout_bias_tau_s = std::nan("");
  double readout_rate_random_walk = std::nan("");
  // Where the read-outs were read (seconds): the -1/2 and +1/2 segments; the minimum's 95 %
  // interval (units of the bias read-out) and whether it is resolved (a rise on both sides).
  std::array<double, 2> readout_random_walk_taus_s = {std::nan(""), std::nan("")};
  std::array<double, 2> readout_rate_random_walk_taus_s = {std::nan(""), std::nan("")};
  std::array<double, 2> readout_bias_interval = {std::nan(""), std::nan("")};
  bool readout_bias_resolved = false;
  // The longest tau left out of the fit and the read-outs for too few intervals (nan: none).
  double skipped_tau_s = std::nan("");

  // Whether the fitted model describes the curve (reduced chi-square at most the threshold of
  // docs/allan.md); the taus the fit used, and per term where it carries a share of the model.
  bool describes_curve = true;
  std::array<double, 2> fit_taus_s = {std::nan(""), std::nan("")};
  std::array<std::array<double, 2>, kNoiseTerms> term_taus_s = {};
  // An output filter detected in the samples: the samples' lag-1 autocorrelation and the first tau
  // the fit used past the filtered ones (nan when no filter).
  bool filter_detected = false;
  double sample_lag1 = std::nan("");
  double filtered_below_tau_s = std::nan("");

  // The figure to quote per term (docs/allan.md "Which figure to quote"), in the units the file
  // writes it (engineer units where the kind has them, as the read-outs): a value with its 1-sigma
  // and 2-sigma interval, or an upper bound (at_most); `from` says where it comes from (nan:
  // nothing to quote, not written).
  struct Quote {
    double value = std::nan("");  // the figure; an upper bound when at_most
    double sigma = std::nan("");
    std::array<double, 2> interval = {std::nan(""), std::nan("")};
    bool at_most = false;
    std::string from;
  };
  std::array<Quote, kNoiseTerms> quote;
  YAML::Node extra;  // keys of the column this reader does not know (a map, or null)

  NoiseColumnRecord() {
    for (auto& taus : term_taus_s) taus = {std::nan(""), std::nan("")};
  }
};

// Kalibr's imu.yaml continuous-time figures (nan: unknown, not written). OpenVINS reads the same
// keys (kalibr_imu_chain.yaml, imu0); VINS-Mono's acc_n, gyr_n, acc_w, gyr_w are the same figures.
struct KalibrNoiseRecord {
  double gyroscope_noise_density = std::nan("");      // rad/s/sqrt(Hz)
  double gyroscope_random_walk = std::nan("");        // rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = std::nan("");  // m/s^2/sqrt(Hz)
  double accelerometer_random_walk = std::nan("");    // m/s^3/sqrt(Hz)
  double update_rate = std::nan("");                  // Hz
  // Where each of the four figures comes from ("gyro_y: IEEE 952 fit ..."; "" when not known), and
  // the factor the figures were multiplied by (NoiseRecord::vio_inflation).
  std::string gyroscope_noise_density_from, gyroscope_random_walk_from, accelerometer_noise_density_from,
      accelerometer_random_walk_from;
  double inflation = 1.0;
};
// The inflation of static noise figures advised before an estimator uses them in motion
// (docs/allan.md "Noise blocks for estimators"), as text.
inline constexpr const char* kAdvisedVioInflation =
    "2 to 10 in motion (vibration, temperature change and model error raise the noise over a static "
    "log; check with your estimator's consistency)";

// The noise block: what it says about the record the columns came from, and the columns. Written
// and read by io (NoiseYaml, ReadNoiseFile, and a calibration's `noise:` key, Calibration::noise);
// everyone else holds this struct. A member a file does not state reads as its default here (text
// empty, numbers nan, sample_count 0) and is then not written.
struct NoiseRecord {
  std::string software;
  std::string samples;
  // The calibration the raw samples were corrected through on the way in (`imufit allan
  // --calibration`) and its SHA-256: the figures are the corrected unit's, so a reader must be able
  // to tell which correction. Both "" (and not written) for samples analysed as they are.
  std::string calibration;
  std::string calibration_sha256;
  double sample_interval_s = std::nan("");
  long long sample_count = 0;
  double duration_s = std::nan("");
  std::vector<NoiseColumnRecord> columns;
  // Kalibr's figures as a file states them; when not set, KalibrNoiseOf() derives them from the
  // columns (what `imufit allan` writes).
  std::optional<KalibrNoiseRecord> kalibr;
  // The factor the estimator blocks (kalibr, openvins, vins_mono) multiply the measured figures by
  // (`imufit allan --vio-inflation`; 1: as measured).
  double vio_inflation = 1.0;
  YAML::Node extra;  // keys of the block this reader does not know (a map, or null)
};
// The block's Kalibr figures: `record.kalibr` when set, else the worst axis of each sensor of the
// figures to quote (NoiseColumnRecord::quote: the fit where it describes the curve, else the
// read-out, an unresolved term's upper bound), times vio_inflation, and 1 / sample_interval_s. A
// column without quotes (a file of an older imufit) gives its fitted value, an unresolved term its
// upper bound (value + 2 sigma).
KalibrNoiseRecord KalibrNoiseOf(const NoiseRecord& record);
// The text of the noise block (top-level key `noise:`), with a comment saying what it is.
std::string NoiseYaml(const NoiseRecord& record);
// Writes it atomically, in `transaction` when not null.
void WriteNoiseYaml(const std::string& path, const NoiseRecord& record,
                    OutputTransaction* transaction = nullptr);
// Reads the `noise:` block of a file `imufit allan --noise-yaml` wrote (alone, or appended to a
// calibration). Throws InputError naming the file, and the key where a value has the wrong type.
NoiseRecord ReadNoiseFile(const std::string& path);

// [value, 1-sigma] of a fitted column's term, in the units of `key` (any term's SI key or engineer
// key of UnitsOf(column's kind, term)), when `noise` has that column and the pair is finite.
std::optional<std::array<double, 2>> NoiseFigure(const std::optional<NoiseRecord>& noise,
                                                 const std::string& column, const std::string& key);

// What a noise file says about each sensor, for a plan judged with the unit's measured noise
// (`imufit plan check --noise-yaml`): the worst axis of the fitted columns of each kind, SI.
struct SensorNoiseFigures {
  double gyro_noise_density = 0.0;      // rad/s/sqrt(Hz): the white (random walk) term
  double gyro_bias_instability = 0.0;   // rad/s (0 when no gyro column resolved it)
  double accel_noise_density = 0.0;     // m/s^2/sqrt(Hz)
  double accel_bias_instability = 0.0;  // m/s^2
};
// Reads the noise block written by `imufit allan --noise-yaml` (alone or appended to a calibration).
// Throws InputError naming the file when it is not one, or when a sensor has no fitted white noise.
SensorNoiseFigures ReadSensorNoise(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_NOISE_FILE_H_
