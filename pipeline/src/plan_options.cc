// The options of `imufit plan check` (plan_check.h), described once, and the unit's noise from a
// noise YAML.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "imufit/io/noise_file.h"
#include "imufit/pipeline/plan_check.h"

namespace imufit {
namespace {

std::string TolerancesText(const PlanCheckOptions& options) {
  std::string text;
  for (const auto& [group, value] : options.tolerances) {
    text += (text.empty() ? "" : ",") + group + "=" + OptionNumberText(value);
  }
  return text;
}

// "GROUP=VALUE" pairs, one a line (the option given several times) or separated by ','.
std::string SetTolerances(const std::string& text, PlanCheckOptions* options) {
  std::string allowed;
  for (const std::string& g : PlanGroups()) allowed += (allowed.empty() ? "" : ", ") + g;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find_first_of(",\n", start), text.size());
    const std::string pair = text.substr(start, end - start);
    start = end + 1;
    if (pair.empty()) continue;
    const size_t equals = pair.find('=');
    const std::string group = pair.substr(0, equals);
    if (equals == std::string::npos ||
        std::find(PlanGroups().begin(), PlanGroups().end(), group) == PlanGroups().end()) {
      return "\"" + pair + "\": give GROUP=VALUE with GROUP one of " + allowed;
    }
    const std::string number = pair.substr(equals + 1);
    char* parsed_end = nullptr;
    const double value = std::strtod(number.c_str(), &parsed_end);
    if (number.empty() || *parsed_end != '\0' || !(value > 0.0) || !std::isfinite(value)) {
      return "\"" + pair + "\": the tolerance must be a positive number in " + PlanGroupUnit(group);
    }
    options->tolerances[group] = value;
  }
  return "";
}

OptionTable<PlanCheckOptions> MakePlanCheckOptionTable() {
  OptionTable<PlanCheckOptions> t;
  t.Text("tolerance", "--tolerance",
         "GROUP=VALUE: tolerance of a coefficient group's value (gyro.bias deg/s, accel.bias mg, *.scale "
         "ppm, *.misalignment mrad, gyro.g_sensitivity deg/s/g); repeat it, or separate pairs with ','",
         TolerancesText, SetTolerances)
      .repeatable = true;
  t.Number("z", "--z", "coverage factor: a tolerance is met when z sigma <= it", "", &PlanCheckOptions::z,
           PositiveFinite());
  t.Numbers(
      "spec_range_c", "--spec-range", "the range the unit is specified over (default: the plan's): LO,HI",
      "degC",
      [](const PlanCheckOptions& o) {
        return o.spec_range_c ? std::vector<double>{(*o.spec_range_c)[0], (*o.spec_range_c)[1]}
                              : std::vector<double>{};
      },
      [](const std::vector<double>& v, PlanCheckOptions* o) {
        if (v.size() == 2) o->spec_range_c = {{std::min(v[0], v[1]), std::max(v[0], v[1])}};
        if (v.empty()) o->spec_range_c.reset();
      },
      2);
  t.OptionalNumber("latitude_deg", "--latitude", "the table's latitude", "deg",
                   &PlanCheckOptions::latitude_deg, Between(-90.0, 90.0), "the plan's");
  t.Number("weak_tolerance", "--weak-tolerance",
           "a direction weaker than this fraction of the strongest is named weak", "",
           &PlanCheckOptions::weak_tolerance, Between(0.0, 1.0, true, true));
  t.Number("cut_loss", "--cut-loss",
           "a segment whose removal grows every sigma by less than this fraction could be cut", "",
           &PlanCheckOptions::cut_loss, PositiveFinite());
  return t;
}

}  // namespace

const OptionTable<PlanCheckOptions>& PlanCheckOptionTable() {
  static const OptionTable<PlanCheckOptions> table = MakePlanCheckOptionTable();
  return table;
}

const std::vector<std::string>& PlanGroups() {
  static const std::vector<std::string> groups = {"gyro.bias",          "gyro.scale", "gyro.misalignment",
                                                  "gyro.g_sensitivity", "accel.bias", "accel.scale",
                                                  "accel.misalignment"};
  return groups;
}

void ApplyNoiseYaml(const std::string& path, SimulationOptions* schedule) {
  const SensorNoiseFigures noise = ReadSensorNoise(path);
  schedule->gyro_noise_density = noise.gyro_noise_density;
  schedule->accel_noise_density = noise.accel_noise_density;
  schedule->gyro_bias_instability = noise.gyro_bias_instability;
  schedule->accel_bias_instability = noise.accel_bias_instability;
}

}  // namespace imufit
