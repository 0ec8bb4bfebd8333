// imufit — benchmark of the correction core that `imufit apply` runs per row: the shared
// model's SensorModel::Correct over N samples held in memory (no CSV), in the (N,) / (N, 3) layout
// of numpy arrays, so that bench/python_correct_bench.py can compare imufit.Calibration.correct
// with it. Best of three runs, one core. Figures are measured, never asserted.
//
// Usage: correct_bench [N] [calibration.yaml]   (default 1e7, fixtures/mems_truth.yaml)
// Prints one line: "correct_bench N seconds ns_per_sample checksum".
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "imufit/io/calibration.h"

int main(int argc, char** argv) {
  const long long n = argc > 1 ? std::atoll(argv[1]) : 10000000LL;
  const std::string path = argc > 2 ? argv[2] : IMUFIT_FIXTURES_DIR "/mems_truth.yaml";
  const imufit::Calibration calibration = imufit::ReadCalibration(path);
  const imufit::SensorModel& model = calibration.model;

  // Raw counts of a unit at rest and turning, temperatures across the range (values do not change
  // the work: the correction has no branches).
  std::vector<double> temp_c(n), gyro(3 * n), accel(3 * n), omega(3 * n), a(3 * n);
  for (long long i = 0; i < n; ++i) {
    temp_c[i] = -40.0 + 125.0 * static_cast<double>(i % 100000) / 100000.0;
    for (int k = 0; k < 3; ++k) {
      gyro[3 * i + k] = static_cast<double>((i * (k + 3)) % 2001) - 1000.0;
      accel[3 * i + k] = k == 2 ? 2048.0 + static_cast<double>(i % 7) : static_cast<double>(i % 11) - 5.0;
    }
  }
  double best_s = 1e300;
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    Eigen::Vector3d omega_hat, a_hat;
    for (long long i = 0; i < n; ++i) {
      model.Correct(temp_c[i], Eigen::Vector3d(&gyro[3 * i]), Eigen::Vector3d(&accel[3 * i]), &omega_hat,
                    &a_hat);
      std::copy(omega_hat.data(), omega_hat.data() + 3, &omega[3 * i]);
      std::copy(a_hat.data(), a_hat.data() + 3, &a[3 * i]);
    }
    best_s =
        std::min(best_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  double checksum = 0.0;
  for (long long i = 0; i < 3 * n; i += 9973) checksum += omega[i] + a[i];
  std::printf("correct_bench %lld %.6f %.3f %.17g\n", n, best_s, best_s / static_cast<double>(n) * 1e9,
              checksum);
  return 0;
}
