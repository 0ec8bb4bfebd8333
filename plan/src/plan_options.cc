// The options of `imufit plan check` (plan_check.h), described once, and the unit's noise from a
// noise YAML.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "imufit/io/noise_file.h"
#include "imufit/plan/plan_check.h"
#include "imufit/plan/plan_design.h"

namespace imufit {

std::string GroupValuesText(const std::map<std::string, double>& values) {
  std::string text;
  for (const auto& [group, value] : values) {
    text += (text.empty() ? "" : ",") + group + "=" + OptionNumberText(value);
  }
  return text;
}

std::string ParseGroupValues(const std::string& text, std::map<std::string, double>* values) {
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
      return "\"" + pair + "\": the value must be a positive number in " + PlanGroupUnit(group);
    }
    (*values)[group] = value;
  }
  return "";
}

namespace {

std::string SetTolerances(const std::string& text, PlanCheckOptions* options) {
  return ParseGroupValues(text, &options->tolerances);
}

OptionTable<PlanCheckOptions> MakePlanCheckOptionTable() {
  OptionTable<PlanCheckOptions> t;
  t.Text(
       "tolerance", "--tolerance",
       "GROUP=VALUE: tolerance of a coefficient group's value (gyro.bias deg/s, accel.bias mg, *.scale "
       "ppm, *.misalignment mrad, gyro.g_sensitivity deg/s/g); repeat it, or separate pairs with ','",
       [](const PlanCheckOptions& o) { return GroupValuesText(o.tolerances); }, SetTolerances)
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
  t.Number("min_ratio", "--min-ratio",
           "with --limits: the least ratio of a criterion's tolerance to the U (z sigma) the plan achieves "
           "(4 for 4:1)",
           "", &PlanCheckOptions::min_ratio, AtLeast(1.0));
  t.Include(WindowOptionTable(), &PlanCheckOptions::windows);
  return t;
}

std::string SetPositions(const std::string& text, PlanDesignOptions* options) {
  size_t start = 0;
  std::string kept;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(',', start), text.size());
    const std::string name = text.substr(start, end - start);
    start = end + 1;
    if (name != "faces" && name != "edges" && name != "corners") {
      return "\"" + name + "\" is not a set of positions: give faces, edges or corners, ',' separated";
    }
    kept += (kept.empty() ? "" : ",") + name;
  }
  options->positions = kept;
  return "";
}

OptionTable<PlanDesignOptions> MakePlanDesignOptionTable() {
  using O = PlanDesignOptions;
  OptionTable<O> t;
  t.Include(PlanCheckOptionTable(), &O::check);
  t.Text(
      "positions", "--positions", "candidate positions: faces (6), edges (12), corners (8), ',' separated",
      [](const O& o) { return o.positions; }, SetPositions);
  t.Numbers(
      "rates_dps", "--rates", "candidate rate magnitudes, each run as a +- pair", "deg/s",
      [](const O& o) { return o.rates_dps; }, [](const std::vector<double>& v, O* o) { o->rates_dps = v; });
  t.Number("max_rate_dps", "--max-rate", "the table's rate limit", "deg/s", &O::max_rate_dps,
           PositiveFinite());
  t.Flag("two_axis", "--two-axis",
         "a two-axis table: rates about every candidate direction, not only the faces'", &O::two_axis);
  t.Numbers(
      "set_points_c", "--set-points", "the temperature set-points a soak may be at", "degC",
      [](const O& o) { return o.set_points_c; },
      [](const std::vector<double>& v, O* o) { o->set_points_c = v; });
  t.Number("soak_settle_s", "--soak-settle", "thermal settling of a soak, its cost before the first segment",
           "s", &O::soak_settle_s, NonNegativeFinite());
  t.Text(
       "prior", "--prior",
       "GROUP=VALUE: the data-sheet 1-sigma of a group's value over the range (units as --tolerance; "
       "the prior that makes the first step well posed); repeat it, or separate pairs with ','",
       [](const O& o) { return GroupValuesText(o.prior); },
       [](const std::string& text, O* o) { return ParseGroupValues(text, &o->prior); })
      .repeatable = true;
  t.Number("max_exchange_rounds", "--exchange-rounds", "exchange rounds at most", "", &O::max_exchange_rounds,
           AtLeast(0));
  t.OptionalNumber("gravity_mps2", "--gravity-mps2",
                   "the station's gravity, written into the plan (the fit reads the accelerometer's scale "
                   "against it)",
                   "m/s^2", &O::gravity_mps2, Between(9.7, 9.9),
                   "the candidates' plan's; else WGS84 normal gravity at --latitude; else 9.80665");
  return t;
}

}  // namespace

const OptionTable<PlanDesignOptions>& PlanDesignOptionTable() {
  static const OptionTable<PlanDesignOptions> table = MakePlanDesignOptionTable();
  return table;
}

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
