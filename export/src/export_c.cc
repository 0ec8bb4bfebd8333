// --format c and bin: the coefficients for the C runtime (model/c/imufit_runtime.h), as a header
// with an initializer and as the packed blob; the float and double builds measured as consumers.
#include <cmath>
#include <cstdint>
#include <cstring>

#include <zlib.h>

#include "export_internal.h"
#include "imufit/io/error.h"
#include "imufit/model/check.h"
#include "imufit_runtime.h"
#define IMUFIT_RUNTIME_FLOAT
#include "imufit_runtime.h"  // the float build's declarations: imufit_calibration_f, imufit_correct_f

namespace imufit {
namespace export_internal {
namespace {

constexpr const char* kConsumer = "the imufit C runtime (model/c/imufit_runtime.h, blob format 1)";

// The runtime's struct (double or float build) filled from a calibration as a compiler fills it
// from the header's initializer: every double converted to the build's type.
template <typename Runtime>
Runtime RuntimeCalibration(const Calibration& calibration) {
  Runtime runtime{};
  std::strncpy(runtime.serial, calibration.serial.c_str(), IMUFIT_SERIAL_BYTES - 1);
  using Real = decltype(runtime.reference_temp_c);
  runtime.reference_temp_c = static_cast<Real>(calibration.model.basis.center_c);
  runtime.temp_min_c = static_cast<Real>(calibration.fit_temp_range_c[0]);
  runtime.temp_max_c = static_cast<Real>(calibration.fit_temp_range_c[1]);
  for (int i = 0; i < kGyroCoefficients * kPolynomialTerms; ++i) {
    runtime.gyro[i / kPolynomialTerms][i % kPolynomialTerms] = static_cast<Real>(calibration.model.gyro[i]);
  }
  for (int i = 0; i < kAccelCoefficients * kPolynomialTerms; ++i) {
    runtime.accel[i / kPolynomialTerms][i % kPolynomialTerms] = static_cast<Real>(calibration.model.accel[i]);
  }
  return runtime;
}

// The runtime's correction as a consumer: inputs converted to the build's type.
template <typename Runtime, typename Correct>
ConsumerCorrection RuntimeConsumer(const Calibration& calibration, Correct correct) {
  return [runtime = RuntimeCalibration<Runtime>(calibration), correct](
             double temp_c, const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw,
             Eigen::Vector3d* omega_radps, Eigen::Vector3d* a_mps2) {
    using Real = decltype(runtime.reference_temp_c);
    Real gyro[3], accel[3], omega[3], a[3];
    for (int axis = 0; axis < 3; ++axis) {
      gyro[axis] = static_cast<Real>(gyro_raw(axis));
      accel[axis] = static_cast<Real>(accel_raw(axis));
    }
    correct(&runtime, static_cast<Real>(temp_c), gyro, accel, omega, a);
    for (int axis = 0; axis < 3; ++axis) {
      (*omega_radps)(axis) = omega[axis];
      (*a_mps2)(axis) = a[axis];
    }
  };
}

// Measures the float build (the result's loss: the larger) and the double build (returned).
ExportLoss MeasureRuntimes(const Calibration& calibration, const Envelope& envelope, ExportResult* result) {
  *result = MeasuredResult(kConsumer, calibration, envelope,
                           RuntimeConsumer<imufit_calibration_f>(calibration, imufit_correct_f));
  return MeasureLoss(calibration.model, envelope,
                     RuntimeConsumer<imufit_calibration>(calibration, imufit_correct));
}

std::string RuntimeBuildsNote(const ExportLoss& double_build) {
  char text[200];
  std::snprintf(
      text, sizeof text,
      "(the loss above is the float build's; the double build's worst case is %.3g deg/s and %.3g mg)",
      double_build.gyro_worst_dps.maxCoeff(), double_build.accel_worst_mg.maxCoeff());
  return text;
}

std::array<unsigned char, IMUFIT_SHA256_BYTES> Sha256Bytes(const std::string& hex) {
  std::array<unsigned char, IMUFIT_SHA256_BYTES> bytes{};
  if (hex.size() != 2 * bytes.size()) return bytes;
  for (size_t i = 0; i < bytes.size(); ++i) {
    bytes[i] = static_cast<unsigned char>(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
  }
  return bytes;
}

void RequireSerialFits(const Calibration& calibration) {
  if (calibration.serial.size() > IMUFIT_SERIAL_BYTES - 1) {
    throw ExportError("the serial is " + std::to_string(calibration.serial.size()) +
                      " bytes long; the C runtime holds at most " + std::to_string(IMUFIT_SERIAL_BYTES - 1));
  }
}

// A C string literal of `text`: printable ASCII as it is, the rest (and '"', '\\', '?', which
// could start a trigraph) as octal escapes.
std::string CString(const std::string& text) {
  std::string literal = "\"";
  for (const char c : text) {
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\' && c != '?') {
      literal += c;
    } else {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\%03o", static_cast<unsigned char>(c));
      literal += escape;
    }
  }
  return literal + "\"";
}

// A double literal of C that reads back as exactly `value`; for the float build (`to_float`) the
// same literal cast to float, which converts it as the implicit conversion would (round to
// nearest) but says so: the header compiles under -Wconversion -Wfloat-conversion -Werror.
std::string CNumber(double value, const std::string& name, bool to_float) {
  std::string text = DoubleText(value, name);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return to_float ? "(float)" + text : text;
}

void AppendRows(const double* params, int coefficients, const char* sensor, bool last, bool to_float,
                std::string* out) {
  *out += "    { \\\n";
  for (int i = 0; i < coefficients; ++i) {
    const std::string name =
        std::string(sensor) + " " + kCoefficientNames[i].group + " " + kCoefficientNames[i].axis;
    *out += "      {";
    for (int k = 0; k < kPolynomialTerms; ++k) {
      *out += (k ? ", " : "") + CNumber(params[i * kPolynomialTerms + k], name, to_float);
    }
    *out += std::string("}") + (i + 1 < coefficients ? "," : " ") + " /* " + name + " */ \\\n";
  }
  *out += std::string("    }") + (last ? "" : ",") + " \\\n";
}

std::string Upper(const std::string& name) {
  std::string upper = name;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return upper;
}

void RequireCIdentifier(const std::string& name) {
  bool ok = !name.empty() && !std::isdigit(static_cast<unsigned char>(name[0]));
  for (const char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  if (!ok) throw InputError("--c-name", QuoteForMessage(name) + " is not a C identifier");
}

std::string HeaderText(const Calibration& calibration, const ExportOptions& options,
                       const ExportResult& result, const std::string& builds_note) {
  const std::string name = Upper(options.c_name);
  std::string out = "/* ";
  for (const std::string& line : ProvenanceLines(calibration, options, result)) {
    out += (out.size() > 3 ? " * " : "") + line + "\n";
  }
  out += " * " + builds_note + "\n *\n";
  out +=
      " * Use with the runtime, the double build:\n"
      " *   static const imufit_calibration calibration = " +
      name +
      "_INITIALIZER;\n"
      " *   imufit_correct(&calibration, temp_c, gyro_raw, accel_raw, omega_radps, a_mps2);\n"
      " * or the float build (IMUFIT_RUNTIME_FLOAT defined before imufit_runtime.h):\n"
      " *   static const imufit_calibration_f calibration = " +
      name +
      "_INITIALIZER_F;\n"
      " *   imufit_correct_f(&calibration, temp_c, gyro_raw, accel_raw, omega_radps, a_mps2);\n */\n";
  out += "#ifndef " + name + "_H_\n#define " + name + "_H_\n\n#include \"imufit_runtime.h\"\n\n";
  out +=
      "/* serial, SHA-256 of the calibration file, reference temperature and fitted range (degC), then\n"
      " * c0..c3 of every gyro and accelerometer coefficient in powers of dT = T - T_ref. */\n";
  const auto sha = Sha256Bytes(options.calibration_sha256);
  for (const bool to_float : {false, true}) {
    out += "#define " + name + (to_float ? "_INITIALIZER_F" : "_INITIALIZER") + " \\\n  { \\\n    " +
           CString(calibration.serial) + ", \\\n    {";
    for (size_t i = 0; i < sha.size(); ++i) {
      char byte[8];
      std::snprintf(byte, sizeof byte, "0x%02x", sha[i]);
      out += (i ? ", " : "") + std::string(byte);
    }
    out += "}, \\\n    " + CNumber(calibration.model.basis.center_c, "reference_temp_c", to_float) + ", " +
           CNumber(calibration.fit_temp_range_c[0], "fit_temp_range_c", to_float) + ", " +
           CNumber(calibration.fit_temp_range_c[1], "fit_temp_range_c", to_float) + ", \\\n";
    AppendRows(calibration.model.gyro.data(), kGyroCoefficients, "gyro", false, to_float, &out);
    AppendRows(calibration.model.accel.data(), kAccelCoefficients, "accel", true, to_float, &out);
    out += to_float ? "  }\n" : "  }\n\n";
  }
  out += "\n#endif  /* " + name + "_H_ */\n";
  return out;
}

void PutBytes(uint64_t value, int bytes, size_t offset, std::string* blob) {
  for (int i = 0; i < bytes; ++i) (*blob)[offset + i] = static_cast<char>((value >> (8 * i)) & 0xFF);
}

void PutDoubles(const double* values, int count, size_t offset, std::string* blob) {
  for (int i = 0; i < count; ++i) {
    IMUFIT_CHECK(std::isfinite(values[i]),
                 "a calibration holds finite numbers (ReadCalibration refuses others)");
    uint64_t bits;
    std::memcpy(&bits, &values[i], sizeof bits);
    PutBytes(bits, 8, offset + 8 * i, blob);
  }
}

}  // namespace

ExportResult ExportC(const Calibration& calibration, const ExportOptions& options, const Envelope& envelope) {
  RequireCIdentifier(options.c_name);
  RequireSerialFits(calibration);
  ExportResult result;
  const ExportLoss double_build = MeasureRuntimes(calibration, envelope, &result);
  result.content = HeaderText(calibration, options, result, RuntimeBuildsNote(double_build));
  return result;
}

ExportResult ExportBin(const Calibration& calibration, const ExportOptions& options,
                       const Envelope& envelope) {
  ExportResult result;
  MeasureRuntimes(calibration, envelope, &result);
  result.content = CalibrationBlob(calibration, options.calibration_sha256);
  return result;
}

}  // namespace export_internal

std::string CalibrationBlob(const Calibration& calibration, const std::string& sha256_hex) {
  export_internal::RequireSerialFits(calibration);
  std::string blob(IMUFIT_BLOB_BYTES, '\0');
  blob.replace(0, 4, IMUFIT_BLOB_MAGIC);
  export_internal::PutBytes(IMUFIT_BLOB_VERSION, 2, IMUFIT_BLOB_OFFSET_VERSION, &blob);
  export_internal::PutBytes(IMUFIT_BLOB_BYTES, 4, IMUFIT_BLOB_OFFSET_LENGTH, &blob);
  blob.replace(IMUFIT_BLOB_OFFSET_SERIAL, calibration.serial.size(), calibration.serial);
  const auto sha = export_internal::Sha256Bytes(sha256_hex);
  blob.replace(IMUFIT_BLOB_OFFSET_SHA256, sha.size(), reinterpret_cast<const char*>(sha.data()), sha.size());
  export_internal::PutDoubles(&calibration.model.basis.center_c, 1, IMUFIT_BLOB_OFFSET_REFERENCE, &blob);
  export_internal::PutDoubles(calibration.fit_temp_range_c.data(), 2, IMUFIT_BLOB_OFFSET_TEMP_MIN, &blob);
  export_internal::PutDoubles(calibration.model.gyro.data(), kGyroParameters, IMUFIT_BLOB_OFFSET_GYRO, &blob);
  export_internal::PutDoubles(calibration.model.accel.data(), kAccelParameters, IMUFIT_BLOB_OFFSET_ACCEL,
                              &blob);
  // zlib's CRC-32 is the runtime's (IEEE 802.3): an independent implementation of the same check.
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(blob.data()), IMUFIT_BLOB_OFFSET_CRC);
  export_internal::PutBytes(crc, 4, IMUFIT_BLOB_OFFSET_CRC, &blob);
  return blob;
}

}  // namespace imufit
