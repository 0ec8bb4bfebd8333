// imufit — benchmark of the Allan deviation: oadev at octave taus over 1e7 and 1e8
// samples, in memory (1e8 doubles = 800 MB).
//
// Prints, per size: one plain streaming pass over the array (a sum of squares, one core: the
// memory-bandwidth yardstick), the integration of the rates into the phase, the deviations alone
// (the sweep), and the full computation with noise identification and confidence intervals; each
// with its ratio to the plain pass. Target: 1e8 samples in under 2 s on the 2-core machine
// (allantools takes about 24 s and 3 GiB there). Figures are measured, never asserted.
//
// Usage: allan_bench [N ...]   (default 1e7 1e8); --threads T (default 0 = all cores).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "imufit/noise/allan.h"

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// White noise with a slow random walk, from a 64-bit xorshift generator (fixed seed): the values
// do not matter for the timing, only that they are not trivially compressible.
std::vector<double> MakeRates(int64_t n) {
  std::vector<double> y;
  y.reserve(static_cast<size_t>(n) + 1);  // RatesToPhase appends X_n: no 800 MB reallocation
  y.resize(static_cast<size_t>(n));
  uint64_t state = 0x9E3779B97F4A7C15ull;
  double walk = 0.0;
  for (int64_t i = 0; i < n; ++i) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    const double uniform = static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0) - 0.5;
    walk += 1e-4 * uniform;
    y[i] = 1e-3 * uniform + walk + 0.01;
  }
  return y;
}

double PlainPass(const std::vector<double>& y) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  const size_t n = y.size();
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += y[i] * y[i];
    s1 += y[i + 1] * y[i + 1];
    s2 += y[i + 2] * y[i + 2];
    s3 += y[i + 3] * y[i + 3];
  }
  for (; i < n; ++i) s0 += y[i] * y[i];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int64_t> sizes;
  int threads = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else {
      sizes.push_back(static_cast<int64_t>(std::atof(argv[i])));
    }
  }
  if (sizes.empty()) sizes = {10000000, 100000000};
  const double tau0_s = 0.001;
  std::printf("%12s %6s %10s %10s %10s %10s %8s %8s\n", "samples", "taus", "plain_s", "phase_s", "sweep_s",
              "full_s", "sweep/pl", "full/pl");
  for (int64_t n : sizes) {
    std::vector<double> y = MakeRates(n);
    // Warm the pages, then time the plain pass (best of three).
    volatile double sink = PlainPass(y);
    double plain = 1e30;
    for (int r = 0; r < 3; ++r) {
      const auto start = std::chrono::steady_clock::now();
      sink = PlainPass(y);
      plain = std::min(plain, Seconds(start));
    }
    (void)sink;
    std::vector<int64_t> factors;
    imufit::AveragingFactors(imufit::TauSpec(), imufit::AllanEstimator::kOadev, n, tau0_s, &factors);

    auto start = std::chrono::steady_clock::now();
    imufit::RatesToPhase(&y, threads);
    const double phase = Seconds(start);

    start = std::chrono::steady_clock::now();
    const std::vector<double> devs =
        imufit::Deviations(y, tau0_s, factors, imufit::AllanEstimator::kOadev, threads);
    const double sweep = Seconds(start);

    imufit::AllanOptions options;
    options.threads = threads;
    start = std::chrono::steady_clock::now();
    const imufit::AllanResult result = imufit::ComputeAllan(y, tau0_s, factors, options);
    const double full = Seconds(start) + phase;

    std::printf("%12lld %6zu %10.3f %10.3f %10.3f %10.3f %8.1f %8.1f\n", static_cast<long long>(n),
                factors.size(), plain, phase, sweep, full, sweep / plain, full / plain);
    std::printf("%12s oadev(tau0) = %.6g, oadev(tau_max = %g s) = %.6g [%.6g, %.6g]\n", "", devs.front(),
                result.points.back().tau_s, result.points.back().dev, result.points.back().dev_lo,
                result.points.back().dev_hi);
  }
  return 0;
}
