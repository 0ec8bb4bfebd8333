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
// then PX4's board rotation, which is imufit's body frame only if the sensor is mounted so.
// With d = raw / k (k the driver's raw per SI unit), imufit's model gives exactly
// offset(T) = V(T) / k, a cubic written here in powers of T - TREF with TREF the calibration's
// reference; the accelerometer's scale k / S(T) is held at TREF; the gyro scale, both
// misalignments and the g-sensitivity have no parameter, and are the loss.
#include <cmath>
#include <cstdint>

#include "export_internal.h"
#include "imufit/io/error.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer =
    "PX4 (v1.12 and later: TC_G0/TC_A0 thermal compensation, CAL_ACC0 scale; .params of QGroundControl)";
constexpr int kTypeInt32 = 6;   // MAV_PARAM_TYPE_INT32
constexpr int kTypeReal32 = 9;  // MAV_PARAM_TYPE_REAL32

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

}  // namespace

ExportResult ExportPx4(const Calibration& calibration, const ExportOptions& options,
                       const Envelope& envelope) {
  if (!options.device_id)
    throw InputError("--device-id", "a px4 export needs the sensor's device ID (TC_G0_ID)");
  if (*options.device_id < 0 || *options.device_id > 0xFFFFFFFFLL) {
    throw InputError("--device-id", std::to_string(*options.device_id) + " is not a 32-bit device ID");
  }
  // PX4 keeps the unsigned device ID in an INT32 parameter: the same 32 bits.
  const int32_t device_id = static_cast<int32_t>(static_cast<uint32_t>(*options.device_id));
  const double k_gyro = options.gyro_raw_per_radps, k_accel = options.accel_raw_per_mps2;
  ParameterList list;
  list.Integer("TC_G_ENABLE", 1);
  list.Integer("TC_A_ENABLE", 1);
  const Px4Thermal gyro =
      AddThermal(calibration, "TC_G0", calibration.model.gyro.data(), k_gyro, device_id, &list);
  const Px4Thermal accel =
      AddThermal(calibration, "TC_A0", calibration.model.accel.data(), k_accel, device_id, &list);
  list.Integer("CAL_GYRO0_ID", device_id);
  list.Integer("CAL_ACC0_ID", device_id);
  float scale[3];
  const SensorCoefficients<double> at_reference =
      AccelAt(calibration.model, calibration.model.basis.center_c);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string xyz(1, "XYZ"[axis]);
    list.Real("CAL_GYRO0_" + xyz + "OFF", 0.0);
    list.Real("CAL_ACC0_" + xyz + "OFF", 0.0);
    scale[axis] = list.Real("CAL_ACC0_" + xyz + "SCALE", k_accel / at_reference.scale(axis));
  }

  const ConsumerCorrection consumer = [=](double temp_c, const Eigen::Vector3d& gyro_raw,
                                          const Eigen::Vector3d& accel_raw, Eigen::Vector3d* omega_radps,
                                          Eigen::Vector3d* a_mps2) {
    float gyro_offset[3], accel_offset[3];
    Offsets(gyro, static_cast<float>(temp_c), gyro_offset);
    Offsets(accel, static_cast<float>(temp_c), accel_offset);
    for (int axis = 0; axis < 3; ++axis) {
      const float d_gyro = static_cast<float>(gyro_raw(axis) / k_gyro);
      const float d_accel = static_cast<float>(accel_raw(axis) / k_accel);
      (*omega_radps)(axis) = d_gyro - gyro_offset[axis] - 0.0f;
      (*a_mps2)(axis) = (d_accel - accel_offset[axis] - 0.0f) * scale[axis];
    }
  };
  ExportResult result = MeasuredResult(kConsumer, calibration, envelope, consumer);
  result.content = ParamsText(ProvenanceLines(calibration, options, result), list);
  return result;
}

}  // namespace imufit::export_internal
