// imufit — the calibration file (docs/spec.md section 3): what the fit exports and consumers read.
//
// Coefficients are written as lists c0..c3 of powers of dT = T - 25 degC, each number in its
// shortest round-trip form, so write -> read gives back the same doubles (==). An optional
// `sigma` tree mirrors the coefficients with their 1-sigma uncertainties; the optional `fit:` and
// `check:` blocks are the fit's typed record (fit_record.h), the optional `noise:` block the
// unit's noise record (noise_file.h). Written through the one writer of machine-readable text
// (machine_text.h). Keys the reader does not know are
// kept in `extra` (and written back); a `format` other than imufit-calibration or a version above
// kCalibrationFormatVersion is refused.
#ifndef IMUFIT_IO_CALIBRATION_H_
#define IMUFIT_IO_CALIBRATION_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "imufit/io/fit_record.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/noise_file.h"
#include "imufit/io/output_file.h"
#include "imufit/model/sensor_model.h"

namespace imufit {

inline constexpr int kCalibrationFormatVersion = 1;

// The body frames a calibration may state (docs/spec.md section 1): x along the accelerometer's x
// axis, y in the plane of its x and y axes.
inline constexpr const char* kBodyFrameAccelerometerXy = "accelerometer_xy";

// Where a calibration by hand's gravity came from (`fit: field: gravity_source:`).
inline constexpr const char* kGravityStated = "stated";          // --gravity-mps2
inline constexpr const char* kGravityFromLatitude = "latitude";  // --latitude, --height-m
inline constexpr const char* kGravityStandard = "standard";      // 9.80665 m/s^2, none given

struct Calibration {
  std::string serial;
  std::string created_utc;  // ISO 8601, e.g. "2026-11-22T06:00:00Z"
  std::string software;     // e.g. "imufit 0.1.0"
  std::array<double, 2> fit_temp_range_c{-40.0, 85.0};
  // The body frame's convention (`body_frame:`): a calibration by hand states kBodyFrameAccelerometerXy;
  // absent, the axes of the table's fixture.
  std::optional<std::string> body_frame;
  // The coefficients, in powers of x = T - reference_temp_c (basis.center_c; half_range_c = 1).
  // imufit writes reference_temp_c = 25 degC; a reader honours whatever the file states.
  SensorModel model;
  // 1-sigma of every parameter, same layout as `model` (its basis is not used).
  std::optional<SensorModel> sigma;
  // What the fit did and on which files (`fit:`), and its errors on a held-out run (`check:`).
  std::optional<FitRecord> fit;
  std::optional<CheckRecord> check;
  // The unit's noise figures (`noise:`, appended from `imufit allan --noise-yaml`: noise_file.h).
  std::optional<NoiseRecord> noise;
  // Further top-level keys: a YAML map, written after the records; on reading, every key this
  // reader does not know. Holds no `fit`, `check`, `noise` or `body_frame` key.
  YAML::Node extra;
};

Calibration ReadCalibration(const std::string& path);
// The file's text; `calibration.model.basis.half_range_c` must be 1.
std::string CalibrationToYaml(const Calibration& calibration);
// The file as a document (machine_text.h), as CalibrationToYaml() writes it, with `extra`'s keys
// as they were read (a quoted "12" stays a string): what an exporter writes as JSON.
MachineDoc CalibrationDoc(const Calibration& calibration);
// Writes atomically (OutputFile), in `transaction` when not null.
void WriteCalibration(const std::string& path, const Calibration& calibration,
                      OutputTransaction* transaction = nullptr);

// The sensors ("gyro", "accel") that `calibration` does not calibrate: held whole at nominal
// values (scale 1 raw per SI unit, the rest 0) by a fit that estimated only the other sensor
// (`imufit fit --fit accel` without --prior). Read from the record's `uncalibrated_sensors`; for a
// file written before that key, from its `held` groups and `held_values`. A consumer that would
// use such a sensor as calibrated (apply, export, a certificate) refuses or marks it.
std::vector<std::string> UncalibratedSensors(const Calibration& calibration);

// The current UTC time as "YYYY-MM-DDTHH:MM:SSZ".
std::string UtcNow();

}  // namespace imufit

#endif  // IMUFIT_IO_CALIBRATION_H_
