// imufit — benchmark of the correction core that `imufit apply` runs per row: the shared
// model's SensorModel::Correct over N samples held in memory (no CSV), in the (N,) / (N, 3) layout
// of numpy arrays, so that bench/python_correct_bench.py can compare imufit.Calibration.correct
// with it. Best of three runs, one core. Figures are measured, never asserted.
//
// Side by side in the same run, the C runtime for firmware (model/c/imufit_runtime.h) on the same
// samples: its double build on the same arrays, its float build on float copies of them (what a
// firmware holds), both loaded from the calibration's blob (`imufit export --format bin`). The
// three alternate round by round, so that a machine shared with other work slows them alike.
//
// Last, what `imufit apply` does with a thermometer that repeats its reading (here 8 samples per
// reading, an 800 Hz unit whose temperature updates at 100 Hz): the coefficients evaluated once per
// reading and reused (SensorModel::CoefficientsAtTemperature + CorrectWith) against
// SensorModel::Correct on every sample of the same arrays; the checksums must be equal.
//
// Usage: correct_bench [N] [calibration.yaml]   (default 1e7, fixtures/mems_truth.yaml)
// Prints "correct_bench N seconds ns_per_sample checksum" (the C++ core: the line
// bench/python_correct_bench.py reads), then the same for c_runtime_double and c_runtime_float,
// each with its time as a fraction of the C++ core's; then per_sample_held and reused_coefficients
// (its time as a fraction of per_sample_held's).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "imufit/export/export.h"
#include "imufit/io/calibration.h"
#include "imufit_runtime.h"
#define IMUFIT_RUNTIME_FLOAT
#include "imufit_runtime.h"  // the float build: imufit_calibration_f, imufit_correct_f

namespace {

// The smaller of best_s and the wall time of one call of `correct`, seconds.
template <typename Correct>
double BestSeconds(const Correct& correct, double best_s) {
  const auto start = std::chrono::steady_clock::now();
  correct();
  return std::min(best_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

template <typename Real>
double Checksum(const std::vector<Real>& omega, const std::vector<Real>& a) {
  double checksum = 0.0;
  for (size_t i = 0; i < omega.size(); i += 9973) checksum += omega[i] + a[i];
  return checksum;
}

void Print(const char* name, long long n, double seconds, double checksum, double cpp_seconds) {
  std::printf("%s %lld %.6f %.3f %.17g", name, n, seconds, seconds / static_cast<double>(n) * 1e9, checksum);
  if (cpp_seconds > 0.0) std::printf(" %.3f", seconds / cpp_seconds);
  std::printf("\n");
}

}  // namespace

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
  const std::string blob = imufit::CalibrationBlob(calibration, "");
  const auto* blob_bytes = reinterpret_cast<const unsigned char*>(blob.data());
  imufit_calibration runtime{};
  imufit_calibration_f runtime_f{};
  if (imufit_load_blob(blob_bytes, blob.size(), &runtime) != IMUFIT_OK ||
      imufit_load_blob_f(blob_bytes, blob.size(), &runtime_f) != IMUFIT_OK) {
    std::fprintf(stderr, "correct_bench: the runtime refused the calibration's blob\n");
    return 1;
  }
  const std::vector<float> temp_f(temp_c.begin(), temp_c.end()), gyro_f(gyro.begin(), gyro.end()),
      accel_f(accel.begin(), accel.end());
  std::vector<double> omega_c(3 * n), a_c(3 * n);
  std::vector<float> omega_f(3 * n), a_f(3 * n);

  // SensorModel::Correct on every sample, at the temperatures `temps`, into `omega_out` and `a_out`.
  const auto per_sample = [&](const std::vector<double>& temps, std::vector<double>* omega_out,
                              std::vector<double>* a_out) {
    return [&, temps = &temps, omega_out, a_out] {
      Eigen::Vector3d omega_hat, a_hat;
      for (long long i = 0; i < n; ++i) {
        model.Correct((*temps)[i], Eigen::Vector3d(&gyro[3 * i]), Eigen::Vector3d(&accel[3 * i]), &omega_hat,
                      &a_hat);
        std::copy(omega_hat.data(), omega_hat.data() + 3, &(*omega_out)[3 * i]);
        std::copy(a_hat.data(), a_hat.data() + 3, &(*a_out)[3 * i]);
      }
    };
  };
  const auto cpp_core = per_sample(temp_c, &omega, &a);
  const auto c_double = [&] {
    for (long long i = 0; i < n; ++i) {
      imufit_correct(&runtime, temp_c[i], &gyro[3 * i], &accel[3 * i], &omega_c[3 * i], &a_c[3 * i]);
    }
  };
  const auto c_float = [&] {
    for (long long i = 0; i < n; ++i) {
      imufit_correct_f(&runtime_f, temp_f[i], &gyro_f[3 * i], &accel_f[3 * i], &omega_f[3 * i], &a_f[3 * i]);
    }
  };
  constexpr long long kSamplesPerReading = 8;
  std::vector<double> temp_held(n);
  for (long long i = 0; i < n; ++i) temp_held[i] = temp_c[i - i % kSamplesPerReading];
  std::vector<double> omega_h(3 * n), a_h(3 * n), omega_r(3 * n), a_r(3 * n);
  const auto per_sample_held = per_sample(temp_held, &omega_h, &a_h);
  const auto reused_coefficients = [&] {
    Eigen::Vector3d omega_hat, a_hat;
    imufit::UnitCoefficients<double> coefficients;
    for (long long i = 0; i < n; ++i) {
      if (i == 0 || temp_held[i] != temp_held[i - 1])
        coefficients = model.CoefficientsAtTemperature(temp_held[i]);
      imufit::CorrectWith(coefficients, Eigen::Vector3d(&gyro[3 * i]), Eigen::Vector3d(&accel[3 * i]),
                          &omega_hat, &a_hat);
      std::copy(omega_hat.data(), omega_hat.data() + 3, &omega_r[3 * i]);
      std::copy(a_hat.data(), a_hat.data() + 3, &a_r[3 * i]);
    }
  };

  double cpp_s = 1e300, double_s = 1e300, float_s = 1e300, held_s = 1e300, reused_s = 1e300;
  for (int run = 0; run < 3; ++run) {
    cpp_s = BestSeconds(cpp_core, cpp_s);
    double_s = BestSeconds(c_double, double_s);
    float_s = BestSeconds(c_float, float_s);
    held_s = BestSeconds(per_sample_held, held_s);
    reused_s = BestSeconds(reused_coefficients, reused_s);
  }
  Print("correct_bench", n, cpp_s, Checksum(omega, a), 0.0);
  Print("c_runtime_double", n, double_s, Checksum(omega_c, a_c), cpp_s);
  Print("c_runtime_float", n, float_s, Checksum(omega_f, a_f), cpp_s);
  Print("per_sample_held", n, held_s, Checksum(omega_h, a_h), 0.0);
  Print("reused_coefficients", n, reused_s, Checksum(omega_r, a_r), held_s);
  if (omega_r != omega_h || a_r != a_h) {
    std::fprintf(stderr, "correct_bench: reused coefficients changed the correction\n");
    return 1;
  }
  return 0;
}
