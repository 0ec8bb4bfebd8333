// imufit — the fit's record in a calibration file: the `fit:` block (what the fit did, on which
// files) and the `check:` block (its errors on a held-out run) of docs/spec.md section 3, as typed
// structs. pipeline's FitRun fills them, io writes and reads them (calibration.h), and the
// acceptance verdict, the certificate and the Python module read their members: nobody else
// looks a key up by its name.
//
// Each block is declared once, as a table of (type, key, what it says) from which the struct's
// members (named as the keys), the writer, the reader and the Python attributes are all derived.
// The table's order is the order in which the keys are written. Every member is optional: a file
// written by an older imufit, or edited by hand, may lack any key, and a member that is not set is
// not written. Keys of the block the reader does not know are kept in `extra` and written after
// the known ones. Lists of numbers (temperatures) are written one item per line, lists of names
// and ids on one line.
#ifndef IMUFIT_IO_FIT_RECORD_H_
#define IMUFIT_IO_FIT_RECORD_H_

#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

// X(type, key, description): the `fit:` block. SI units, as the keys say.
#define IMUFIT_FIT_RECORD_FIELDS(X)                                                                     \
  X(std::string, plan, "the plan file, as given")                                                       \
  X(std::string, samples, "the samples file, as given")                                                 \
  X(std::string, plan_sha256, "SHA-256 of the plan file")                                               \
  X(std::string, samples_sha256, "SHA-256 of the samples file")                                         \
  X(std::string, acquired_utc, "when the run was recorded (the samples header's '# acquired:'), UTC")   \
  X(std::string, unit_model, "the product's model or part number (the samples header's '# model:')")    \
  X(std::string, unit_firmware, "the unit's firmware (the samples header's '# firmware:')")             \
  X(std::string, ambient, "the laboratory's conditions (the samples header's '# ambient:')")            \
  X(long long, samples_read, "samples in the file")                                                     \
  X(int, segments_found_in_data, "a file without a segment column: the segments found in the data")     \
  X(int, plan_passes_found, "a file without a segment column: complete passes through the plan")        \
  X(int, windows_used, "windows the fit used")                                                          \
  X(int, windows_downweighted, "windows the robust loss down-weighted")                                 \
  X(std::vector<double>, distinct_temperatures_c, "the distinct temperatures of the windows, degC")     \
  X(int, iterations, "solver iterations over all passes")                                               \
  X(std::string, termination, "why the solver stopped, in its own words")                               \
  X(double, gyro_residual_rms_radps, "RMS of the gyro residuals, rad/s")                                \
  X(double, accel_residual_rms_mps2, "RMS of the accelerometer residuals, m/s^2")                       \
  X(double, gyro_reduced_chi2, "reduced chi-square of the gyro residuals")                              \
  X(double, accel_reduced_chi2, "reduced chi-square of the accelerometer residuals")                    \
  X(int, gyro_temp_order, "order of the gyro's temperature polynomials")                                \
  X(int, accel_temp_order, "order of the accelerometer's temperature polynomials")                      \
  X(bool, g_sensitivity_fitted, "whether the gyro g-sensitivity was fitted (else held at zero)")        \
  X(std::vector<std::string>, fitted, "the coefficient groups the fit estimated, e.g. gyro.bias")       \
  X(std::vector<std::string>, held, "the groups held at their stated values (sigma 0)")                 \
  X(std::string, held_values, "where the held values came from: prior, or scale 1, others 0")           \
  X(std::vector<std::string>, uncalibrated_sensors,                                                     \
    "sensors held whole without a prior (gyro, accel): not calibrated by this file")                    \
  X(std::string, loss, "the robust loss")                                                               \
  X(double, gyro_bias_stability_radps, "the gyro bias stability in the sigmas, rad/s (0: white noise)") \
  X(double, accel_bias_stability_mps2, "the accelerometer bias stability in the sigmas, m/s^2")         \
  X(double, bias_correlation_s, "correlation time of that bias wander, s")                              \
  X(std::vector<int>, segments_without_windows, "plan segments without a single usable window")         \
  X(int, missing_segments, "how many segments that is")                                                 \
  X(std::string, inconsistent, "written with --write-inconsistent: why the fit is inconsistent")        \
  X(FieldRecord, field, "a calibration by hand (fit --field): the session's own figures")

// X(type, key, description): the `fit: field:` block of a calibration by hand (fit --field,
// docs/field.md): the session's own figures.
#define IMUFIT_FIELD_RECORD_FIELDS(X)                                                               \
  X(int, poses, "rests the fit used")                                                               \
  X(int, turns, "turns between them the fit used")                                                  \
  X(double, gravity_mps2, "the local gravity the fit used, m/s^2")                                  \
  X(double, accel_norm_rms_mps2, "RMS over the rests of |a| - g after correction, m/s^2")           \
  X(double, gyro_static_rms_radps, "RMS of the corrected gyro at rest, over rests and axes, rad/s") \
  X(double, gravity_direction_rms_rad, "RMS over the turns of the gravity direction's error, rad")  \
  X(double, reduced_chi2, "reduced chi-square of the weighted residuals")                           \
  X(double, noise_scale_accel_rests,                                                                \
    "the rests' accelerometer noise as a multiple of the log's white noise")                        \
  X(double, noise_scale_gyro_rests, "the rests' gyro noise as a multiple of the log's white noise") \
  X(double, noise_scale_turns, "the turns' noise as a multiple of the log's white noise")           \
  X(int, saturated_turns, "turns left out because a gyro axis touched its converter's rail")        \
  X(std::string, gravity_source,                                                                    \
    "where gravity_mps2 came from: stated (--gravity-mps2), latitude (WGS-84 normal gravity at "    \
    "latitude_deg, height_m), standard (9.80665 m/s^2: no local gravity given)")                    \
  X(double, latitude_deg, "with gravity_source latitude: the geodetic latitude, degrees")           \
  X(double, height_m, "with gravity_source latitude: the height above the ellipsoid, m")            \
  X(std::vector<std::string>, session_samples,                                                      \
    "several sessions fitted jointly: the samples files, as given, in order (one session: absent)") \
  X(std::vector<std::string>, session_samples_sha256, "SHA-256 of each session's samples file")     \
  X(std::vector<int>, session_samples_read, "samples in each session's file")                       \
  X(std::vector<int>, session_poses, "rests each session contributed")                              \
  X(std::vector<int>, session_turns, "turns within each session (none joins two sessions)")         \
  X(std::vector<double>, session_temp_min_c, "each session's coldest reading, degC")                \
  X(std::vector<double>, session_temp_max_c, "each session's warmest reading, degC")                \
  X(bool, session_biases_tested,                                                                    \
    "whether each session's biases could be tested against the joint fit (false: the curve in "     \
    "temperature absorbs a session's offset, a turn-on offset is taken for temperature unseen)")    \
  X(std::vector<double>, session_gyro_bias_chi2,                                                    \
    "when tested: each session's gyro bias offset from the joint fit, chi-square for 3")            \
  X(std::vector<double>, session_accel_bias_chi2,                                                   \
    "when tested: each session's accelerometer bias offset from the joint fit, chi-square for 3")

// X(type, key, description): the `check:` block, with `imufit fit --check-samples`.
#define IMUFIT_CHECK_RECORD_FIELDS(X)                                      \
  X(std::string, samples, "the held-out samples file, as given")           \
  X(double, gyro_error_rms_radps, "RMS of the gyro errors over it, rad/s") \
  X(double, accel_error_rms_mps2, "RMS of the accelerometer errors, m/s^2")

#define IMUFIT_RECORD_MEMBER(type, key, description) std::optional<type> key;

namespace imufit {

struct FieldRecord {
  IMUFIT_FIELD_RECORD_FIELDS(IMUFIT_RECORD_MEMBER)
  YAML::Node extra;
};

struct FitRecord {
  IMUFIT_FIT_RECORD_FIELDS(IMUFIT_RECORD_MEMBER)
  YAML::Node extra;  // keys of the block this reader does not know (a map, or null)
};

struct CheckRecord {
  IMUFIT_CHECK_RECORD_FIELDS(IMUFIT_RECORD_MEMBER)
  YAML::Node extra;
};

}  // namespace imufit

#undef IMUFIT_RECORD_MEMBER

#endif  // IMUFIT_IO_FIT_RECORD_H_
