// --format kalibr: Kalibr's imu.yaml: the noise densities of the calibration's noise block and
// the intrinsics of Kalibr's scale-misalignment IMU model at one temperature.
//
// Kalibr's model (ethz-asl/kalibr, kalibr_imu_camera_calibration/IccSensors.py,
// IccScaledMisalignedImu), with d the driver's output in m/s^2 and rad/s, a_i and w_i the true
// specific force and rate in Kalibr's IMU frame i, and b the biases its estimator tracks:
//
//   d_accel = M_a a_i + b_a                                      (M_a lower triangular)
//   d_gyro  = M_g C_gyro_i w_i + A C_gyro_i a_i + b_g            (M_g lower triangular, C_gyro_i a rotation)
//
// imufit's model at the temperature T0, with d = raw / k and body-frame truth a_b, w_b, is
// d_accel = G_a a_b + V_a / k_a with G_a = diag(S_a / k_a) M_a^-1, and likewise for the gyro with
// H / k_g a_b added. Kalibr's IMU frame is the frame in which the accelerometer's matrix is lower
// triangular: G_a = L_a C_i_b (LQ decomposition), so M_a = L_a and frame i = C_i_b * body; then
// G_g C_i_b^T = M_g C_gyro_i (LQ again) and A = (H / k_g) C_i_b^T C_gyro_i^T. At T0 this holds the
// whole model; what is lost is the temperature dependence. C_i_b (a few mrad from identity) is
// written as a comment; the loss is measured in imufit's body frame by rotating Kalibr's output
// back with it. Kalibr's estimator tracks the biases online: the file gives the biases at T0 as
// `b`, a starting value (Kalibr ignores keys it does not use), and the loss assumes the consumer
// uses them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include <Eigen/Dense>

#include "export_internal.h"
#include "imufit/io/error.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/output_file.h"
#include "imufit/model/check.h"

namespace imufit::export_internal {
namespace {

constexpr const char* kConsumer = "Kalibr (ethz-asl/kalibr imu.yaml with the scale-misalignment IMU model)";

// G = L Q: L lower triangular with a positive diagonal, Q a rotation (det +1 when det G > 0).
void LowerTimesRotation(const Eigen::Matrix3d& g, Eigen::Matrix3d* lower, Eigen::Matrix3d* rotation) {
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr(g.transpose());
  Eigen::Matrix3d q = qr.householderQ();
  Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  for (int i = 0; i < 3; ++i) {  // G^T = Q R = (Q D)(D R) with D = diag(+-1): make diag(R) positive
    if (r(i, i) < 0.0) {
      r.row(i) *= -1.0;
      q.col(i) *= -1.0;
    }
  }
  *lower = r.transpose();
  lower->triangularView<Eigen::StrictlyUpper>().setZero();  // +0, not the -0 of a flipped sign
  *rotation = q.transpose();
}

// The noise block's Kalibr figure, required and positive (Kalibr refuses a density that is not).
double NoiseFigure(const KalibrNoiseRecord& figures, double KalibrNoiseRecord::*figure, const char* key) {
  const double value = figures.*figure;
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw ExportError(
        std::string("Kalibr needs noise.kalibr.") + key +
        " > 0 in the calibration (append the noise block of `imufit allan --noise-yaml`, or give it with "
        "`imufit export --noise`)");
  }
  return value;
}

// Kalibr's intrinsics as written and read back.
struct KalibrImu {
  Eigen::Matrix3d m_accel, m_gyro, a_gyro, c_gyro_i, c_i_b;
  Eigen::Vector3d b_accel, b_gyro;
};

}  // namespace

ExportResult ExportKalibr(const Calibration& calibration, const ExportOptions& options,
                          const Envelope& envelope) {
  const double t0 = ClampToRange(calibration, options.temp_c.value_or(calibration.model.basis.center_c));
  const double k_gyro = options.gyro_raw_per_radps, k_accel = options.accel_raw_per_mps2;
  const SensorCoefficients<double> accel = AccelAt(calibration.model, t0),
                                   gyro = GyroAt(calibration.model, t0);
  const Eigen::Matrix3d g_accel = (accel.scale / k_accel).asDiagonal() * accel.misalignment.inverse();
  const Eigen::Matrix3d g_gyro = (gyro.scale / k_gyro).asDiagonal() * gyro.misalignment.inverse();
  IMUFIT_CHECK(g_accel.determinant() > 0.0 && g_gyro.determinant() > 0.0,
               "ReadCalibration refuses negative scale factors and a nearly singular M");
  Eigen::Matrix3d m_accel, c_i_b, m_gyro, c_gyro_i;
  LowerTimesRotation(g_accel, &m_accel, &c_i_b);
  LowerTimesRotation(g_gyro * c_i_b.transpose(), &m_gyro, &c_gyro_i);
  const Eigen::Matrix3d a_gyro = gyro.g_sensitivity / k_gyro * c_i_b.transpose() * c_gyro_i.transpose();

  // Kalibr's keys in its order, read one by one: a missing figure is named in that order too.
  const KalibrNoiseRecord figures =
      calibration.noise ? KalibrNoiseOf(*calibration.noise) : KalibrNoiseRecord();
  MachineDoc doc = MachineDoc::Map();
  // Each figure says where it comes from (the noise block's figure to quote, docs/allan.md).
  for (const auto& [key, figure, unit, from] :
       {std::tuple{"accelerometer_noise_density", &KalibrNoiseRecord::accelerometer_noise_density,
                   "m/s^2/sqrt(Hz)", &KalibrNoiseRecord::accelerometer_noise_density_from},
        {"accelerometer_random_walk", &KalibrNoiseRecord::accelerometer_random_walk, "m/s^3/sqrt(Hz)",
         &KalibrNoiseRecord::accelerometer_random_walk_from},
        {"gyroscope_noise_density", &KalibrNoiseRecord::gyroscope_noise_density, "rad/s/sqrt(Hz)",
         &KalibrNoiseRecord::gyroscope_noise_density_from},
        {"gyroscope_random_walk", &KalibrNoiseRecord::gyroscope_random_walk, "rad/s^2/sqrt(Hz)",
         &KalibrNoiseRecord::gyroscope_random_walk_from}}) {
    const std::string& source = figures.*from;
    doc.Add(key, NumberDoc(NoiseFigure(figures, figure, key), key),
            source.empty() ? std::string(unit) : std::string(unit) + "; " + source);
  }
  doc.Add("rostopic", MachineDoc::Text(options.rostopic));
  doc.Add("update_rate",
          NumberDoc(NoiseFigure(figures, &KalibrNoiseRecord::update_rate, "update_rate"), "update_rate"),
          "Hz");
  KalibrImu imu;
  doc.Add("model", MachineDoc::Text("scale-misalignment"));
  MachineDoc accelerometers = MachineDoc::Map();
  accelerometers.Add("M", MatrixDoc(m_accel, "M_accel", MachineDoc::Style::kFlow, &imu.m_accel));
  accelerometers.Add("b", VectorDoc(accel.bias / k_accel, "b_accel", &imu.b_accel),
                     "m/s^2 at the export temperature");
  doc.Add("accelerometers", std::move(accelerometers));
  MachineDoc gyroscopes = MachineDoc::Map();
  gyroscopes.Add("M", MatrixDoc(m_gyro, "M_gyro", MachineDoc::Style::kFlow, &imu.m_gyro));
  gyroscopes.Add("A", MatrixDoc(a_gyro, "A", MachineDoc::Style::kFlow, &imu.a_gyro), "(rad/s)/(m/s^2)");
  gyroscopes.Add("C_gyro_i", MatrixDoc(c_gyro_i, "C_gyro_i", MachineDoc::Style::kFlow, &imu.c_gyro_i));
  gyroscopes.Add("b", VectorDoc(gyro.bias / k_gyro, "b_gyro", &imu.b_gyro),
                 "rad/s at the export temperature");
  doc.Add("gyroscopes", std::move(gyroscopes));
  Eigen::Matrix3d c_i_b_read;
  const std::string frame = MatrixText(c_i_b, "C_i_b", "", &c_i_b_read);
  imu.c_i_b = c_i_b_read;

  const ConsumerCorrection consumer =
      [imu, k_gyro, k_accel](double, const Eigen::Vector3d& gyro_raw, const Eigen::Vector3d& accel_raw,
                             Eigen::Vector3d* omega_radps, Eigen::Vector3d* a_mps2) {
        const Eigen::Vector3d a_i = imu.m_accel.lu().solve(accel_raw / k_accel - imu.b_accel);
        const Eigen::Vector3d w_gyro =
            imu.m_gyro.lu().solve(gyro_raw / k_gyro - imu.b_gyro - imu.a_gyro * (imu.c_gyro_i * a_i));
        *a_mps2 = imu.c_i_b.transpose() * a_i;
        *omega_radps = imu.c_i_b.transpose() * (imu.c_gyro_i.transpose() * w_gyro);
      };
  ExportResult result = MeasuredResult(kConsumer, calibration, envelope, consumer);
  std::vector<std::string> header = ProvenanceLines(calibration, options, result);
  // Figures imufit measured (they name their source) or inflated: the factor and the advice said.
  if (figures.inflation != 1.0 || !figures.gyroscope_noise_density_from.empty()) {
    header.push_back("noise figures x " + FormatDouble(figures.inflation) +
                     (figures.inflation == 1.0 ? " (as measured on a static log)" : "") +
                     "; advised before use in motion: " + kAdvisedVioInflation);
  }
  const double angle_mrad = std::acos(std::clamp((c_i_b.trace() - 1.0) / 2.0, -1.0, 1.0)) * 1e3;
  char text[200];
  std::snprintf(text, sizeof text,
                "intrinsics at %s degC; Kalibr's IMU frame i = C_i_b * imufit's body frame (%.3g mrad):",
                FormatDouble(t0).c_str(), angle_mrad);
  header.push_back(text);
  header.push_back("C_i_b: " + frame);
  doc.CommentFirst(header);
  result.content = YamlText(doc);
  return result;
}

}  // namespace imufit::export_internal
