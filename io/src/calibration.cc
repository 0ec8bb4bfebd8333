#include "imufit/io/calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include "fit_record_yaml.h"
#include "imufit/io/error.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/output_file.h"
#include "imufit/model/check.h"
#include "imufit/model/rate_table.h"
#include "noise_yaml.h"
#include "yaml_util.h"

namespace imufit {
namespace {

constexpr const char* kKnownKeys[] = {
    "format", "version", "serial", "created_utc", "software", "reference_temp_c", "fit_temp_range_c", "gyro",
    "accel",  "sigma",   "fit",    "check",       "noise",    "body_frame"};

// One sensor's coefficient tree (bias, scale, misalignment[, g_sensitivity]), each coefficient a
// list c0..c3 on one line.
MachineDoc SensorDoc(const double* params, int coefficients, const char* unit) {
  MachineDoc sensor = MachineDoc::Map();
  if (unit != nullptr) sensor.Add("unit", MachineDoc::Text(unit));
  MachineDoc group_doc = MachineDoc::Map();
  const char* group = nullptr;
  for (int i = 0; i < coefficients; ++i) {
    const CoefficientName& name = kCoefficientNames[i];
    if (group != nullptr && std::string(group) != name.group) {
      sensor.Add(group, std::move(group_doc));
      group_doc = MachineDoc::Map();
    }
    group = name.group;
    group_doc.Add(name.axis, MachineDoc::Numbers(std::vector<double>(params + i * kPolynomialTerms,
                                                                     params + (i + 1) * kPolynomialTerms)));
  }
  if (group != nullptr) sensor.Add(group, std::move(group_doc));
  return sensor;
}

void ReadSensor(const yaml::Located& sensor, double* params, int coefficients) {
  for (int i = 0; i < coefficients; ++i) {
    const CoefficientName& name = kCoefficientNames[i];
    const std::vector<double> terms = sensor[name.group][name.axis].Doubles(kPolynomialTerms);
    for (int k = 0; k < kPolynomialTerms; ++k) params[i * kPolynomialTerms + k] = terms[k];
  }
}

// Refuses a sensor whose correction cannot be computed across the fit temperature range, or
// whose scale factor is negative: a scale factor that changes sign, comes near zero (below
// kMinScale, or below 1/1000 of its largest magnitude), is negative (the unit's axis or rotation
// sign convention is the opposite of the body frame's), or a misalignment matrix M that is nearly
// singular (det M below 0.1).
void CheckInvertible(const yaml::Located& sensor, const double* params, int coefficients, double center_c,
                     const std::array<double, 2>& range) {
  constexpr double kMinScale = 1e-9;
  const bool gyro = coefficients == kGyroCoefficients;
  for (int axis = 0; axis < 3; ++axis) {
    const double* c = params + (kScaleCoefficient + axis) * kPolynomialTerms;
    const PolynomialExtremes e = ExtremesOverRange(c, center_c, range[0], range[1]);
    const bool sign_change = e.min_value <= 0.0 && e.max_value >= 0.0;
    const bool negative = e.max_value < 0.0;
    const double largest = std::max(std::abs(e.min_value), std::abs(e.max_value));
    const double smallest = std::min(std::abs(e.min_value), std::abs(e.max_value));
    const double at_c = std::abs(e.min_value) < std::abs(e.max_value) ? e.min_at_c : e.max_at_c;
    if (sign_change || negative || !(smallest >= kMinScale) || !(smallest >= 1e-3 * largest) ||
        !std::isfinite(largest)) {
      char text[480];
      if (sign_change) {
        std::snprintf(
            text, sizeof text,
            "the scale factor changes sign within fit_temp_range_c [%g, %g] degC (%.4g at %.4g degC, "
            "%.4g at %.4g degC); the correction divides by it; %s",
            range[0], range[1], e.min_value, e.min_at_c, e.max_value, e.max_at_c,
            ScaleSignAdvice(gyro, axis).c_str());
      } else if (negative) {
        std::snprintf(
            text, sizeof text,
            "the scale factor is negative within fit_temp_range_c [%g, %g] degC (%.4g at %.4g degC); %s",
            range[0], range[1], e.max_value, e.max_at_c, ScaleSignAdvice(gyro, axis).c_str());
      } else {
        std::snprintf(
            text, sizeof text,
            "the scale factor comes near zero within fit_temp_range_c [%g, %g] degC (%.3g at %.4g degC, "
            "at most %.3g elsewhere); the correction divides by it",
            range[0], range[1], EvaluateTemperaturePolynomial(c, at_c - center_c), at_c, largest);
      }
      sensor["scale"][kCoefficientNames[kScaleCoefficient + axis].axis].Fail(text);
    }
  }
  constexpr int kSteps = 64;
  for (int i = 0; i <= kSteps; ++i) {
    const double t = range[0] + (range[1] - range[0]) * i / kSteps;
    const double det = CoefficientsAt(params, coefficients, t - center_c).misalignment.determinant();
    if (!(det >= 0.1)) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "M is nearly singular within fit_temp_range_c: det M = %.3g at %.4g degC", det, t);
      sensor["misalignment"].Fail(text);
    }
  }
}

void CheckUnit(const yaml::Located& sensor, const std::string& expected) {
  if (sensor.Has("unit") && sensor["unit"].String() != expected) {
    sensor["unit"].Fail(QuoteForMessage(sensor["unit"].String()) + " is not supported (expected " + expected +
                        ")");
  }
}

}  // namespace

std::vector<std::string> UncalibratedSensors(const Calibration& calibration) {
  if (!calibration.fit) return {};
  const FitRecord& record = *calibration.fit;
  if (record.uncalibrated_sensors) return *record.uncalibrated_sensors;
  // An older record: a sensor whose bias is held was held whole; without a prior, at nominal.
  std::vector<std::string> sensors;
  if (!record.held || record.held_values.value_or("") == "prior") return sensors;
  for (const char* sensor : {"gyro", "accel"}) {
    if (std::count(record.held->begin(), record.held->end(), std::string(sensor) + ".bias") > 0)
      sensors.push_back(sensor);
  }
  return sensors;
}

Calibration ReadCalibration(const std::string& path) {
  const YAML::Node root_node = yaml::LoadFile(path);
  if (!root_node.IsMap()) throw InputError(path, "not an imufit calibration (expected a YAML mapping)");
  const yaml::Located root{&path, root_node, ""};
  const std::string format = root["format"].String();
  if (format != "imufit-calibration") {
    root["format"].Fail(QuoteForMessage(format) + " is not \"imufit-calibration\"");
  }
  const long version = root["version"].Integer();
  if (version < 1 || version > kCalibrationFormatVersion) {
    root["version"].Fail("version " + std::to_string(version) +
                         " is not supported (this imufit reads up to version " +
                         std::to_string(kCalibrationFormatVersion) + ")");
  }
  Calibration calibration;
  if (root.Has("serial")) calibration.serial = root["serial"].String();
  if (root.Has("created_utc")) calibration.created_utc = root["created_utc"].String();
  if (root.Has("software")) calibration.software = root["software"].String();
  calibration.model.basis.center_c =
      root.Has("reference_temp_c") ? root["reference_temp_c"].Double() : kReferenceTempC;
  calibration.model.basis.half_range_c = 1.0;
  if (root.Has("fit_temp_range_c")) {
    const std::vector<double> range = root["fit_temp_range_c"].Doubles(2);
    if (!(range[0] <= range[1])) root["fit_temp_range_c"].Fail("the range must be [low, high]");
    calibration.fit_temp_range_c = {range[0], range[1]};
  }
  const yaml::Located gyro = root["gyro"];
  CheckUnit(gyro, "rad/s");
  ReadSensor(gyro, calibration.model.gyro.data(), kGyroCoefficients);
  const yaml::Located accel = root["accel"];
  CheckUnit(accel, "m/s^2");
  ReadSensor(accel, calibration.model.accel.data(), kAccelCoefficients);
  // A scale factor near zero or a singular M would make every consumer's correction non-finite
  // or meaningless: refuse them here.
  const double center_c = calibration.model.basis.center_c;
  CheckInvertible(gyro, calibration.model.gyro.data(), kGyroCoefficients, center_c,
                  calibration.fit_temp_range_c);
  CheckInvertible(accel, calibration.model.accel.data(), kAccelCoefficients, center_c,
                  calibration.fit_temp_range_c);
  if (root.Has("sigma")) {
    const yaml::Located sigma = root["sigma"];
    SensorModel sigmas;
    sigmas.basis = calibration.model.basis;
    ReadSensor(sigma["gyro"], sigmas.gyro.data(), kGyroCoefficients);
    ReadSensor(sigma["accel"], sigmas.accel.data(), kAccelCoefficients);
    calibration.sigma = sigmas;
  }
  if (root.Has("fit")) calibration.fit = ReadFitRecord(root["fit"]);
  if (root.Has("check")) calibration.check = ReadCheckRecord(root["check"]);
  if (root.Has("noise")) calibration.noise = ReadNoiseRecord(root["noise"]);
  if (root.Has("body_frame")) {
    calibration.body_frame = root["body_frame"].String();
    if (*calibration.body_frame != kBodyFrameAccelerometerXy) {
      root["body_frame"].Fail(QuoteForMessage(*calibration.body_frame) +
                              " is not a body frame imufit knows (" + kBodyFrameAccelerometerXy + ")");
    }
  }
  calibration.extra = YAML::Node(YAML::NodeType::Map);
  for (const auto& entry : root_node) {
    const std::string& key = entry.first.Scalar();
    bool known = false;
    for (const char* k : kKnownKeys) known = known || key == k;
    // force_insert: no search, so many keys cost linear time (LoadFile refused duplicates).
    if (!known) calibration.extra.force_insert(key, entry.second);
  }
  return calibration;
}

MachineDoc CalibrationDoc(const Calibration& calibration) {
  IMUFIT_CHECK(calibration.model.basis.half_range_c == 1.0, "a calibration is written in powers of dT");
  MachineDoc doc = MachineDoc::Map();
  doc.Add("format", MachineDoc::Text("imufit-calibration"));
  doc.Add("version", MachineDoc::Integer(kCalibrationFormatVersion));
  doc.Add("serial", MachineDoc::Text(calibration.serial));
  doc.Add("created_utc", MachineDoc::Text(calibration.created_utc));
  doc.Add("software", MachineDoc::Text(calibration.software));
  doc.Add("reference_temp_c", MachineDoc::Number(calibration.model.basis.center_c));
  doc.Add("fit_temp_range_c",
          MachineDoc::Numbers({calibration.fit_temp_range_c[0], calibration.fit_temp_range_c[1]}));
  doc.Add("gyro", SensorDoc(calibration.model.gyro.data(), kGyroCoefficients, "rad/s"));
  doc.Add("accel", SensorDoc(calibration.model.accel.data(), kAccelCoefficients, "m/s^2"));
  if (calibration.sigma) {
    doc.Comment("1-sigma uncertainty of every coefficient above, same layout and units");
    MachineDoc sigma = MachineDoc::Map();
    sigma.Add("gyro", SensorDoc(calibration.sigma->gyro.data(), kGyroCoefficients, nullptr));
    sigma.Add("accel", SensorDoc(calibration.sigma->accel.data(), kAccelCoefficients, nullptr));
    doc.Add("sigma", std::move(sigma));
  }
  // The fit's record, the noise record, then the further keys.
  if (calibration.fit) doc.Add("fit", FitRecordDoc(*calibration.fit));
  if (calibration.check) doc.Add("check", CheckRecordDoc(*calibration.check));
  if (calibration.noise) doc.Add("noise", NoiseDoc(*calibration.noise));
  if (calibration.body_frame) doc.Add("body_frame", MachineDoc::Text(*calibration.body_frame));
  if (calibration.extra.IsMap()) {
    for (const auto& entry : calibration.extra) {
      const std::string& key = entry.first.Scalar();
      IMUFIT_CHECK(key != "fit" && key != "check" && key != "noise" && key != "body_frame",
                   "the records are written from their typed members");
      doc.Add(key, MachineDocOfYaml(entry.second));
    }
  }
  return doc;
}

std::string CalibrationToYaml(const Calibration& calibration) {
  return YamlText(CalibrationDoc(calibration));
}

void WriteCalibration(const std::string& path, const Calibration& calibration,
                      OutputTransaction* transaction) {
  WriteFileAtomically(path, CalibrationToYaml(calibration), transaction);
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace imufit
