// imufit — a calibration exported to where it is used (`imufit export`, docs/export.md).
//
//   c       a C header for the firmware runtime (model/c/imufit_runtime.h): an initializer macro
//   bin     the runtime's packed little-endian blob (magic, version, length, CRC-32), for EEPROM
//   px4     PX4 parameters in the ground station's tab-separated .params format: the TC_Gn_* /
//           TC_An_* bias cubics, CAL_ACCn_xSCALE, the device IDs (instance n = --instance)
//   ardupilot  ArduPilot parameters (.parm): INS_TCALn_* about its fixed 35 degC, offsets and
//           accelerometer scale at the calibration temperature, INS_ACC_ID / INS_GYR_ID
//   kalibr  Kalibr's imu.yaml: the noise densities and its scale-misalignment intrinsics
//   imucal  imucal's Ferraris JSON (K, R, b, K_ga) at one temperature
//   json    the whole calibration in JSON (the calibration file's schema, docs/calibration.schema.json)
//
// Every format that cannot hold the whole model measures its loss before anything is written: the
// full model (`imufit apply`'s SensorModel::Correct) and the consumer's own equations, evaluated
// with the consumer's arithmetic (float32 where it uses it) on the numbers exactly as the file
// prints them, over the envelope: the temperatures (the calibration's fitted range, or a range
// inside it) x every axis of the angular rate in [-full_scale, full_scale] x every axis of the
// specific force in [-max_g, max_g] g.
// The loss (worst case and RMS per axis, deg/s and mg) and the provenance are written into the
// exported file's comments (or its comment field).
#ifndef IMUFIT_EXPORT_EXPORT_H_
#define IMUFIT_EXPORT_EXPORT_H_

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "imufit/base/option_table.h"
#include "imufit/io/calibration.h"

namespace imufit {

enum class ExportFormat { kC, kBin, kPx4, kArduPilot, kKalibr, kImucal, kJson };

const char* ToString(ExportFormat format);
// The format of a name in any case ("PX4"); nullopt for a name that is not a format.
std::optional<ExportFormat> ExportFormatFromString(std::string_view name);
// "c, bin, px4, ardupilot, kalibr, imucal, json".
std::string ExportFormatNames();

// What an export is asked for. ExportOptionTable() describes each option (the command line of
// `imufit export`, its help and validation messages); the defaults are these. An option that
// serves only some formats says which (ExportOptionFormats()), and `imufit export` refuses it with
// another.
struct ExportOptions {
  ExportFormat format = ExportFormat::kJson;
  // The envelope the loss is measured over: the temperatures, each axis of the angular rate in
  // [-full_scale_dps, full_scale_dps], each axis of the specific force in [-max_g, max_g] g.
  // envelope_temp_c: {min, max} degC inside the calibration's fitted range; empty: that range.
  std::vector<double> envelope_temp_c;
  double full_scale_dps = 500.0;
  double max_g = 2.0;
  // What the consumer's driver divides the unit's raw output by to give SI (px4, ardupilot,
  // kalibr, which read rad/s and m/s^2 from a driver): raw per rad/s, raw per m/s^2. 1 for a unit
  // that reports SI; 939.65 for a +/-2000 deg/s gyro at 16.4 LSB per deg/s.
  double gyro_raw_per_radps = 1.0;
  double accel_raw_per_mps2 = 1.0;
  // The temperature the one-temperature formats (kalibr, imucal) are taken at, degC; by default
  // the calibration's reference temperature clamped to its fitted range.
  std::optional<double> temp_c;
  // px4, ardupilot: the sensors' device IDs (PX4's TC_G0_ID / CAL_GYRO0_ID and TC_A0_ID /
  // CAL_ACC0_ID; ArduPilot's INS_GYR_ID and INS_ACC_ID). device_id serves both sensors (one die);
  // gyro_device_id and accel_device_id each one (separate dies). Required.
  std::optional<long long> device_id;
  std::optional<long long> gyro_device_id;
  std::optional<long long> accel_device_id;
  // px4: the parameter instance 0..3 (TC_G<n>, TC_A<n>, CAL_GYRO<n>, CAL_ACC<n>), default 0;
  // ardupilot: 1..3 (INS_TCAL<n>, INS_ACC/ACC2/ACC3, INS_GYR/GYR2/GYR3), default 1.
  std::optional<int> instance;
  // c: the C identifier the header is named by (NAME_INITIALIZER, NAME_H_).
  std::string c_name = "imufit_unit";
  // kalibr: the IMU's ROS topic.
  std::string rostopic = "/imu0";
  // Provenance, written into the file: the exporting program, the calibration file (its base
  // name) and the SHA-256 of its bytes.
  std::string software;
  std::string calibration_file;
  std::string calibration_sha256;

  // "" when valid, else a readable reason naming the option and its value.
  std::string Validate() const;
};
// Every option but the provenance (software, calibration_file, calibration_sha256).
const OptionTable<ExportOptions>& ExportOptionTable();
// Whether the option `key` of ExportOptionTable() serves `format`.
bool ExportOptionServes(const std::string& key, ExportFormat format);
// The formats the option `key` serves, "kalibr, imucal"; "" when it serves every format.
std::string ExportOptionFormats(const std::string& key);

// The error of the consumer's correction against the full model over the envelope, per axis.
struct ExportLoss {
  bool measured = false;  // false: nothing is lost (json, and the coefficients of c and bin)
  long long points = 0;   // samples of the envelope evaluated
  Eigen::Vector3d gyro_worst_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_rms_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_worst_mg = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_rms_mg = Eigen::Vector3d::Zero();
};

struct ExportResult {
  std::string content;  // the file's bytes
  ExportLoss loss;
  std::string consumer;  // the consumer and the version of its equations that were emulated
  std::string envelope;  // the envelope, in words
  // What the user must know (a parameter range clamped, offsets a consumer takes for "not
  // calibrated"), one sentence each; also in the file.
  std::vector<std::string> warnings;
};

// Thrown when the calibration cannot be exported to the format (exit status 1): a term the
// consumer requires is missing (kalibr without a noise block), a serial too long for the blob.
class ExportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Converts, measures the loss, and returns the file's content with the loss and provenance in it.
// Throws InputError for options the format cannot use (a px4 export without a device ID, a
// non-positive envelope) and ExportError when the calibration cannot be exported.
ExportResult ExportCalibration(const Calibration& calibration, const ExportOptions& options);

// The loss as lines of text ("gyro  worst x .. y .. z .. deg/s, rms ..."), each prefixed.
std::string DescribeLoss(const ExportResult& result, const std::string& prefix);

// One line saying by how much the loss exceeds the bounds (worst case over the axes, deg/s and
// mg), or nullopt when it is within them.
std::optional<std::string> LossBeyondBounds(const ExportLoss& loss, double max_gyro_dps, double max_accel_mg);

// The --format bin blob of model/c/imufit_runtime.h. Throws ExportError for a serial over 63
// bytes.
std::string CalibrationBlob(const Calibration& calibration, const std::string& sha256_hex);

// A bound on the error of the float build of the C runtime against the full model (double) for
// one sample, per output axis, derived by propagating the float32 rounding of every operation the
// runtime performs (docs/export.md). Valid for a temperature inside the fitted range that, like the
// reference temperature and the raw values, is exact in float.
struct FloatRuntimeBound {
  Eigen::Vector3d omega_radps;
  Eigen::Vector3d a_mps2;
};
FloatRuntimeBound FloatRuntimeErrorBound(const SensorModel& model, double temp_c,
                                         const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw);

}  // namespace imufit

#endif  // IMUFIT_EXPORT_EXPORT_H_
