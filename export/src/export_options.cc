// ExportOptions: its option table (base/option_table.h), the formats each option serves, and its
// checks. `imufit export` takes its options, their help and defaults from here.
#include <cerrno>
#include <cstdlib>
#include <optional>
#include <vector>

#include "imufit/export/export.h"

namespace imufit {
namespace {

// The options that serve only some formats; every other option serves every format.
struct FormatOption {
  const char* key;
  std::vector<ExportFormat> formats;
};
const std::vector<FormatOption>& FormatOptions() {
  static const std::vector<FormatOption> options = {
      {"gyro_raw_per_radps", {ExportFormat::kPx4, ExportFormat::kArduPilot, ExportFormat::kKalibr}},
      {"accel_raw_per_mps2", {ExportFormat::kPx4, ExportFormat::kArduPilot, ExportFormat::kKalibr}},
      {"temp_c", {ExportFormat::kKalibr, ExportFormat::kImucal}},
      {"device_id", {ExportFormat::kPx4, ExportFormat::kArduPilot}},
      {"gyro_device_id", {ExportFormat::kPx4, ExportFormat::kArduPilot}},
      {"accel_device_id", {ExportFormat::kPx4, ExportFormat::kArduPilot}},
      {"instance", {ExportFormat::kPx4, ExportFormat::kArduPilot}},
      {"c_name", {ExportFormat::kC}},
      {"rostopic", {ExportFormat::kKalibr}},
  };
  return options;
}

const FormatOption* FindFormatOption(const std::string& key) {
  for (const FormatOption& option : FormatOptions()) {
    if (key == option.key) return &option;
  }
  return nullptr;
}

// The help of an option that serves some formats starts with them: "kalibr, imucal: ...".
std::string ForFormats(const char* key, const std::string& help) {
  const std::string formats = ExportOptionFormats(key);
  return formats.empty() ? help : formats + ": " + help;
}

// A whole number in decimal, nullopt for any other text.
std::optional<long long> WholeNumber(const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const long long n = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) return std::nullopt;
  return n;
}

// A 32-bit unsigned device ID (PX4 and ArduPilot keep its bits in an INT32 parameter).
void DeviceId(OptionTable<ExportOptions>* t, const char* key, const char* flag, const char* help,
              std::optional<long long> ExportOptions::*member) {
  t->Text(
      key, flag, ForFormats(key, help),
      [member](const ExportOptions& o) { return o.*member ? std::to_string(*(o.*member)) : std::string(); },
      [member](const std::string& text, ExportOptions* o) -> std::string {
        const std::optional<long long> id = WholeNumber(text);
        if (!id || *id < 0 || *id > 0xFFFFFFFFLL) return "\"" + text + "\" is not a 32-bit device ID";
        o->*member = id;
        return "";
      });
}

OptionTable<ExportOptions> MakeExportOptionTable() {
  using O = ExportOptions;
  OptionTable<O> t;
  t.Text(
      "format", "--format,-f", "the format: " + ExportFormatNames() + " (in any case)",
      [](const O& o) { return std::string(ToString(o.format)); },
      [](const std::string& text, O* o) -> std::string {
        const std::optional<ExportFormat> format = ExportFormatFromString(text);
        if (!format) return "\"" + text + "\" is not a format (" + ExportFormatNames() + ")";
        o->format = *format;
        return "";
      });
  t.Numbers(
      "envelope_temp_c", "--envelope-temp-c",
      "the envelope: the temperatures MIN,MAX the loss is measured over, inside the fitted range "
      "(default: the calibration's fitted range)",
      "degC", [](const O& o) { return o.envelope_temp_c; },
      [](const std::vector<double>& v, O* o) { o->envelope_temp_c = v; }, 2);
  t.Number("full_scale_dps", "--full-scale-dps", "the envelope: the largest angular rate on each axis",
           "deg/s", &O::full_scale_dps, PositiveFinite());
  t.Number("max_g", "--max-g", "the envelope: the largest specific force on each axis", "g", &O::max_g,
           PositiveFinite());
  t.Number("gyro_raw_per_radps", "--gyro-raw-per-radps",
           ForFormats("gyro_raw_per_radps", "what the driver divides the raw gyro output by to give rad/s"),
           "", &O::gyro_raw_per_radps, PositiveFinite());
  t.Number("accel_raw_per_mps2", "--accel-raw-per-mps2",
           ForFormats("accel_raw_per_mps2",
                      "what the driver divides the raw accelerometer output by to give m/s^2"),
           "", &O::accel_raw_per_mps2, PositiveFinite());
  t.OptionalNumber("temp_c", "--temp-c",
                   ForFormats("temp_c",
                              "the temperature the one-temperature formats are taken at (default: the "
                              "calibration's reference, clamped to its fitted range)"),
                   "degC", &O::temp_c, {}, "the reference");
  DeviceId(&t, "device_id", "--device-id", "the device ID of both sensors (one die)", &O::device_id);
  DeviceId(&t, "gyro_device_id", "--gyro-device-id",
           "the gyro's device ID (TC_G0_ID, CAL_GYRO0_ID; INS_GYR_ID), instead of --device-id",
           &O::gyro_device_id);
  DeviceId(&t, "accel_device_id", "--accel-device-id",
           "the accelerometer's device ID (TC_A0_ID, CAL_ACC0_ID; INS_ACC_ID), instead of --device-id",
           &O::accel_device_id);
  t.Text(
      "instance", "--instance",
      ForFormats("instance",
                 "the parameter instance: px4 0..3 (TC_G0..3, TC_A0..3, CAL_ACC0..3; default 0), "
                 "ardupilot 1..3 (INS_TCAL1..3, INS_ACC..ACC3; default 1)"),
      [](const O& o) { return o.instance ? std::to_string(*o.instance) : std::string(); },
      [](const std::string& text, O* o) -> std::string {
        const std::optional<long long> n = WholeNumber(text);
        if (!n || *n < 0 || *n > 3) return "\"" + text + "\" is not an instance 0..3";
        o->instance = static_cast<int>(*n);
        return "";
      });
  t.String("c_name", "--c-name", ForFormats("c_name", "the C name of the unit (NAME_INITIALIZER)"),
           &O::c_name);
  t.String("rostopic", "--rostopic", ForFormats("rostopic", "the IMU's ROS topic"), &O::rostopic);
  return t;
}

}  // namespace

const OptionTable<ExportOptions>& ExportOptionTable() {
  static const OptionTable<ExportOptions> table = MakeExportOptionTable();
  return table;
}

bool ExportOptionServes(const std::string& key, ExportFormat format) {
  const FormatOption* option = FindFormatOption(key);
  if (option == nullptr) return true;
  for (ExportFormat served : option->formats) {
    if (served == format) return true;
  }
  return false;
}

std::string ExportOptionFormats(const std::string& key) {
  const FormatOption* option = FindFormatOption(key);
  std::string formats;
  if (option == nullptr) return formats;
  for (ExportFormat format : option->formats)
    formats += (formats.empty() ? "" : ", ") + std::string(ToString(format));
  return formats;
}

std::string ExportOptions::Validate() const { return ValidateOptions(ExportOptionTable(), *this); }

}  // namespace imufit
