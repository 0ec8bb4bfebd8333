// Corrects one sample with imufit's shared model, as a consumer of the installed package would.
// Exit status 0 when the correction gives back the truth the sample was made from.
#include <cmath>
#include <cstdio>

#include <imufit/model/sensor_model.h>

int main() {
  // A unit in counts: 16.4 LSB per deg/s and 2048 LSB per g, a bias, a misalignment, a
  // g-sensitivity, and a bias that drifts by 0.1 count per degC.
  imufit::SensorModel model = imufit::SensorModel::Identity();
  constexpr double kPi = 3.14159265358979323846;
  for (int axis = 0; axis < 3; ++axis) {
    model.gyro[(imufit::kScaleCoefficient + axis) * imufit::kPolynomialTerms] = 16.4 * 180.0 / kPi;
    model.accel[(imufit::kScaleCoefficient + axis) * imufit::kPolynomialTerms] = 2048.0 / 9.80665;
    model.gyro[(imufit::kBiasCoefficient + axis) * imufit::kPolynomialTerms] = 20.0 + axis;
    model.gyro[(imufit::kBiasCoefficient + axis) * imufit::kPolynomialTerms + 1] = 0.1;
  }
  model.gyro[imufit::kMisalignmentCoefficient * imufit::kPolynomialTerms] = 0.003;          // xy
  model.accel[(imufit::kMisalignmentCoefficient + 4) * imufit::kPolynomialTerms] = -0.002;  // zx
  model.gyro[imufit::kGSensitivityCoefficient * imufit::kPolynomialTerms] = 0.05;           // xx

  const double temp_c = 40.0;
  const Eigen::Vector3d omega_true_radps(0.1, -0.2, 5.0);
  const Eigen::Vector3d a_true_mps2(0.3, -0.1, 9.81);
  Eigen::Vector3d gyro_m;
  Eigen::Vector3d accel_m;
  model.Forward(temp_c, omega_true_radps, a_true_mps2, &gyro_m, &accel_m);
  Eigen::Vector3d omega_hat_radps;
  Eigen::Vector3d a_hat_mps2;
  model.Correct(temp_c, gyro_m, accel_m, &omega_hat_radps, &a_hat_mps2);

  const double error = std::max((omega_hat_radps - omega_true_radps).cwiseAbs().maxCoeff(),
                                (a_hat_mps2 - a_true_mps2).cwiseAbs().maxCoeff());
  std::printf("raw gyro [%.3f %.3f %.3f] -> omega_hat [%.9f %.9f %.9f] rad/s (error %.1e)\n", gyro_m.x(),
              gyro_m.y(), gyro_m.z(), omega_hat_radps.x(), omega_hat_radps.y(), omega_hat_radps.z(), error);
  return error < 1e-12 ? 0 : 1;
}
