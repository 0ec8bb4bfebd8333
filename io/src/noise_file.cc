#include "imufit/io/noise_file.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/units.h"
#include "imufit/model/check.h"
#include "yaml_util.h"

namespace imufit {
namespace {

// The file holds no non-finite number: a figure that is not finite is left out (docs/allan.md).
std::string YamlNumber(double value) {
  IMUFIT_CHECK(std::isfinite(value), "a noise file number is finite");
  return FormatDouble(value);
}

// "<indent><key>: <value><comment>\n", or nothing when `value` is not finite.
void Scalar(std::ostream& yaml, const char* indent, const std::string& key, double value,
            const char* comment = "") {
  if (std::isfinite(value)) yaml << indent << key << ": " << YamlNumber(value) << comment << "\n";
}

// "<indent><key>: [value, sigma]\n", or nothing when either is not finite.
void Pair(std::ostream& yaml, const char* indent, const std::string& key, double value, double sigma) {
  if (std::isfinite(value) && std::isfinite(sigma)) {
    yaml << indent << key << ": [" << YamlNumber(value) << ", " << YamlNumber(sigma) << "]\n";
  }
}

std::string YamlString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

// The largest fitted value of `term` over the columns of `kind` (Kalibr takes one number for all
// three axes: the worst one is the safe choice), or nan when there is none.
// The two-sided 95 % bound's one side: an unresolved term is given as value + kUpperBoundSigmas sigma.
constexpr double kUpperBoundSigmas = 2.0;

// The largest of the fitted axes of `kind` for `term`, each an unresolved term's upper bound
// (Kalibr's noise model takes every term as present: a random walk the log cannot resolve is given
// as what the log allows, never 0).
double WorstAxis(const std::vector<NoiseColumnRecord>& columns, ColumnKind kind, int term) {
  double worst = std::nan("");
  for (const NoiseColumnRecord& column : columns) {
    if (column.kind != kind || !column.fitted) continue;
    const double figure = column.resolved[term] ? column.value[term]
                                                : column.value[term] + kUpperBoundSigmas * column.sigma[term];
    if (std::isfinite(figure) && !(worst >= figure)) worst = figure;
  }
  return worst;
}

}  // namespace

const NoiseTermUnits& UnitsOf(ColumnKind kind, int term) {
  static const NoiseTermUnits kGyro[kNoiseTerms] = {
      {"quantization_rad", "rad", "", "", 1.0, "quantization"},
      {"random_walk_rad_per_sqrt_s", "rad/sqrt(s)", "arw_deg_per_sqrt_hr", "deg/sqrt(h)",
       kRadToDeg * kSqrtSecondsPerSqrtHour, "angle random walk"},
      {"bias_instability_radps", "rad/s", "bias_instability_deg_per_hr", "deg/h", kRadToDeg * kSecondsPerHour,
       "bias instability"},
      {"rate_random_walk_radps_per_sqrt_s", "rad/s/sqrt(s)", "rrw_deg_per_hr_per_sqrt_hr", "deg/h/sqrt(h)",
       kRadToDeg * kSecondsPerHour * kSqrtSecondsPerSqrtHour, "rate random walk"},
      {"rate_ramp_radps_per_s", "rad/s^2", "rate_ramp_deg_per_hr_per_hr", "deg/h/h",
       kRadToDeg * kSecondsPerHour * kSecondsPerHour, "rate ramp"}};
  static const NoiseTermUnits kAccel[kNoiseTerms] = {
      {"quantization_mps", "m/s", "", "", 1.0, "quantization"},
      {"random_walk_mps_per_sqrt_s", "m/s/sqrt(s)", "vrw_mps_per_sqrt_hr", "m/s/sqrt(h)",
       kSqrtSecondsPerSqrtHour, "velocity random walk"},
      {"bias_instability_mps2", "m/s^2", "bias_instability_ug", "micro-g", 1e6 / kStandardGravityMps2,
       "bias instability"},
      {"rate_random_walk_mps2_per_sqrt_s", "m/s^2/sqrt(s)", "acceleration_random_walk_mps_per_hr_per_sqrt_hr",
       "m/s/h/sqrt(h)", kSecondsPerHour * kSqrtSecondsPerSqrtHour, "acceleration random walk"},
      {"rate_ramp_mps3", "m/s^3", "rate_ramp_ug_per_hr", "micro-g/h",
       1e6 / kStandardGravityMps2 * kSecondsPerHour, "acceleration ramp"}};
  static const NoiseTermUnits kOther[kNoiseTerms] = {
      {"quantization_y_s", "unit*s", "", "", 1.0, "quantization"},
      {"random_walk_y_sqrt_s", "unit*sqrt(s)", "", "", 1.0, "random walk (white)"},
      {"bias_instability_y", "unit", "", "", 1.0, "bias instability (flicker)"},
      {"rate_random_walk_y_per_sqrt_s", "unit/sqrt(s)", "", "", 1.0, "rate random walk"},
      {"rate_ramp_y_per_s", "unit/s", "", "", 1.0, "ramp"}};
  switch (kind) {
    case ColumnKind::kGyro:
      return kGyro[term];
    case ColumnKind::kAccel:
      return kAccel[term];
    case ColumnKind::kOther:
      break;
  }
  return kOther[term];
}

void WriteAllanCsv(const std::string& path, const std::vector<AllanCurveRecord>& curves,
                   OutputTransaction* transaction) {
  OutputFile file(path, transaction);
  file.Write("column,estimator,tau_s,terms,dev,dev_lo,dev_hi\n");
  for (const AllanCurveRecord& curve : curves) {
    for (const AllanCurveRecord::Point& point : curve.points) {
      file.Write(curve.column + "," + curve.estimator + ",");
      file.WriteNumber(point.tau_s);
      file.Write("," + std::to_string(point.terms) + ",");
      file.WriteNumber(point.dev);
      file.Write(",");
      file.WriteNumber(point.dev_lo);
      file.Write(",");
      file.WriteNumber(point.dev_hi);
      file.Write("\n");
    }
  }
  file.Commit();
}

std::string NoiseYaml(const NoiseRecord& record) {
  std::ostringstream yaml;
  yaml << "# Noise figures by imufit allan: the IEEE Std 952 model fitted to the overlapping Allan\n"
       << "# variance. Every figure is [value, 1-sigma uncertainty]. Merge into a calibration by\n"
       << "# appending this file: its only top-level key is `noise`.\n"
       << "noise:\n"
       << "  format: imufit-noise\n"
       << "  version: 1\n"
       << "  software: " << YamlString(record.software) << "\n"
       << "  samples: " << YamlString(record.samples) << "\n";
  if (!record.calibration.empty()) {
    yaml << "  calibration: " << YamlString(record.calibration) << "\n"
         << "  calibration_sha256: " << YamlString(record.calibration_sha256) << "\n";
  }
  Scalar(yaml, "  ", "sample_interval_s", record.sample_interval_s);
  yaml << "  sample_count: " << record.sample_count << "\n";
  Scalar(yaml, "  ", "duration_s", record.duration_s);
  yaml << "  model: \"sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2\"\n"
       << "  columns:\n";
  for (const NoiseColumnRecord& fit : record.columns) {
    yaml << "    " << fit.name << ":\n"
         << "      kind: " << ToString(fit.kind) << "\n"
         << "      unit: " << YamlString(SiUnit(fit.kind)) << "\n"
         << "      fitted: " << (fit.fitted ? "true" : "false") << "\n";
    if (!fit.fitted) {
      yaml << "      reason: " << YamlString(fit.reason) << "\n";
      continue;
    }
    yaml << "      points_used: " << fit.points_used << "\n";
    Scalar(yaml, "      ", "reduced_chi_square", fit.reduced_chi_square);
    for (int k = 0; k < kNoiseTerms; ++k)
      Pair(yaml, "      ", UnitsOf(fit.kind, k).si_key, fit.value[k], fit.sigma[k]);
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseTermUnits& units = UnitsOf(fit.kind, k);
      if (*units.engineer_key == '\0') continue;
      Pair(yaml, "      ", units.engineer_key, fit.value[k] * units.engineer_per_si,
           fit.sigma[k] * units.engineer_per_si);
    }
    for (int k = 0; k < kNoiseTerms; ++k) {
      // A term without a finite value and sigma is unresolved, whatever the fit said.
      const bool finite = std::isfinite(fit.value[k]) && std::isfinite(fit.sigma[k]);
      if (!fit.resolved[k] || !finite)
        yaml << "      " << UnitsOf(fit.kind, k).si_key << "_resolved: false\n";
    }
    const NoiseTermUnits& n = UnitsOf(fit.kind, kRandomWalk);
    const NoiseTermUnits& b = UnitsOf(fit.kind, kBiasInstability);
    const NoiseTermUnits& k = UnitsOf(fit.kind, kRateRandomWalk);
    const bool engineer = *n.engineer_key != '\0';
    std::ostringstream readout;
    Scalar(readout, "        ", engineer ? n.engineer_key : n.si_key,
           fit.readout_random_walk * n.engineer_per_si);
    Scalar(readout, "        ", engineer ? b.engineer_key : b.si_key,
           fit.readout_bias_instability * b.engineer_per_si);
    Scalar(readout, "        ", "bias_instability_tau_s", fit.readout_bias_tau_s);
    Scalar(readout, "        ", engineer ? k.engineer_key : k.si_key,
           fit.readout_rate_random_walk * k.engineer_per_si);
    if (!readout.str().empty()) {
      yaml << "      readout:  # IEEE 952 graphical read-outs of the measured curve\n" << readout.str();
    }
  }
  const auto has = [&](ColumnKind kind) {
    return std::any_of(record.columns.begin(), record.columns.end(),
                       [&](const NoiseColumnRecord& c) { return c.kind == kind && c.fitted; });
  };
  const bool has_gyro = has(ColumnKind::kGyro), has_accel = has(ColumnKind::kAccel);
  if (has_gyro || has_accel) {
    yaml << "  kalibr:  # imu.yaml continuous-time values, the worst axis of each sensor (a term the log\n"
            "           # does not resolve: its upper bound, value + 2 sigma)\n";
    if (has_gyro) {
      Scalar(yaml, "    ", "gyroscope_noise_density",
             WorstAxis(record.columns, ColumnKind::kGyro, kRandomWalk), "  # rad/s/sqrt(Hz)");
      Scalar(yaml, "    ", "gyroscope_random_walk",
             WorstAxis(record.columns, ColumnKind::kGyro, kRateRandomWalk), "  # rad/s^2/sqrt(Hz)");
    }
    if (has_accel) {
      Scalar(yaml, "    ", "accelerometer_noise_density",
             WorstAxis(record.columns, ColumnKind::kAccel, kRandomWalk), "  # m/s^2/sqrt(Hz)");
      Scalar(yaml, "    ", "accelerometer_random_walk",
             WorstAxis(record.columns, ColumnKind::kAccel, kRateRandomWalk), "  # m/s^3/sqrt(Hz)");
    }
    Scalar(yaml, "    ", "update_rate", 1.0 / record.sample_interval_s, "  # Hz");
  }
  return yaml.str();
}

void WriteNoiseYaml(const std::string& path, const NoiseRecord& record, OutputTransaction* transaction) {
  WriteFileAtomically(path, NoiseYaml(record), transaction);
}

std::optional<std::array<double, 2>> ReadNoiseFigure(const YAML::Node& extra, const std::string& column,
                                                     const std::string& key) {
  if (!extra || !extra.IsMap()) return std::nullopt;
  try {
    const YAML::Node node = extra["noise"]["columns"][column][key];
    if (!node || !node.IsSequence() || node.size() != 2) return std::nullopt;
    return std::array<double, 2>{node[0].as<double>(), node[1].as<double>()};
  } catch (const YAML::Exception&) {
    return std::nullopt;
  }
}

SensorNoiseFigures ReadSensorNoise(const std::string& path) {
  const YAML::Node root = yaml::LoadFile(path);
  const YAML::Node columns = root.IsMap() && root["noise"] ? root["noise"]["columns"] : YAML::Node();
  if (!columns || !columns.IsMap()) {
    throw InputError(path, "no noise.columns: give the noise YAML of `imufit allan --noise-yaml`");
  }
  SensorNoiseFigures figures;
  for (const auto& entry : columns) {
    const YAML::Node kind = entry.second["kind"];
    if (!kind || !kind.IsScalar()) continue;
    const bool gyro = kind.Scalar() == ToString(ColumnKind::kGyro);
    if (!gyro && kind.Scalar() != ToString(ColumnKind::kAccel)) continue;
    const ColumnKind column_kind = gyro ? ColumnKind::kGyro : ColumnKind::kAccel;
    const std::string column = entry.first.Scalar();
    double& density = gyro ? figures.gyro_noise_density : figures.accel_noise_density;
    double& instability = gyro ? figures.gyro_bias_instability : figures.accel_bias_instability;
    if (const auto white = ReadNoiseFigure(root, column, UnitsOf(column_kind, kRandomWalk).si_key);
        white && std::isfinite((*white)[0])) {
      density = std::max(density, (*white)[0]);
    }
    if (const auto flicker = ReadNoiseFigure(root, column, UnitsOf(column_kind, kBiasInstability).si_key);
        flicker && std::isfinite((*flicker)[0])) {
      instability = std::max(instability, (*flicker)[0]);
    }
  }
  if (!(figures.gyro_noise_density > 0.0) || !(figures.accel_noise_density > 0.0)) {
    throw InputError(path, std::string("no fitted white noise of the ") +
                               (figures.gyro_noise_density > 0.0 ? "accelerometer" : "gyro") +
                               " columns: analyse a record with gyro_x..z and accel_x..z");
  }
  return figures;
}

}  // namespace imufit
