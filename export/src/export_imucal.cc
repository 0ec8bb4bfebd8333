// --format imucal: imucal's Ferraris calibration JSON (mad-lab-fau/imucal, format 2.0.0) at one
// temperature.
//
// imucal's equations (imucal/ferraris_calibration_info.py), in double (numpy), on the raw output:
//
//   acc = R_a^-1 K_a^-1 (raw_acc - b_a)                       [m/s^2]
//   gyr = R_g^-1 K_g^-1 (raw_gyr - K_ga acc - b_g)            [deg/s]
//
// K diagonal (scale), R a matrix of unit rows (the axes' directions), b a bias, K_ga the gyro's
// acceleration sensitivity. imufit's model at T0 is the same with K R = diag(S) M^-1 (the gyro's
// in raw per deg/s): K_ii = the norm of row i of diag(S) M^-1, R = K^-1 diag(S) M^-1, b = V,
// K_ga = H. So imucal holds the whole model at T0; what is lost is the temperature dependence.
#include <cmath>

#include <Eigen/Dense>

#include "export_internal.h"
#include "imufit/io/output_file.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer = "imucal (mad-lab-fau/imucal FerrarisCalibrationInfo, JSON format 2.0.0)";
constexpr double kDegPerRad = kRadToDeg;

// K (diagonal) and R (unit rows) with K R = forward.
void ScaleAndRotation(const Eigen::Matrix3d& forward, Eigen::Matrix3d* k, Eigen::Matrix3d* r) {
  const Eigen::Vector3d norms = forward.rowwise().norm();
  *k = norms.asDiagonal();
  *r = norms.cwiseInverse().asDiagonal() * forward;
}

struct Ferraris {
  Eigen::Matrix3d k_a, r_a, k_g, r_g, k_ga;
  Eigen::Vector3d b_a, b_g;
};

}  // namespace

ExportResult ExportImucal(const Calibration& calibration, const ExportOptions& options,
                          const Envelope& envelope) {
  const double t0 = ClampToRange(calibration, options.temp_c.value_or(calibration.model.basis.center_c));
  const SensorCoefficients<double> accel = AccelAt(calibration.model, t0),
                                   gyro = GyroAt(calibration.model, t0);
  Eigen::Matrix3d k_a, r_a, k_g, r_g;
  ScaleAndRotation(accel.scale.asDiagonal() * accel.misalignment.inverse(), &k_a, &r_a);
  ScaleAndRotation((gyro.scale / kDegPerRad).asDiagonal() * gyro.misalignment.inverse(), &k_g, &r_g);

  Ferraris f;
  MachineDoc doc = MachineDoc::Map();
  doc.Add("acc_unit", MachineDoc::Text("m/s^2")).Add("gyr_unit", MachineDoc::Text("deg/s"));
  doc.Add("from_acc_unit", MachineDoc::Text("a.u.")).Add("from_gyr_unit", MachineDoc::Text("a.u."));
  const auto matrix = [](const Eigen::Matrix3d& m, const char* name, Eigen::Matrix3d* read_back) {
    return MatrixDoc(m, name, MachineDoc::Style::kBlock, read_back);
  };
  MachineDoc coefficients = MachineDoc::Map();
  coefficients.Add("K_a", matrix(k_a, "K_a", &f.k_a)).Add("R_a", matrix(r_a, "R_a", &f.r_a));
  coefficients.Add("b_a", VectorDoc(accel.bias, "b_a", &f.b_a));
  coefficients.Add("K_g", matrix(k_g, "K_g", &f.k_g)).Add("R_g", matrix(r_g, "R_g", &f.r_g));
  coefficients.Add("K_ga", matrix(gyro.g_sensitivity, "K_ga", &f.k_ga));
  coefficients.Add("b_g", VectorDoc(gyro.bias, "b_g", &f.b_g));

  const ConsumerCorrection consumer = [f](double, const Eigen::Vector3d& gyro_raw,
                                          const Eigen::Vector3d& accel_raw, Eigen::Vector3d* omega_radps,
                                          Eigen::Vector3d* a_mps2) {
    const Eigen::Matrix3d acc_mat = f.r_a.inverse() * f.k_a.inverse();
    const Eigen::Matrix3d gyro_mat = f.r_g.inverse() * f.k_g.inverse();
    *a_mps2 = acc_mat * (accel_raw - f.b_a);
    *omega_radps = gyro_mat * (gyro_raw - (f.k_ga * *a_mps2 + f.b_g)) / kDegPerRad;
  };
  ExportResult result = MeasuredResult(kConsumer, calibration, envelope, consumer);
  const std::string comment = Commented(ProvenanceLines(calibration, options, result), "") + "taken at " +
                              FormatDouble(t0) + " degC; raw inputs in the unit's own numbers (a.u.)";
  doc.Add("comment", MachineDoc::Text(comment));
  for (size_t i = 0; i < coefficients.items().size(); ++i) {
    doc.Add(coefficients.keys()[i].name, coefficients.items()[i]);
  }
  doc.Add("cal_type", MachineDoc::Text("Ferraris")).Add("_format_version", MachineDoc::Text("2.0.0"));
  result.content = JsonText(doc);
  return result;
}

}  // namespace imufit::export_internal
