// ExportOptions: its option table (base/option_table.h), the formats each option serves, and its
// checks. `imufit export` takes its options, their help and defaults from here.
#include <cerrno>
#include <cstdlib>
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
      {"device_id", {ExportFormat::kPx4}},
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
  t.Text(
      "device_id", "--device-id", ForFormats("device_id", "the sensor's device ID (TC_G0_ID, CAL_ACC0_ID)"),
      [](const O& o) { return o.device_id ? std::to_string(*o.device_id) : std::string(); },
      [](const std::string& text, O* o) -> std::string {
        char* end = nullptr;
        errno = 0;
        const long long id = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0' || errno == ERANGE) return "\"" + text + "\" is not a whole number";
        o->device_id = id;
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
