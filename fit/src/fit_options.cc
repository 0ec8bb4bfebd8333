// FitOptions: its option table (model/option_table.h), its names and its checks.
#include <algorithm>

#include "imufit/base/enum_names.h"
#include "imufit/base/text.h"
#include "imufit/fit/thermal_fit.h"

namespace imufit {
namespace {

// The names of `imufit fit --fit`: what each names of the gyro and of the accelerometer (kNone:
// nothing of that sensor).
struct FitGroupName {
  const char* name;
  SensorFit gyro;
  SensorFit accel;
};
constexpr FitGroupName kFitGroupNames[] = {{"all", SensorFit::kAll, SensorFit::kAll},
                                           {"gyro", SensorFit::kAll, SensorFit::kNone},
                                           {"gyro-bias", SensorFit::kBias, SensorFit::kNone},
                                           {"accel", SensorFit::kNone, SensorFit::kAll},
                                           {"accel-bias", SensorFit::kNone, SensorFit::kBias}};

// The name of exactly this much of each sensor, "" when none.
std::string NameOfGroups(SensorFit gyro, SensorFit accel) {
  for (const FitGroupName& entry : kFitGroupNames) {
    if (entry.gyro == gyro && entry.accel == accel) return entry.name;
  }
  return "";
}

OptionTable<FitOptions> MakeFitOptionTable() {
  using O = FitOptions;
  OptionTable<O> t;
  OptionEntry<O>& fit = t.Text(
      "fit", "--fit",
      "what to fit, comma-separated: " + AllNames(kFitGroupNames) +
          "; the rest is held (accel alone calibrates the accelerometer from a static-only run)",
      [](const O& o) { return FitGroupsText(o); },
      [](const std::string& text, O* o) {
        std::string error;
        return ParseFitGroups(text, o, &error) ? "" : error;
      });
  fit.fingerprint = Fingerprint::kCustom;
  fit.describe = [](const O& o) { return "fitted=" + Join(o.Groups(true), ","); };
  t.Number(
      "gyro_temp_order", "--gyro-temp-order",
      "order of the gyro temperature polynomials (0 when temp_c gives one temperature for the whole run)", "",
      &O::gyro_temp_order, Between(0, 3));
  t.Number(
      "accel_temp_order", "--accel-temp-order",
      "order of the accel temperature polynomials (0 when temp_c gives one temperature for the whole run)",
      "", &O::accel_temp_order, Between(0, 3));
  OptionEntry<O>& g_sensitivity =
      t.Flag("fit_g_sensitivity", "--no-g-sensitivity", "fit the gyro g-sensitivity (held at zero when off)",
             &O::fit_g_sensitivity, /*cli_negates=*/true);
  g_sensitivity.fingerprint = Fingerprint::kCustom;  // in `fitted`
  g_sensitivity.describe = [](const O&) { return std::string(); };
  t.Text(
      "loss", "--loss", "robust loss: " + AllNames(kRobustLossNames),
      [](const O& o) { return RobustLossName(o.loss); },
      [](const std::string& text, O* o) {
        std::string error;
        return ParseRobustLoss(text, &o->loss, &error) ? "" : error;
      });
  t.Number("loss_scale", "--loss-scale",
           "where the robust loss acts, in robust spreads of the windows' normalised residuals", "",
           &O::loss_scale, Positive());
  t.Number("gyro_bias_stability_radps", "--gyro-bias-stability-dph",
           "the unit's in-run gyro bias stability, 1-sigma (bias instability and random walk over "
           "bias_correlation_s): added to the reported uncertainty",
           "rad/s", &O::gyro_bias_stability_radps, NonNegative(), CliUnit::kDegPerHour);
  t.Number("accel_bias_stability_mps2", "--accel-bias-stability-ug",
           "the unit's in-run accel bias stability, 1-sigma: added to the reported uncertainty", "m/s^2",
           &O::accel_bias_stability_mps2, NonNegative(), CliUnit::kMicroG);
  t.Number("bias_correlation_s", "--bias-correlation",
           "time over which the wandering bias is taken as constant", "s", &O::bias_correlation_s,
           Positive());
  t.Number("max_iterations", "--max-iterations", "solver iterations at most, per pass", "",
           &O::max_iterations, AtLeast(1));
  t.Flag("closed_form_start", "--nominal-start",
         "start from the closed-form solution (when off: from nominal scale factors, slower; to check that "
         "the solver converges from a poor start)",
         &O::closed_form_start, /*cli_negates=*/true);
  t.Number("threads", "--threads", "solver threads", "", &O::num_threads, AtLeast(1)).fingerprint =
      Fingerprint::kNone;
  t.Number("distinct_temp_c", "--distinct-temp", "temperatures within this span count as one", "degC",
           &O::distinct_temp_c, Positive());
  t.Number("min_excitation_rate_radps", "--min-excitation-rate",
           "a rate segment excites an axis when its true rate about it is at least this", "rad/s",
           &O::min_excitation_rate_radps, Positive());
  t.Number("rank_tolerance", "--rank-tolerance",
           "relative singular value below which a direction of the fit is undetermined", "",
           &O::rank_tolerance, Between(0.0, 1.0, true, true));
  return t;
}

}  // namespace

bool FitOptions::Fits(bool gyro, int coefficient) const {
  const SensorFit fit = gyro ? gyro_fit : accel_fit;
  if (fit == SensorFit::kNone) return false;
  if (coefficient < kScaleCoefficient) return true;
  if (fit == SensorFit::kBias) return false;
  return coefficient < kGSensitivityCoefficient || fit_g_sensitivity;
}

std::vector<std::string> FitOptions::Groups(bool fitted) const {
  std::vector<std::string> names;
  for (const bool gyro : {true, false}) {
    const int coefficients = gyro ? kGyroCoefficients : kAccelCoefficients;
    for (const int c :
         {kBiasCoefficient, kScaleCoefficient, kMisalignmentCoefficient, kGSensitivityCoefficient}) {
      if (c >= coefficients || Fits(gyro, c) != fitted) continue;
      names.push_back(std::string(gyro ? "gyro." : "accel.") + kCoefficientNames[c].group);
    }
  }
  return names;
}

bool ParseFitGroups(const std::string& list, FitOptions* options, std::string* error) {
  SensorFit gyro = SensorFit::kNone;
  SensorFit accel = SensorFit::kNone;
  // kAll wins over kBias, either over kNone.
  const auto at_least = [](SensorFit* fit, SensorFit wanted) {
    if (wanted == SensorFit::kAll || *fit == SensorFit::kNone) *fit = wanted;
  };
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto* entry = std::find_if(std::begin(kFitGroupNames), std::end(kFitGroupNames),
                                     [&name](const FitGroupName& e) { return name == e.name; });
    if (entry == std::end(kFitGroupNames)) {
      *error = "\"" + name + "\" is not a group to fit (" + AllNames(kFitGroupNames) + ", comma-separated)";
      return false;
    }
    if (entry->gyro != SensorFit::kNone) at_least(&gyro, entry->gyro);
    if (entry->accel != SensorFit::kNone) at_least(&accel, entry->accel);
    begin = end + 1;
  }
  if (gyro == SensorFit::kNone && accel == SensorFit::kNone) {
    *error = "nothing to fit";
    return false;
  }
  options->gyro_fit = gyro;
  options->accel_fit = accel;
  return true;
}

std::string FitGroupsText(const FitOptions& options) {
  if (const std::string both = NameOfGroups(options.gyro_fit, options.accel_fit); !both.empty()) return both;
  const std::string gyro = NameOfGroups(options.gyro_fit, SensorFit::kNone);
  const std::string accel = NameOfGroups(SensorFit::kNone, options.accel_fit);
  return gyro + (gyro.empty() || accel.empty() ? "" : ",") + accel;
}

const OptionTable<FitOptions>& FitOptionTable() {
  static const OptionTable<FitOptions> table = MakeFitOptionTable();
  return table;
}

std::string FitOptions::Validate() const {
  if (std::string problem = ValidateOptions(FitOptionTable(), *this); !problem.empty()) return problem;
  if (gyro_fit == SensorFit::kNone && accel_fit == SensorFit::kNone) return "nothing to fit";
  return "";
}

}  // namespace imufit
