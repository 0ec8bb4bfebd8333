// `imufit export`: the formats, the dispatch, the provenance and the loss's words.
#include "imufit/export/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "export_internal.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

struct FormatName {
  ExportFormat format;
  const char* name;
};
constexpr FormatName kFormatNames[] = {
    {ExportFormat::kC, "c"},           {ExportFormat::kBin, "bin"},
    {ExportFormat::kPx4, "px4"},       {ExportFormat::kArduPilot, "ardupilot"},
    {ExportFormat::kKalibr, "kalibr"}, {ExportFormat::kImucal, "imucal"},
    {ExportFormat::kJson, "json"}};

std::string Figures(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof text, "x %.3g y %.3g z %.3g", v.x(), v.y(), v.z());
  return text;
}

// A driver scale (raw per SI unit) the calibration's own scale contradicts: a unit in counts
// exported with the default 1 would lose its whole signal. Throws InputError naming the option.
void RequireDriverScale(const Eigen::Vector3d& scale, double raw_per_si, const char* flag, const char* unit) {
  constexpr double kMostRatio = 2.0;  // a driver's nominal scale is within a few percent of the unit's
  const double ratio = scale.mean() / raw_per_si;
  if (ratio > kMostRatio || ratio < 1.0 / kMostRatio) {
    char text[400];
    std::snprintf(
        text, sizeof text,
        "the calibration's scale at its reference temperature is %.6g raw per %s, %.4g times %s %.6g: "
        "give what the unit's driver divides its raw output by to give %s (a unit in counts: its "
        "counts per %s)",
        scale.mean(), unit, ratio, flag, raw_per_si, unit, unit);
    throw InputError(flag, text);
  }
}

}  // namespace

const char* ToString(ExportFormat format) {
  for (const FormatName& entry : kFormatNames) {
    if (entry.format == format) return entry.name;
  }
  return "?";
}

std::optional<ExportFormat> ExportFormatFromString(std::string_view name) {
  const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
  for (const FormatName& entry : kFormatNames) {
    const std::string_view entry_name = entry.name;
    if (name.size() == entry_name.size() &&
        std::equal(name.begin(), name.end(), entry_name.begin(),
                   [&lower](char a, char b) { return lower(a) == lower(b); })) {
      return entry.format;
    }
  }
  return std::nullopt;
}

std::string ExportFormatNames() {
  std::string names;
  for (const FormatName& entry : kFormatNames) names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

ExportResult ExportCalibration(const Calibration& calibration, const ExportOptions& options) {
  using namespace export_internal;
  if (const std::string problem = options.Validate(); !problem.empty()) throw InputError("export", problem);
  const Envelope envelope = EnvelopeOf(calibration, options);
  if (options.temp_c && !(*options.temp_c >= calibration.fit_temp_range_c[0] &&
                          *options.temp_c <= calibration.fit_temp_range_c[1])) {
    throw InputError("--temp-c", FormatDouble(*options.temp_c) +
                                     " degC is outside the calibration's fitted range [" +
                                     FormatDouble(calibration.fit_temp_range_c[0]) + ", " +
                                     FormatDouble(calibration.fit_temp_range_c[1]) + "] degC");
  }
  if (ExportOptionServes("gyro_raw_per_radps", options.format)) {
    const double reference = calibration.model.basis.center_c;
    RequireDriverScale(export_internal::GyroAt(calibration.model, reference).scale,
                       options.gyro_raw_per_radps, "--gyro-raw-per-radps", "rad/s");
    RequireDriverScale(export_internal::AccelAt(calibration.model, reference).scale,
                       options.accel_raw_per_mps2, "--accel-raw-per-mps2", "m/s^2");
  }
  switch (options.format) {
    case ExportFormat::kC:
      return ExportC(calibration, options, envelope);
    case ExportFormat::kBin:
      return ExportBin(calibration, options, envelope);
    case ExportFormat::kPx4:
      return ExportPx4(calibration, options, envelope);
    case ExportFormat::kArduPilot:
      return ExportArduPilot(calibration, options, envelope);
    case ExportFormat::kKalibr:
      return ExportKalibr(calibration, options, envelope);
    case ExportFormat::kImucal:
      return ExportImucal(calibration, options, envelope);
    case ExportFormat::kJson:
      return ExportJson(calibration, options);
  }
  return {};
}

std::string DescribeLoss(const ExportResult& result, const std::string& prefix) {
  const ExportLoss& loss = result.loss;
  if (!loss.measured) return prefix + "loss: none (every coefficient written as the calibration's double)\n";
  return prefix + "loss against the full model over " + result.envelope + " (" + std::to_string(loss.points) +
         " points):\n" + prefix + "  gyro  worst " + Figures(loss.gyro_worst_dps) + " deg/s, rms " +
         Figures(loss.gyro_rms_dps) + " deg/s\n" + prefix + "  accel worst " + Figures(loss.accel_worst_mg) +
         " mg, rms " + Figures(loss.accel_rms_mg) + " mg\n";
}

std::optional<std::string> LossBeyondBounds(const ExportLoss& loss, double max_gyro_dps,
                                            double max_accel_mg) {
  if (!loss.measured) return std::nullopt;
  const double gyro = loss.gyro_worst_dps.maxCoeff(), accel = loss.accel_worst_mg.maxCoeff();
  std::string excess;
  char text[200];
  if (gyro > max_gyro_dps) {
    std::snprintf(text, sizeof text,
                  "the gyro's worst-case loss %.4g deg/s exceeds the bound %g deg/s by %.4g deg/s", gyro,
                  max_gyro_dps, gyro - max_gyro_dps);
    excess = text;
  }
  if (accel > max_accel_mg) {
    std::snprintf(text, sizeof text,
                  "the accelerometer's worst-case loss %.4g mg exceeds the bound %g mg by %.4g mg", accel,
                  max_accel_mg, accel - max_accel_mg);
    excess += (excess.empty() ? "" : "; ") + std::string(text);
  }
  if (excess.empty()) return std::nullopt;
  return excess;
}

namespace export_internal {

SensorIds DeviceIds(const ExportOptions& options, const char* format) {
  const std::optional<long long> gyro = options.gyro_device_id ? options.gyro_device_id : options.device_id;
  const std::optional<long long> accel =
      options.accel_device_id ? options.accel_device_id : options.device_id;
  if (!gyro || !accel) {
    throw InputError(options.device_id || options.gyro_device_id || options.accel_device_id
                         ? (gyro ? "--accel-device-id" : "--gyro-device-id")
                         : "--device-id",
                     std::string("a ") + format +
                         " export needs the sensors' device IDs: --device-id (gyro and accelerometer on one "
                         "die), or --gyro-device-id and --accel-device-id");
  }
  // The autopilots keep the unsigned device ID in an INT32 parameter: the same 32 bits.
  const auto bits = [](long long id) { return static_cast<int32_t>(static_cast<uint32_t>(id)); };
  return {bits(*gyro), bits(*accel)};
}

int InstanceOf(const ExportOptions& options, int low, int high, int fallback, const char* format) {
  if (!options.instance) return fallback;
  if (*options.instance < low || *options.instance > high) {
    throw InputError("--instance", std::to_string(*options.instance) + " is not an instance of " + format +
                                       " (" + std::to_string(low) + ".." + std::to_string(high) + ")");
  }
  return *options.instance;
}

ExportLoss WorstOf(const ExportLoss& a, const ExportLoss& b) {
  ExportLoss worst = a;
  worst.gyro_worst_dps = a.gyro_worst_dps.cwiseMax(b.gyro_worst_dps);
  worst.gyro_rms_dps = a.gyro_rms_dps.cwiseMax(b.gyro_rms_dps);
  worst.accel_worst_mg = a.accel_worst_mg.cwiseMax(b.accel_worst_mg);
  worst.accel_rms_mg = a.accel_rms_mg.cwiseMax(b.accel_rms_mg);
  return worst;
}

std::string WorstFigures(const ExportLoss& loss) {
  return "gyro worst " + Figures(loss.gyro_worst_dps) + " deg/s, accel worst " +
         Figures(loss.accel_worst_mg) + " mg";
}

std::string CalibrationFileName(const ExportOptions& options) {
  return CommentSafe(options.calibration_file.substr(options.calibration_file.find_last_of('/') + 1));
}

std::vector<std::string> ProvenanceLines(const Calibration& calibration, const ExportOptions& options,
                                         const ExportResult& result) {
  std::vector<std::string> lines = {
      "imufit calibration of unit " +
          CommentSafe(calibration.serial.empty() ? "(no serial)" : calibration.serial) + ", for " +
          result.consumer,
      "calibration: " + CalibrationFileName(options) + ", SHA-256 " + CommentSafe(options.calibration_sha256),
      "calibration made by: " + CommentSafe(calibration.software) + ", " +
          CommentSafe(calibration.created_utc),
      "exported by: " + CommentSafe(options.software) + " (imufit export --format " +
          ToString(options.format) + ")",
      "fitted temperature range [" + FormatDouble(calibration.fit_temp_range_c[0]) + ", " +
          FormatDouble(calibration.fit_temp_range_c[1]) + "] degC, reference temperature " +
          FormatDouble(calibration.model.basis.center_c) + " degC"};
  std::string loss = DescribeLoss(result, "");
  for (size_t start = 0; start < loss.size();) {
    const size_t end = loss.find('\n', start);
    lines.push_back(loss.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

}  // namespace export_internal
}  // namespace imufit
