#include "imufit/io/noise_file.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/units.h"
#include "imufit/model/check.h"
#include "noise_yaml.h"
#include "yaml_util.h"

namespace imufit {
namespace {

constexpr int kNoiseFormatVersion = 1;
constexpr const char* kNoiseModel =
    "sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2";

// Adds `key: value` when `value` is finite (the file holds no non-finite number, docs/allan.md).
void AddFinite(MachineDoc* map, const std::string& key, double value, std::string comment = "") {
  if (std::isfinite(value)) map->Add(key, MachineDoc::Number(value), std::move(comment));
}

// Adds `key: [low, high]` when both are finite.
void AddRange(MachineDoc* map, const std::string& key, const std::array<double, 2>& range) {
  if (std::isfinite(range[0]) && std::isfinite(range[1]))
    map->Add(key, MachineDoc::Numbers({range[0], range[1]}));
}

// Adds `key: [value, sigma]` when both are finite.
void AddPair(MachineDoc* map, const std::string& key, double value, double sigma) {
  if (std::isfinite(value) && std::isfinite(sigma)) map->Add(key, MachineDoc::Numbers({value, sigma}));
}

// The two-sided 95 % bound's one side: an unresolved term is given as value + kUpperBoundSigmas sigma.
constexpr double kUpperBoundSigmas = 2.0;

// A column's figure of `term` for an estimator's block: its quote when it has one, else (a file of
// an older imufit) the fitted value or an unresolved term's upper bound; nan when none.
double EstimatorFigure(const NoiseColumnRecord& column, int term, std::string* from) {
  const NoiseColumnRecord::Quote& quote = column.quote[term];
  if (std::isfinite(quote.value)) {  // in the file's units: back to SI
    const NoiseTermUnits& units = UnitsOf(column.kind, term);
    *from = quote.from;
    return *units.engineer_key != '\0' ? quote.value / units.engineer_per_si : quote.value;
  }
  *from = column.resolved[term] ? "IEEE 952 fit" : "upper bound of the IEEE 952 fit (not resolved)";
  return column.resolved[term] ? column.value[term]
                               : column.value[term] + kUpperBoundSigmas * column.sigma[term];
}

// The largest of the fitted axes of `kind` for `term` (Kalibr takes one number for all three
// axes: the worst one is the safe choice; its noise model takes every term as present, so a term
// the log does not resolve is given as what the log allows, never 0), and where it comes from.
double WorstAxis(const std::vector<NoiseColumnRecord>& columns, ColumnKind kind, int term,
                 std::string* from) {
  double worst = std::nan("");
  for (const NoiseColumnRecord& column : columns) {
    if (column.kind != kind || !column.fitted) continue;
    std::string source;
    const double figure = EstimatorFigure(column, term, &source);
    if (std::isfinite(figure) && !(worst >= figure)) {
      worst = figure;
      *from = column.name + ": " + source;
    }
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

namespace {

// The readouts' keys: engineer units where the kind has them, else SI (kRandomWalk,
// kBiasInstability, kRateRandomWalk), and the bias instability's tau.
std::array<std::string, 4> ReadoutKeys(ColumnKind kind) {
  const auto key = [kind](int term) {
    const NoiseTermUnits& units = UnitsOf(kind, term);
    return std::string(*units.engineer_key != '\0' ? units.engineer_key : units.si_key);
  };
  return {key(kRandomWalk), key(kBiasInstability), "bias_instability_tau_s", key(kRateRandomWalk)};
}

MachineDoc NoiseColumnDoc(const NoiseColumnRecord& fit) {
  MachineDoc column = MachineDoc::Map();
  column.Add("kind", MachineDoc::Text(ToString(fit.kind)));
  column.Add("unit", MachineDoc::Text(SiUnit(fit.kind)));
  column.Add("fitted", MachineDoc::Bool(fit.fitted));
  if (!fit.fitted) {
    column.Add("reason", MachineDoc::Text(fit.reason));
  } else {
    column.Add("points_used", MachineDoc::Integer(fit.points_used));
    AddFinite(&column, "reduced_chi_square", fit.reduced_chi_square);
    for (int k = 0; k < kNoiseTerms; ++k)
      AddPair(&column, UnitsOf(fit.kind, k).si_key, fit.value[k], fit.sigma[k]);
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseTermUnits& units = UnitsOf(fit.kind, k);
      if (*units.engineer_key == '\0') continue;
      AddPair(&column, units.engineer_key, fit.value[k] * units.engineer_per_si,
              fit.sigma[k] * units.engineer_per_si);
    }
    for (int k = 0; k < kNoiseTerms; ++k) {
      // A term without a finite value and sigma is unresolved, whatever the fit said.
      const bool finite = std::isfinite(fit.value[k]) && std::isfinite(fit.sigma[k]);
      if (!fit.resolved[k] || !finite) {
        column.Add(std::string(UnitsOf(fit.kind, k).si_key) + "_resolved", MachineDoc::Bool(false));
      }
    }
    column.Add(
        "describes_curve", MachineDoc::Bool(fit.describes_curve),
        fit.describes_curve ? "" : "reduced chi-square above the misfit threshold: quote the read-outs");
    AddRange(&column, "fit_taus_s", fit.fit_taus_s);
    MachineDoc term_taus = MachineDoc::Map();
    for (int k = 0; k < kNoiseTerms; ++k)
      AddRange(&term_taus, UnitsOf(fit.kind, k).si_key, fit.term_taus_s[k]);
    if (!term_taus.items().empty()) {
      column.Add("term_taus_s", std::move(term_taus),
                 "where each term carries a quarter of the model or more");
    }
    if (fit.filter_detected) {
      MachineDoc filter = MachineDoc::Map();
      AddFinite(&filter, "lag1", fit.sample_lag1);
      AddFinite(&filter, "filtered_below_tau_s", fit.filtered_below_tau_s);
      column.Add("output_filter", std::move(filter),
                 "taus below filtered_below_tau_s are left out of the fit");
    }
    const std::array<std::string, 4> keys = ReadoutKeys(fit.kind);
    const double readouts[4] = {fit.readout_random_walk, fit.readout_bias_instability, fit.readout_bias_tau_s,
                                fit.readout_rate_random_walk};
    MachineDoc readout = MachineDoc::Map();
    for (int i = 0; i < 4; ++i) AddFinite(&readout, keys[i], readouts[i]);
    AddRange(&readout, keys[0] + "_taus_s", fit.readout_random_walk_taus_s);
    AddRange(&readout, keys[1] + "_interval", fit.readout_bias_interval);
    if (std::isfinite(fit.readout_bias_instability)) {
      readout.Add("bias_instability_resolved", MachineDoc::Bool(fit.readout_bias_resolved));
    }
    AddRange(&readout, keys[3] + "_taus_s", fit.readout_rate_random_walk_taus_s);
    AddFinite(&readout, "skipped_tau_s", fit.skipped_tau_s);
    if (!readout.items().empty()) {
      column.Add("readout", std::move(readout), "IEEE 952 graphical read-outs of the measured curve");
    }
    MachineDoc quote = MachineDoc::Map();
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseColumnRecord::Quote& q = fit.quote[k];
      if (!std::isfinite(q.value)) continue;
      const NoiseTermUnits& units = UnitsOf(fit.kind, k);
      MachineDoc figure = MachineDoc::Map();
      if (q.at_most) {
        figure.Add("at_most", MachineDoc::Number(q.value));
      } else {
        figure.Add("value", MachineDoc::Number(q.value));
        AddFinite(&figure, "sigma", q.sigma);
        AddRange(&figure, "interval", q.interval);
      }
      figure.Add("from", MachineDoc::Text(q.from));
      quote.Add(*units.engineer_key != '\0' ? units.engineer_key : units.si_key, std::move(figure));
    }
    if (!quote.items().empty()) {
      column.Add("quote", std::move(quote),
                 "the figure to quote per term (docs/allan.md), interval at 2 sigma");
    }
  }
  if (fit.extra.IsMap()) {
    for (const auto& entry : fit.extra) column.Add(entry.first.Scalar(), MachineDocOfYaml(entry.second));
  }
  return column;
}

bool HasFitted(const NoiseRecord& record, ColumnKind kind) {
  return std::any_of(record.columns.begin(), record.columns.end(),
                     [&](const NoiseColumnRecord& c) { return c.kind == kind && c.fitted; });
}

// ---------------------------------------------------------------- reading

double NumberOr(const yaml::Located& block, const char* key, double otherwise) {
  return block.Has(key) ? block[key].Double() : otherwise;
}

std::string TextOr(const yaml::Located& block, const char* key) {
  return block.Has(key) ? block[key].String() : std::string();
}

// `key: [low, high]` into `range` when present.
void ReadRange(const yaml::Located& block, const std::string& key, std::array<double, 2>* range) {
  if (!block.Has(key)) return;
  const std::vector<double> pair = block[key].Doubles(2);
  *range = {pair[0], pair[1]};
}

// Unknown keys of `block` into `extra` (a map, or left null).
void KeepUnknown(const yaml::Located& block, const std::vector<std::string>& known, YAML::Node* extra) {
  for (const auto& entry : block.node) {
    if (std::find(known.begin(), known.end(), entry.first.Scalar()) != known.end()) continue;
    if (!extra->IsMap()) *extra = YAML::Node(YAML::NodeType::Map);
    extra->force_insert(entry.first, entry.second);
  }
}

NoiseColumnRecord ReadNoiseColumn(const std::string& name, const yaml::Located& block) {
  block.RequireMap();
  NoiseColumnRecord column;
  column.name = name;
  std::vector<std::string> known = {"kind",   "unit", "fitted", "reason", "points_used", "reduced_chi_square",
                                    "readout"};
  if (block.Has("kind")) {
    const std::string kind = block["kind"].String();
    if (kind == ToString(ColumnKind::kGyro)) {
      column.kind = ColumnKind::kGyro;
    } else if (kind == ToString(ColumnKind::kAccel)) {
      column.kind = ColumnKind::kAccel;
    } else if (kind != ToString(ColumnKind::kOther)) {
      block["kind"].Fail(QuoteForMessage(kind) + " is not a kind of column (gyro, accel, other)");
    }
  }
  column.fitted = block.Has("fitted") && block["fitted"].Bool();
  column.reason = TextOr(block, "reason");
  if (block.Has("points_used")) {
    const long points = block["points_used"].Integer();
    if (points < 0 || points > std::numeric_limits<int>::max()) block["points_used"].Fail("out of range");
    column.points_used = static_cast<int>(points);
  }
  column.reduced_chi_square = NumberOr(block, "reduced_chi_square", std::nan(""));
  for (int k = 0; k < kNoiseTerms; ++k) {
    const NoiseTermUnits& units = UnitsOf(column.kind, k);
    const std::string resolved_key = std::string(units.si_key) + "_resolved";
    known.push_back(units.si_key);
    known.push_back(resolved_key);
    if (*units.engineer_key != '\0') known.push_back(units.engineer_key);  // derived from the SI pair
    column.value[k] = column.sigma[k] = std::nan("");
    if (block.Has(units.si_key)) {
      const std::vector<double> pair = block[units.si_key].Doubles(2);
      column.value[k] = pair[0];
      column.sigma[k] = pair[1];
    }
    column.resolved[k] = !(block.Has(resolved_key) && !block[resolved_key].Bool());
  }
  if (block.Has("readout")) {
    const yaml::Located readout = block["readout"];
    readout.RequireMap();
    const std::array<std::string, 4> keys = ReadoutKeys(column.kind);
    const std::string random_walk_taus = keys[0] + "_taus_s", bias_interval = keys[1] + "_interval",
                      rate_random_walk_taus = keys[3] + "_taus_s";
    readout.RejectUnknownKeys({keys[0].c_str(), keys[1].c_str(), keys[2].c_str(), keys[3].c_str(),
                               random_walk_taus.c_str(), bias_interval.c_str(), "bias_instability_resolved",
                               rate_random_walk_taus.c_str(), "skipped_tau_s"});
    double* readouts[4] = {&column.readout_random_walk, &column.readout_bias_instability,
                           &column.readout_bias_tau_s, &column.readout_rate_random_walk};
    for (int i = 0; i < 4; ++i) *readouts[i] = NumberOr(readout, keys[i].c_str(), std::nan(""));
    ReadRange(readout, random_walk_taus, &column.readout_random_walk_taus_s);
    ReadRange(readout, bias_interval, &column.readout_bias_interval);
    ReadRange(readout, rate_random_walk_taus, &column.readout_rate_random_walk_taus_s);
    column.readout_bias_resolved =
        readout.Has("bias_instability_resolved") && readout["bias_instability_resolved"].Bool();
    column.skipped_tau_s = NumberOr(readout, "skipped_tau_s", std::nan(""));
  }
  column.describes_curve = !block.Has("describes_curve") || block["describes_curve"].Bool();
  ReadRange(block, "fit_taus_s", &column.fit_taus_s);
  if (block.Has("term_taus_s")) {
    const yaml::Located term_taus = block["term_taus_s"];
    term_taus.RequireMap();
    for (int k = 0; k < kNoiseTerms; ++k)
      ReadRange(term_taus, UnitsOf(column.kind, k).si_key, &column.term_taus_s[k]);
  }
  if (block.Has("output_filter")) {
    const yaml::Located filter = block["output_filter"];
    filter.RejectUnknownKeys({"lag1", "filtered_below_tau_s"});
    column.filter_detected = true;
    column.sample_lag1 = NumberOr(filter, "lag1", std::nan(""));
    column.filtered_below_tau_s = NumberOr(filter, "filtered_below_tau_s", std::nan(""));
  }
  if (block.Has("quote")) {
    const yaml::Located quote = block["quote"];
    quote.RequireMap();
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseTermUnits& units = UnitsOf(column.kind, k);
      const bool engineer = *units.engineer_key != '\0';
      const char* key = engineer ? units.engineer_key : units.si_key;
      if (!quote.Has(key)) continue;
      const yaml::Located figure = quote[key];
      figure.RejectUnknownKeys({"value", "sigma", "interval", "at_most", "from"});
      NoiseColumnRecord::Quote& q = column.quote[k];
      q.at_most = figure.Has("at_most");
      q.value = NumberOr(figure, q.at_most ? "at_most" : "value", std::nan(""));
      q.sigma = NumberOr(figure, "sigma", std::nan(""));
      ReadRange(figure, "interval", &q.interval);
      q.from = TextOr(figure, "from");
    }
  }
  for (const char* key : {"describes_curve", "fit_taus_s", "term_taus_s", "output_filter", "quote"})
    known.push_back(key);
  KeepUnknown(block, known, &column.extra);
  return column;
}

}  // namespace

MachineDoc NoiseDoc(const NoiseRecord& record) {
  MachineDoc noise = MachineDoc::Map();
  noise.Add("format", MachineDoc::Text("imufit-noise"));
  noise.Add("version", MachineDoc::Integer(kNoiseFormatVersion));
  if (!record.software.empty()) noise.Add("software", MachineDoc::Text(record.software));
  if (!record.samples.empty()) noise.Add("samples", MachineDoc::Text(record.samples));
  if (!record.calibration.empty()) {
    noise.Add("calibration", MachineDoc::Text(record.calibration));
    noise.Add("calibration_sha256", MachineDoc::Text(record.calibration_sha256));
  }
  AddFinite(&noise, "sample_interval_s", record.sample_interval_s);
  if (record.sample_count > 0) noise.Add("sample_count", MachineDoc::Integer(record.sample_count));
  AddFinite(&noise, "duration_s", record.duration_s);
  noise.Add("model", MachineDoc::Text(kNoiseModel));
  MachineDoc columns = MachineDoc::Map();
  for (const NoiseColumnRecord& column : record.columns) columns.Add(column.name, NoiseColumnDoc(column));
  if (!record.columns.empty()) noise.Add("columns", std::move(columns));
  const KalibrNoiseRecord k = KalibrNoiseOf(record);
  // The estimators' blocks: the same four figures under each one's keys (docs/allan.md).
  const std::string inflation =
      "x " + FormatDouble(k.inflation) + (k.inflation == 1.0 ? " (as measured)" : "");
  const auto from = [&](const std::string& unit, const std::string& source) {
    return source.empty() ? unit : unit + "; " + source;
  };
  if (k.inflation != 1.0 || std::isfinite(k.gyroscope_noise_density) ||
      std::isfinite(k.accelerometer_noise_density)) {
    noise.Add("vio_inflation", MachineDoc::Number(k.inflation),
              std::string("the estimator blocks below are the measured figures times this; advised: ") +
                  kAdvisedVioInflation);
  }
  MachineDoc kalibr = MachineDoc::Map();
  AddFinite(&kalibr, "gyroscope_noise_density", k.gyroscope_noise_density,
            from("rad/s/sqrt(Hz)", k.gyroscope_noise_density_from));
  AddFinite(&kalibr, "gyroscope_random_walk", k.gyroscope_random_walk,
            from("rad/s^2/sqrt(Hz)", k.gyroscope_random_walk_from));
  AddFinite(&kalibr, "accelerometer_noise_density", k.accelerometer_noise_density,
            from("m/s^2/sqrt(Hz)", k.accelerometer_noise_density_from));
  AddFinite(&kalibr, "accelerometer_random_walk", k.accelerometer_random_walk,
            from("m/s^3/sqrt(Hz)", k.accelerometer_random_walk_from));
  AddFinite(&kalibr, "update_rate", k.update_rate, "Hz");
  if (!kalibr.items().empty()) {
    noise.Add(
        "kalibr", std::move(kalibr),
        "Kalibr imu.yaml, continuous time, the worst axis of each sensor's figure to quote " + inflation);
    MachineDoc openvins = MachineDoc::Map();
    AddFinite(&openvins, "accelerometer_noise_density", k.accelerometer_noise_density, "m/s^2/sqrt(Hz)");
    AddFinite(&openvins, "accelerometer_random_walk", k.accelerometer_random_walk, "m/s^3/sqrt(Hz)");
    AddFinite(&openvins, "gyroscope_noise_density", k.gyroscope_noise_density, "rad/s/sqrt(Hz)");
    AddFinite(&openvins, "gyroscope_random_walk", k.gyroscope_random_walk, "rad/s^2/sqrt(Hz)");
    AddFinite(&openvins, "update_rate", k.update_rate, "Hz");
    noise.Add("openvins", std::move(openvins),
              "OpenVINS kalibr_imu_chain.yaml, under imu0: (Kalibr's keys and units) " + inflation);
    MachineDoc vins = MachineDoc::Map();
    AddFinite(&vins, "acc_n", k.accelerometer_noise_density, "m/s^2/sqrt(Hz), white noise");
    AddFinite(&vins, "gyr_n", k.gyroscope_noise_density, "rad/s/sqrt(Hz), white noise");
    AddFinite(&vins, "acc_w", k.accelerometer_random_walk, "m/s^3/sqrt(Hz), bias random walk");
    AddFinite(&vins, "gyr_w", k.gyroscope_random_walk, "rad/s^2/sqrt(Hz), bias random walk");
    noise.Add("vins_mono", std::move(vins),
              "VINS-Mono / VINS-Fusion config keys (continuous-time densities, as Kalibr's) " + inflation);
  }
  if (record.extra.IsMap()) {
    for (const auto& entry : record.extra) noise.Add(entry.first.Scalar(), MachineDocOfYaml(entry.second));
  }
  return noise;
}

NoiseRecord ReadNoiseRecord(const yaml::Located& block) {
  block.RequireMap();
  if (block.Has("format") && block["format"].String() != "imufit-noise") {
    block["format"].Fail(QuoteForMessage(block["format"].String()) + " is not \"imufit-noise\"");
  }
  if (block.Has("version")) {
    const long version = block["version"].Integer();
    if (version < 1 || version > kNoiseFormatVersion) {
      block["version"].Fail("version " + std::to_string(version) +
                            " is not supported (this imufit reads version " +
                            std::to_string(kNoiseFormatVersion) + ")");
    }
  }
  NoiseRecord record;
  record.software = TextOr(block, "software");
  record.samples = TextOr(block, "samples");
  record.calibration = TextOr(block, "calibration");
  record.calibration_sha256 = TextOr(block, "calibration_sha256");
  record.sample_interval_s = NumberOr(block, "sample_interval_s", std::nan(""));
  if (block.Has("sample_count")) record.sample_count = block["sample_count"].Integer();
  record.duration_s = NumberOr(block, "duration_s", std::nan(""));
  if (block.Has("columns")) {
    const yaml::Located columns = block["columns"];
    columns.RequireMap();
    for (const auto& entry : columns.node) {
      const std::string name = entry.first.Scalar();
      record.columns.push_back(ReadNoiseColumn(name, columns[name]));
    }
  }
  if (block.Has("kalibr")) {
    const yaml::Located kalibr = block["kalibr"];
    kalibr.RejectUnknownKeys({"gyroscope_noise_density", "gyroscope_random_walk",
                              "accelerometer_noise_density", "accelerometer_random_walk", "update_rate"});
    KalibrNoiseRecord k;
    k.gyroscope_noise_density = NumberOr(kalibr, "gyroscope_noise_density", std::nan(""));
    k.gyroscope_random_walk = NumberOr(kalibr, "gyroscope_random_walk", std::nan(""));
    k.accelerometer_noise_density = NumberOr(kalibr, "accelerometer_noise_density", std::nan(""));
    k.accelerometer_random_walk = NumberOr(kalibr, "accelerometer_random_walk", std::nan(""));
    k.update_rate = NumberOr(kalibr, "update_rate", std::nan(""));
    record.kalibr = k;
  }
  record.vio_inflation = NumberOr(block, "vio_inflation", 1.0);
  if (!(record.vio_inflation > 0.0)) block["vio_inflation"].Fail("must be a positive number");
  if (record.kalibr) {
    record.kalibr->inflation = record.vio_inflation;
    // A block that says what the columns give is theirs: derived again, with where each figure
    // comes from. One that differs (edited by hand) is kept as the file states it.
    NoiseRecord derived = record;
    derived.kalibr.reset();
    const KalibrNoiseRecord own = KalibrNoiseOf(derived);
    const auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
    if (same(own.gyroscope_noise_density, record.kalibr->gyroscope_noise_density) &&
        same(own.gyroscope_random_walk, record.kalibr->gyroscope_random_walk) &&
        same(own.accelerometer_noise_density, record.kalibr->accelerometer_noise_density) &&
        same(own.accelerometer_random_walk, record.kalibr->accelerometer_random_walk) &&
        same(own.update_rate, record.kalibr->update_rate)) {
      record.kalibr.reset();
    }
  }
  KeepUnknown(
      block,
      {"format", "version", "software", "samples", "calibration", "calibration_sha256", "sample_interval_s",
       "sample_count", "duration_s", "model", "columns", "kalibr", "vio_inflation", "openvins", "vins_mono"},
      &record.extra);
  return record;
}

KalibrNoiseRecord KalibrNoiseOf(const NoiseRecord& record) {
  if (record.kalibr) return *record.kalibr;
  KalibrNoiseRecord k;
  k.inflation = record.vio_inflation;
  const auto worst = [&](ColumnKind kind, int term, std::string* from) {
    return WorstAxis(record.columns, kind, term, from) * record.vio_inflation;
  };
  if (HasFitted(record, ColumnKind::kGyro)) {
    k.gyroscope_noise_density = worst(ColumnKind::kGyro, kRandomWalk, &k.gyroscope_noise_density_from);
    k.gyroscope_random_walk = worst(ColumnKind::kGyro, kRateRandomWalk, &k.gyroscope_random_walk_from);
  }
  if (HasFitted(record, ColumnKind::kAccel)) {
    k.accelerometer_noise_density =
        worst(ColumnKind::kAccel, kRandomWalk, &k.accelerometer_noise_density_from);
    k.accelerometer_random_walk =
        worst(ColumnKind::kAccel, kRateRandomWalk, &k.accelerometer_random_walk_from);
  }
  if (HasFitted(record, ColumnKind::kGyro) || HasFitted(record, ColumnKind::kAccel)) {
    k.update_rate = 1.0 / record.sample_interval_s;
  }
  return k;
}

std::string NoiseYaml(const NoiseRecord& record) {
  MachineDoc doc = MachineDoc::Map();
  doc.Comment("Noise figures by imufit allan: the IEEE Std 952 model fitted to the overlapping Allan");
  doc.Comment("variance. Every figure is [value, 1-sigma uncertainty]. Merge into a calibration by");
  doc.Comment("appending this file: its only top-level key is `noise`.");
  doc.Add("noise", NoiseDoc(record));
  return YamlText(doc);
}

void WriteNoiseYaml(const std::string& path, const NoiseRecord& record, OutputTransaction* transaction) {
  WriteFileAtomically(path, NoiseYaml(record), transaction);
}

NoiseRecord ReadNoiseFile(const std::string& path) {
  const YAML::Node root = yaml::LoadFile(path);
  const yaml::Located located{&path, root, ""};
  if (!root.IsMap() || !located.Has("noise")) {
    throw InputError(path, "no noise block: give the noise YAML of `imufit allan --noise-yaml`");
  }
  return ReadNoiseRecord(located["noise"]);
}

std::optional<std::array<double, 2>> NoiseFigure(const std::optional<NoiseRecord>& noise,
                                                 const std::string& column, const std::string& key) {
  if (!noise) return std::nullopt;
  for (const NoiseColumnRecord& c : noise->columns) {
    if (c.name != column || !c.fitted) continue;
    for (int k = 0; k < kNoiseTerms; ++k) {
      const NoiseTermUnits& units = UnitsOf(c.kind, k);
      const double factor = key == units.si_key                                        ? 1.0
                            : *units.engineer_key != '\0' && key == units.engineer_key ? units.engineer_per_si
                                                                                       : 0.0;
      if (factor == 0.0 || !std::isfinite(c.value[k]) || !std::isfinite(c.sigma[k])) continue;
      return std::array<double, 2>{c.value[k] * factor, c.sigma[k] * factor};
    }
  }
  return std::nullopt;
}

SensorNoiseFigures ReadSensorNoise(const std::string& path) {
  const NoiseRecord record = ReadNoiseFile(path);
  if (record.columns.empty()) {
    throw InputError(path, "no noise.columns: give the noise YAML of `imufit allan --noise-yaml`");
  }
  SensorNoiseFigures figures;
  for (const NoiseColumnRecord& column : record.columns) {
    if (column.kind == ColumnKind::kOther) continue;
    const bool gyro = column.kind == ColumnKind::kGyro;
    double& density = gyro ? figures.gyro_noise_density : figures.accel_noise_density;
    double& instability = gyro ? figures.gyro_bias_instability : figures.accel_bias_instability;
    const auto finite = [&](int term) {
      return std::isfinite(column.value[term]) && std::isfinite(column.sigma[term]);
    };
    if (finite(kRandomWalk)) density = std::max(density, column.value[kRandomWalk]);
    if (finite(kBiasInstability)) instability = std::max(instability, column.value[kBiasInstability]);
  }
  if (!(figures.gyro_noise_density > 0.0) || !(figures.accel_noise_density > 0.0)) {
    throw InputError(path, std::string("no fitted white noise of the ") +
                               (figures.gyro_noise_density > 0.0 ? "accelerometer" : "gyro") +
                               " columns: analyse a record with gyro_x..z and accel_x..z");
  }
  return figures;
}

}  // namespace imufit
