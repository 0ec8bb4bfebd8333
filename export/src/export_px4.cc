// --format px4: PX4's thermal compensation and accelerometer calibration parameters, in the tab-
// separated .params format of QGroundControl.
//
// What PX4 does with them (src/modules/temperature_compensation/TemperatureCompensation.cpp,
// src/lib/sensor_calibration/{Gyroscope,Accelerometer}.hpp), in float32, with d the driver's output
// in rad/s or m/s^2 and T the sensor's temperature:
//
//   dT        = clamp(T, TMIN, TMAX) - TREF
//   offset    = X0 + X1 dT + X2 dT^2 + X3 dT^3        (dT^2 = dT dT, dT^3 = dT^2 dT)
//   gyro      = d - offset - CAL_GYRO0_xOFF
//   accel     = (d - offset - CAL_ACC0_xOFF) * CAL_ACC0_xSCALE
//
// (any instance n of TC_Gn / TC_An / CAL_ACCn: PX4 finds a sensor's parameters by their _ID), then
// PX4's board rotation, which is imufit's body frame only if the sensor is mounted so.
// With d = raw / k (k the driver's raw per SI unit), imufit's model gives exactly
// offset(T) = V(T) / k, a cubic written here in powers of T - TREF with TREF the calibration's
// reference; the accelerometer's scale k / S(T) is held at TREF; the gyro scale, both
// misalignments and the g-sensitivity have no parameter, and are the loss.
//
// How the scale is loaded differs between releases (src/lib/sensor_calibration/Accelerometer.cpp):
// v1.12 passes CAL_ACCn_xSCALE through set_scale(), which keeps the scale it holds (1 after boot)
// unless the new one differs from it by more than 0.01 (Euclidean norm of the difference);
// releases that read the parameters directly apply it as written. Both are measured; the loss
// reported is the worse of the two, per axis. TC_G_ENABLE and TC_A_ENABLE take effect at the next
// boot (@reboot_required), and the boot also resets set_scale()'s reference to 1.
#include <cmath>
#include <cstdint>

#include "export_internal.h"
#include "imufit/io/error.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer =
    "PX4 v1.12 and later (TC_Gn/TC_An thermal compensation, CAL_ACCn scale, loaded through v1.12's "
    "set_scale() and directly; .params of QGroundControl)";
constexpr float kSetScaleThreshold = 0.01f;  // set_scale(): |scale - current| must exceed it
constexpr int kTypeInt32 = 6;                // MAV_PARAM_TYPE_INT32
constexpr int kTypeReal32 = 9;               // MAV_PARAM_TYPE_REAL32

struct Parameter {
  std::string name;
  std::string text;
  int type;
};

// One sensor's thermal parameters, as PX4 reads them back (float32).
struct Px4Thermal {
  float x[kPolynomialTerms][3];  // X0..X3 per axis
  float tref, tmin, tmax;
};

class ParameterList {
 public:
  float Real(const std::string& name, double value) {
    parameters_.push_back({name, FloatText(value, name), kTypeReal32});
    return ReadFloat(parameters_.back().text);
  }
  void Integer(const std::string& name, int32_t value) {
    parameters_.push_back({name, std::to_string(value), kTypeInt32});
  }
  const std::vector<Parameter>& parameters() const { return parameters_; }

 private:
  std::vector<Parameter> parameters_;
};

// TC_<prefix>_*: the bias cubic V(T) / raw_per_si about TREF = the calibration's reference.
Px4Thermal AddThermal(const Calibration& calibration, const std::string& prefix, const double* params,
                      double raw_per_si, int32_t device_id, ParameterList* list) {
  Px4Thermal thermal;
  const double reference = calibration.model.basis.center_c;
  list->Integer(prefix + "_ID", device_id);
  for (int k = kPolynomialTerms - 1; k >= 0; --k) {
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector4d c =
          Rebased(Cubic(params, kBiasCoefficient + axis), reference, reference) / raw_per_si;
      thermal.x[k][axis] = list->Real(prefix + "_X" + std::to_string(k) + "_" + std::to_string(axis), c(k));
    }
  }
  thermal.tref = list->Real(prefix + "_TREF", reference);
  thermal.tmin = list->Real(prefix + "_TMIN", calibration.fit_temp_range_c[0]);
  thermal.tmax = list->Real(prefix + "_TMAX", calibration.fit_temp_range_c[1]);
  return thermal;
}

// calc_thermal_offsets_3D, in float.
void Offsets(const Px4Thermal& thermal, float temp_c, float offset[3]) {
  float dt;
  if (temp_c > thermal.tmax) {
    dt = thermal.tmax - thermal.tref;
  } else if (temp_c < thermal.tmin) {
    dt = thermal.tmin - thermal.tref;
  } else {
    dt = temp_c - thermal.tref;
  }
  const float dt2 = dt * dt, dt3 = dt2 * dt;
  for (int axis = 0; axis < 3; ++axis) {
    offset[axis] =
        thermal.x[0][axis] + thermal.x[1][axis] * dt + thermal.x[2][axis] * dt2 + thermal.x[3][axis] * dt3;
  }
}

std::string ParamsText(const std::vector<std::string>& provenance, const ParameterList& list) {
  std::string out = "# Onboard parameters for Vehicle 1\n#\n" + Commented(provenance, "# ") +
                    "#\n# Vehicle-Id Component-Id Name Value Type\n";
  for (const Parameter& p : list.parameters()) {
    out += "1\t1\t" + p.name + "\t" + p.text + "\t" + std::to_string(p.type) + "\n";
  }
  return out;
}

// The scale PX4 v1.12's set_scale() holds after boot: the written one, or 1 when it lies within
// 0.01 (Euclidean norm) of 1.
// 0.01 (Euclidean norm) of 1: matrix::Vector::longerThan, in float, x + y + z in that order.
Eigen::Vector3f SetScaleAfterBoot(const float written[3]) {
  float norm_squared = 0.0f;
  for (int axis = 0; axis < 3; ++axis) norm_squared += (1.0f - written[axis]) * (1.0f - written[axis]);
  if (norm_squared > kSetScaleThreshold * kSetScaleThreshold)
    return Eigen::Vector3f(written[0], written[1], written[2]);
  return Eigen::Vector3f::Ones();
}

}  // namespace

ExportResult ExportPx4(const Calibration& calibration, const ExportOptions& options,
                       const Envelope& envelope) {
  const SensorIds ids = DeviceIds(options, "px4");
  const std::string n = std::to_string(InstanceOf(options, 0, 3, 0, "px4"));
  const double k_gyro = options.gyro_raw_per_radps, k_accel = options.accel_raw_per_mps2;
  ParameterList list;
  list.Integer("TC_G_ENABLE", 1);
  list.Integer("TC_A_ENABLE", 1);
  const Px4Thermal gyro =
      AddThermal(calibration, "TC_G" + n, calibration.model.gyro.data(), k_gyro, ids.gyro, &list);
  const Px4Thermal accel =
      AddThermal(calibration, "TC_A" + n, calibration.model.accel.data(), k_accel, ids.accel, &list);
  list.Integer("CAL_GYRO" + n + "_ID", ids.gyro);
  list.Integer("CAL_ACC" + n + "_ID", ids.accel);
  float scale[3];
  const SensorCoefficients<double> at_reference =
      AccelAt(calibration.model, calibration.model.basis.center_c);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string xyz(1, "XYZ"[axis]);
    list.Real("CAL_GYRO" + n + "_" + xyz + "OFF", 0.0);
    list.Real("CAL_ACC" + n + "_" + xyz + "OFF", 0.0);
    scale[axis] = list.Real("CAL_ACC" + n + "_" + xyz + "SCALE", k_accel / at_reference.scale(axis));
  }
  const Eigen::Vector3f set_scale = SetScaleAfterBoot(scale);

  const auto consumer = [=](const Eigen::Vector3f& accel_scale) -> ConsumerCorrection {
    return [=](double temp_c, const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw,
               Eigen::Vector3d* omega_radps, Eigen::Vector3d* a_mps2) {
      float gyro_offset[3], accel_offset[3];
      Offsets(gyro, static_cast<float>(temp_c), gyro_offset);
      Offsets(accel, static_cast<float>(temp_c), accel_offset);
      for (int axis = 0; axis < 3; ++axis) {
        const float d_gyro = static_cast<float>(gyro_raw(axis) / k_gyro);
        const float d_accel = static_cast<float>(accel_raw(axis) / k_accel);
        (*omega_radps)(axis) = d_gyro - gyro_offset[axis] - 0.0f;
        (*a_mps2)(axis) = (d_accel - accel_offset[axis] - 0.0f) * accel_scale(axis);
      }
    };
  };
  ExportResult result = MeasuredResult(kConsumer, calibration, envelope,
                                       consumer(Eigen::Vector3f(scale[0], scale[1], scale[2])));
  const ExportLoss through_set_scale = MeasureLoss(calibration.model, envelope, consumer(set_scale));
  std::vector<std::string> notes = {
      "loss with CAL_ACC" + n + "_xSCALE applied as written: " + WorstFigures(result.loss),
      "loss with PX4 v1.12's set_scale() (" +
          std::string(set_scale == Eigen::Vector3f::Ones() && scale[0] != 1.0f
                          ? "which ignores this scale: within 0.01 of 1, it keeps 1"
                          : "which applies this scale") +
          "): " + WorstFigures(through_set_scale)};
  result.loss = WorstOf(result.loss, through_set_scale);
  std::vector<std::string> provenance = ProvenanceLines(calibration, options, result);
  provenance.insert(provenance.end(), notes.begin(), notes.end());
  provenance.push_back(
      "TC_G_ENABLE and TC_A_ENABLE take effect only after a reboot: load this file, then reboot");
  provenance.push_back("the vehicle; TC_G" + n + "_ID/CAL_GYRO" + n + "_ID and TC_A" + n + "_ID/CAL_ACC" + n +
                       "_ID must be the device IDs PX4 reports for the gyro and the accelerometer.");
  result.content = ParamsText(provenance, list);
  return result;
}

}  // namespace imufit::export_internal
