// imufit — what the exporters of export/src/export_*.cc share: the envelope and the loss measurement,
// the numbers as a consumer prints and reads them, provenance comments, one function per format.
#ifndef IMUFIT_IO_SRC_EXPORT_INTERNAL_H_
#define IMUFIT_IO_SRC_EXPORT_INTERNAL_H_

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "imufit/export/export.h"
#include "imufit/io/machine_text.h"
#include "imufit/model/constants.h"
#include "imufit/model/sensor_model.h"

namespace imufit::export_internal {

// A consumer's correction of one sample, evaluated as the consumer evaluates it: raw outputs of
// the unit in, angular rate (rad/s) and specific force (m/s^2) in imufit's body frame out.
using ConsumerCorrection =
    std::function<void(double temp_c, const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw,
                       Eigen::Vector3d* omega_radps, Eigen::Vector3d* a_mps2)>;

// The envelope in SI: the fitted temperature range, the largest rate and specific force per axis.
struct Envelope {
  double temp_low_c = 0.0;
  double temp_high_c = 0.0;
  double full_scale_radps = 0.0;
  double max_specific_force_mps2 = 0.0;
  // Where each bound comes from, in words naming the option that changes it.
  std::string temp_source, rate_source, force_source;
};
// Throws InputError for a temperature range outside the calibration's fitted range.
Envelope EnvelopeOf(const Calibration& calibration, const ExportOptions& options);
std::string DescribeEnvelope(const Envelope& envelope);

// The consumer's error against SensorModel::Correct on a grid over the envelope: 26 temperatures
// across the range (ends included), 5 levels per axis of the rate and of the specific force
// (-1, -1/2, 0, 1/2, 1 of the envelope), the raw outputs made by the model's exact inverse.
ExportLoss MeasureLoss(const SensorModel& model, const Envelope& envelope,
                       const ConsumerCorrection& consumer);

// The text a float32 parameter is printed as (9 significant digits: reads back as exactly the
// nearest float of `value`), and the float a consumer reads from it. Throws ExportError, naming
// `name`, for a value that is not finite in float.
std::string FloatText(double value, const std::string& name);
float ReadFloat(const std::string& text);
// The shortest text that reads back as exactly `value`. Throws ExportError for a non-finite value.
std::string DoubleText(double value, const std::string& name);
double ReadDouble(const std::string& text);
// "[a, b, c]" in shortest round-trip numbers; `read_back` gets what a reader parses from it.
std::string VectorText(const Eigen::Vector3d& v, const std::string& name, Eigen::Vector3d* read_back);
// "[[a, b, c], [d, e, f], [g, h, i]]" on one line when `indent` is empty, else one row per line
// indented by `indent` plus two spaces, the closing bracket by `indent`.
std::string MatrixText(const Eigen::Matrix3d& m, const std::string& name, const std::string& indent,
                       Eigen::Matrix3d* read_back);

// A number, vector or matrix (a list of rows, on one line or one row a line) as the one writer of
// machine-readable text writes it (io/machine_text.h), and what a reader parses from it. Throws
// ExportError, naming `name`, for a value that is not finite.
MachineDoc NumberDoc(double value, const std::string& name);
MachineDoc VectorDoc(const Eigen::Vector3d& v, const std::string& name, Eigen::Vector3d* read_back);
MachineDoc MatrixDoc(const Eigen::Matrix3d& m, const std::string& name, MachineDoc::Style rows,
                     Eigen::Matrix3d* read_back);

// `text` with every character outside printable ASCII replaced by '?' and "*/" broken up: safe
// inside any comment.
std::string CommentSafe(std::string_view text);
// The calibration file's base name, safe for a comment.
std::string CalibrationFileName(const ExportOptions& options);
// The provenance and loss lines of an exported file (without comment markers).
std::vector<std::string> ProvenanceLines(const Calibration& calibration, const ExportOptions& options,
                                         const ExportResult& result);
// Every line prefixed with `marker` ("# ") and ended.
std::string Commented(const std::vector<std::string>& lines, const std::string& marker);
// A result naming its consumer and envelope, with the consumer's loss measured over it.
ExportResult MeasuredResult(const char* consumer, const Calibration& calibration, const Envelope& envelope,
                            const ConsumerCorrection& correction);

// The device IDs of a px4 or ardupilot export: --gyro-device-id / --accel-device-id, else
// --device-id, as the INT32 parameter holds the unsigned 32 bits. Throws InputError naming the
// options when one is missing.
struct SensorIds {
  int32_t gyro = 0;
  int32_t accel = 0;
};
SensorIds DeviceIds(const ExportOptions& options, const char* format);
// --instance, within [low, high] for `format`, else `fallback`. Throws InputError outside.
int InstanceOf(const ExportOptions& options, int low, int high, int fallback, const char* format);
// Per axis the larger worst case and the larger RMS of two measurements over the same envelope.
ExportLoss WorstOf(const ExportLoss& a, const ExportLoss& b);
// "gyro worst x .. y .. z deg/s, accel worst x .. y .. z mg".
std::string WorstFigures(const ExportLoss& loss);

// The cubic `c` (powers of T - from_reference_c) re-expanded exactly in powers of T - to_reference_c.
Eigen::Vector4d Rebased(const double* c, double from_reference_c, double to_reference_c);
// The cubic of coefficient `index` of a sensor's parameters.
inline const double* Cubic(const double* params, int index) { return params + index * kPolynomialTerms; }
// A sensor's coefficients at one temperature.
SensorCoefficients<double> GyroAt(const SensorModel& model, double temp_c);
SensorCoefficients<double> AccelAt(const SensorModel& model, double temp_c);
// temp_c clamped to the calibration's fitted range.
double ClampToRange(const Calibration& calibration, double temp_c);

// One function per format: the content (without the provenance, which they add themselves), the
// loss, the consumer's name and version.
ExportResult ExportC(const Calibration& calibration, const ExportOptions& options, const Envelope& envelope);
ExportResult ExportBin(const Calibration& calibration, const ExportOptions& options,
                       const Envelope& envelope);
ExportResult ExportPx4(const Calibration& calibration, const ExportOptions& options,
                       const Envelope& envelope);
ExportResult ExportArduPilot(const Calibration& calibration, const ExportOptions& options,
                             const Envelope& envelope);
ExportResult ExportKalibr(const Calibration& calibration, const ExportOptions& options,
                          const Envelope& envelope);
ExportResult ExportImucal(const Calibration& calibration, const ExportOptions& options,
                          const Envelope& envelope);
ExportResult ExportJson(const Calibration& calibration, const ExportOptions& options);

}  // namespace imufit::export_internal

#endif  // IMUFIT_IO_SRC_EXPORT_INTERNAL_H_
