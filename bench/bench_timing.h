// imufit benchmarks: the timing they share.
#ifndef IMUFIT_BENCH_BENCH_TIMING_H_
#define IMUFIT_BENCH_BENCH_TIMING_H_

#include <algorithm>
#include <chrono>
#include <functional>

namespace imufit::bench {

// Best of `runs` wall-clock times of `f`, s.
inline double BestSeconds(int runs, const std::function<void()>& f) {
  double best = 1e300;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace imufit::bench

#endif  // IMUFIT_BENCH_BENCH_TIMING_H_
