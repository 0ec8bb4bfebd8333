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
#ifndef IMUFIT_IO_NOISE_FILE_H_
#define IMUFIT_IO_NOISE_FILE_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "imufit/io/output_file.h"
#include "imufit/noise/column_analysis.h"

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

// Writes the Allan deviation CSV (each column's `curve`) atomically, in `transaction` when not null.
void WriteAllanCsv(const std::string& path, const std::vector<ColumnAnalysis>& results,
                   OutputTransaction* transaction = nullptr);

// What the noise block says about the record the columns came from.
struct NoiseRecord {
  std::string software;
  std::string samples;
  // The calibration the raw samples were corrected through on the way in (`imufit allan
  // --calibration`) and its SHA-256: the figures are the corrected unit's, so a reader must be able
  // to tell which correction. Both "" (and not written) for samples analysed as they are.
  std::string calibration;
  std::string calibration_sha256;
  double sample_interval_s = 0.0;
  long long sample_count = 0;
  double duration_s = 0.0;
};
// The text of the noise block (top-level key `noise:`).
std::string NoiseYaml(const NoiseRecord& record, const std::vector<ColumnAnalysis>& results);
// Writes it atomically, in `transaction` when not null.
void WriteNoiseYaml(const std::string& path, const NoiseRecord& record,
                    const std::vector<ColumnAnalysis>& results, OutputTransaction* transaction = nullptr);

// [value, 1-sigma] of noise.columns.<column>.<key> in a calibration's further keys (Calibration::
// extra), when there and a pair of numbers.
std::optional<std::array<double, 2>> ReadNoiseFigure(const YAML::Node& calibration_extra,
                                                     const std::string& column, const std::string& key);

}  // namespace imufit

#endif  // IMUFIT_IO_NOISE_FILE_H_
