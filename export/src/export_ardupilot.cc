// --format ardupilot: ArduPilot's IMU temperature calibration (INS_TCAL1_*) with the offsets and
// accelerometer scale it is applied with, as a .parm file (NAME VALUE lines, # comments).
//
// What ArduPilot does with them (libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp and
// AP_InertialSensor_Backend.cpp's _rotate_and_correct_*), in float32, with d the driver's output
// in rad/s or m/s^2, T the sensor's temperature and T_cal = INS_ACC1_CALTEMP / INS_GYR1_CALTEMP:
//
//   p(t)   = (C1 + (C2 + C3 t) t) t * 1e-6,   t = clamp(T, TMIN, TMAX) - 35   (no constant term)
//   v      = d - p(T) + p(clamp(T_cal, TMIN, TMAX))
//   accel  = (v - INS_ACCOFFS) * INS_ACCSCAL
//   gyro   = v - INS_GYROFFS
//
// ArduPilot's reference is fixed at 35 degC and its coefficients are stored x1e6. With d = raw / k
// imufit's bias V(T) / k is re-expanded exactly in powers of T - 35: d0 + d1 t + d2 t^2 + d3 t^3;
// C_k = d_k 1e6 and the constant goes through the offsets at the calibration temperature:
// INS_*OFFS = d0 + p(T_cal - 35) (T_cal = 35 degC clamped to the fitted range). The
// accelerometer's scale k / S(T) is held at T_cal; the gyro scale, misalignments and
// g-sensitivity have no parameter and are the loss.
//
// Instances n = 1..3 (--instance): INS_TCALn_*, and the offsets of the n-th sensor, whose names
// differ (INS_ACCOFFS, INS_ACC2OFFS, INS_ACC3OFFS; INS_ACC_ID, INS_ACC2_ID; INS_ACC1_CALTEMP,
// INS_ACC2_CALTEMP). INS_ACC_ID and INS_GYR_ID are the device IDs: ArduPilot accepts the
// instance's offsets as a 3D accelerometer calibration only when the saved ID is the sensor's
// (AP_InertialSensor::register_accel, accel_calibrated_ok_all). INS_TCALn_TMIN/TMAX lie in the
// parameters' range -70..80 degC (their metadata, which ground stations enforce): a fitted range
// beyond it is clamped, and ArduPilot then holds the correction at the end of the range; the loss
// is measured over the envelope with that clamping. The INS_TCALn_* parameters other than
// ENABLE exist only once INS_TCALn_ENABLE is 1 (AP_PARAM_FLAG_ENABLE): the file says to load it
// twice.
#include <algorithm>
#include <cmath>

#include "export_internal.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer =
    "ArduPilot (4.1 and later: INS_TCAL1 about its fixed 35 degC, INS_ACCOFFS/ACCSCAL/GYROFFS; .parm)";
constexpr double kArduPilotReferenceC = 35.0;  // TEMP_REFERENCE
constexpr double kScaleFactor = 1e6;           // SCALE_FACTOR of the stored coefficients
constexpr double kTempParameterLowC = -70.0;   // INS_TCALn_TMIN/TMAX @Range
constexpr double kTempParameterHighC = 80.0;

// The names of instance n's parameters: INS_TCAL<n>_, and the sensor's own, whose first instance
// has no number (INS_ACCOFFS) or 1 (INS_ACC1_CALTEMP).
struct InstanceNames {
  std::string tcal;    // "INS_TCAL2_"
  std::string accel;   // "INS_ACC2" (OFFS, SCAL, _ID)
  std::string gyro;    // "INS_GYR2" (OFFS, _ID)
  std::string number;  // "2" (INS_ACC2_CALTEMP)
};
InstanceNames NamesOf(int instance) {
  const std::string n = std::to_string(instance), suffix = instance == 1 ? "" : n;
  return {"INS_TCAL" + n + "_", "INS_ACC" + suffix, "INS_GYR" + suffix, n};
}

// One sensor's parameters, as ArduPilot reads them back (float32).
struct TcalSensor {
  float coefficient[3][3];  // [order 1..3][axis], x1e6
  float offset[3];
  float scale[3] = {1.0f, 1.0f, 1.0f};
  float cal_temp;
};

class ParameterList {
 public:
  float Add(const std::string& name, double value) {
    lines_ += name + " " + FloatText(value, name) + "\n";
    return ReadFloat(FloatText(value, name));
  }
  void Integer(const std::string& name, int32_t value) {
    lines_ += name + " " + std::to_string(value) + "\n";
  }
  const std::string& text() const { return lines_; }

 private:
  std::string lines_;
};

// polynomial_eval in float: (c1 + (c2 + c3 t) t) t * 1e-6.
float Polynomial(const TcalSensor& sensor, int axis, float t) {
  return (sensor.coefficient[0][axis] + (sensor.coefficient[1][axis] + sensor.coefficient[2][axis] * t) * t) *
         t * static_cast<float>(1.0 / kScaleFactor);
}

// The bias cubic of a sensor re-expanded about 35 degC (in SI), its offsets at T_cal, and for the
// accelerometer the scale at T_cal.
TcalSensor AddSensor(const Calibration& calibration, const InstanceNames& names, const std::string& name,
                     const double* params, double raw_per_si, bool accel, double cal_temp_c,
                     ParameterList* tcal, ParameterList* offsets) {
  TcalSensor sensor;
  Eigen::Vector4d d[3];
  for (int axis = 0; axis < 3; ++axis) {
    d[axis] = Rebased(Cubic(params, kBiasCoefficient + axis), calibration.model.basis.center_c,
                      kArduPilotReferenceC) /
              raw_per_si;
  }
  for (int order = 1; order <= 3; ++order) {
    for (int axis = 0; axis < 3; ++axis) {
      sensor.coefficient[order - 1][axis] = tcal->Add(
          names.tcal + name + std::to_string(order) + "_" + "XYZ"[axis], d[axis](order) * kScaleFactor);
    }
  }
  const double t_cal = cal_temp_c - kArduPilotReferenceC;
  const SensorCoefficients<double> at_cal = AccelAt(calibration.model, cal_temp_c);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string xyz(1, "XYZ"[axis]);
    const double offset = EvaluateTemperaturePolynomial(d[axis].data(), t_cal);
    sensor.offset[axis] = offsets->Add((accel ? names.accel : names.gyro) + "OFFS_" + xyz, offset);
    if (accel)
      sensor.scale[axis] = offsets->Add(names.accel + "SCAL_" + xyz, raw_per_si / at_cal.scale(axis));
  }
  sensor.cal_temp = offsets->Add((accel ? "INS_ACC" : "INS_GYR") + names.number + "_CALTEMP", cal_temp_c);
  return sensor;
}

}  // namespace

ExportResult ExportArduPilot(const Calibration& calibration, const ExportOptions& options,
                             const Envelope& envelope) {
  const SensorIds ids = DeviceIds(options, "ardupilot");
  const InstanceNames names = NamesOf(InstanceOf(options, 1, 3, 1, "ardupilot"));
  const double cal_temp_c = ClampToRange(calibration, kArduPilotReferenceC);
  const double tmin_c = std::clamp(calibration.fit_temp_range_c[0], kTempParameterLowC, kTempParameterHighC);
  const double tmax_c = std::clamp(calibration.fit_temp_range_c[1], kTempParameterLowC, kTempParameterHighC);
  ParameterList tcal, offsets;
  tcal.Add(names.tcal + "ENABLE", 1.0);
  const float tmin = tcal.Add(names.tcal + "TMIN", tmin_c);
  const float tmax = tcal.Add(names.tcal + "TMAX", tmax_c);
  offsets.Integer(names.accel + "_ID", ids.accel);
  offsets.Integer(names.gyro + "_ID", ids.gyro);
  const TcalSensor accel = AddSensor(calibration, names, "ACC", calibration.model.accel.data(),
                                     options.accel_raw_per_mps2, true, cal_temp_c, &tcal, &offsets);
  const TcalSensor gyro = AddSensor(calibration, names, "GYR", calibration.model.gyro.data(),
                                    options.gyro_raw_per_radps, false, cal_temp_c, &tcal, &offsets);

  const double k_gyro = options.gyro_raw_per_radps, k_accel = options.accel_raw_per_mps2;
  const ConsumerCorrection consumer = [=](double temp_c, const Eigen::Vector3d& gyro_raw,
                                          const Eigen::Vector3d& accel_raw, Eigen::Vector3d* omega_radps,
                                          Eigen::Vector3d* a_mps2) {
    const float t = std::clamp(static_cast<float>(temp_c), tmin, tmax);
    const auto correct = [&](const TcalSensor& sensor, int axis, float d) {
      const float t_cal = std::clamp(sensor.cal_temp, tmin, tmax);
      d -= Polynomial(sensor, axis, static_cast<float>(t - kArduPilotReferenceC));
      d += Polynomial(sensor, axis, static_cast<float>(t_cal - kArduPilotReferenceC));
      return (d - sensor.offset[axis]) * sensor.scale[axis];
    };
    for (int axis = 0; axis < 3; ++axis) {
      (*a_mps2)(axis) = correct(accel, axis, static_cast<float>(accel_raw(axis) / k_accel));
      (*omega_radps)(axis) = correct(gyro, axis, static_cast<float>(gyro_raw(axis) / k_gyro));
    }
  };
  ExportResult result = MeasuredResult(kConsumer, calibration, envelope, consumer);
  std::vector<std::string> notes = ProvenanceLines(calibration, options, result);
  std::vector<std::string> warnings;
  if (tmin_c != calibration.fit_temp_range_c[0] || tmax_c != calibration.fit_temp_range_c[1]) {
    warnings.push_back("the fitted range [" + FormatDouble(calibration.fit_temp_range_c[0]) + ", " +
                       FormatDouble(calibration.fit_temp_range_c[1]) + "] degC lies beyond " + names.tcal +
                       "TMIN/TMAX's range [-70, 80] degC: written as [" + FormatDouble(tmin_c) + ", " +
                       FormatDouble(tmax_c) +
                       "]; ArduPilot holds the correction at the end beyond it (in the loss)");
  }
  // accel_calibrated_ok_all() takes offsets that are all exactly 0 for "never calibrated" (and
  // refuses to arm: "3D Accel calibration needed"); loading them also replaces the vehicle's own.
  if (accel.offset[0] == 0.0f && accel.offset[1] == 0.0f && accel.offset[2] == 0.0f) {
    warnings.push_back(names.accel +
                       "OFFS_X/Y/Z are all exactly 0: ArduPilot reads that as an accelerometer "
                       "never calibrated and refuses to arm (\"3D Accel calibration needed\"); was the "
                       "accelerometer's bias held rather than fitted?");
  }
  for (const std::string& warning : warnings) notes.push_back("warning: " + warning);
  result.warnings = std::move(warnings);
  notes.push_back(names.tcal + "ENABLE must be 1 before the other " + names.tcal +
                  "* parameters exist: load this file, refresh the parameters, and load it again.");
  notes.push_back(names.accel + "_ID and " + names.gyro +
                  "_ID must be the IDs ArduPilot reports for the sensors; reboot after loading.");
  notes.push_back("ArduPilot re-measures the gyro offsets at every boot unless INS_GYR_CAL is 0.");
  result.content = Commented(notes, "# ") + tcal.text() + offsets.text();
  return result;
}

}  // namespace imufit::export_internal
