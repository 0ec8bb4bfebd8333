#include "imufit/noise/allan.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "imufit/base/enum_names.h"
#include "imufit/model/check.h"
#include "imufit/noise/statistics.h"

namespace imufit {
namespace {

// Name tables of the enums users type (model/enum_names.h).
constexpr EnumName<AllanEstimator> kEstimatorNames[] = {
    {AllanEstimator::kAdev, "adev"},    {AllanEstimator::kOadev, "oadev"}, {AllanEstimator::kMdev, "mdev"},
    {AllanEstimator::kTdev, "tdev"},    {AllanEstimator::kHdev, "hdev"},   {AllanEstimator::kOhdev, "ohdev"},
    {AllanEstimator::kTotdev, "totdev"}};

struct EdfNoiseName {
  EdfNoise value;
  const char* name;
  int alpha;
};
constexpr EdfNoiseName kEdfNoiseNames[] = {
    {EdfNoise::kIdentify, "auto", 0},  {EdfNoise::kWhitePm, "wpm", 2},
    {EdfNoise::kFlickerPm, "fpm", 1},  {EdfNoise::kWhiteFm, "wfm", 0},
    {EdfNoise::kFlickerFm, "ffm", -1}, {EdfNoise::kRandomWalkFm, "rwfm", -2}};

// Work below this many terms per thread is not worth a thread.
constexpr int64_t kMinTermsPerThread = 1 << 16;
// Terms per block of the sweep: the slices X[b + offset .. b + offset + kBlock) of all averaging
// factors of one block stay in the L2 cache while the factors are evaluated.
constexpr int64_t kBlock = 4096;
// Samples per run of the phase integration: a run is summed in double from a long double start.
constexpr int64_t kPhaseRun = 256;
// `--taus all` evaluates every factor; refuse when that would be absurdly slow.
constexpr double kMaxAllWork = 2e10;

int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware == 0 ? 1 : static_cast<int>(hardware);
}

// Runs work(w) for w = 0 .. count-1 on `count` threads (the caller's thread is one of them).
template <typename Work>
void RunParallel(int count, Work work) {
  std::vector<std::thread> pool;
  for (int w = 1; w < count; ++w) pool.emplace_back([&work, w] { work(w); });
  work(0);
  for (std::thread& thread : pool) thread.join();
}

// Plain sum in four accumulators.
double SumOf(const double* y, int64_t count) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int64_t k = 0;
  for (; k + 4 <= count; k += 4) {
    s0 += y[k];
    s1 += y[k + 1];
    s2 += y[k + 2];
    s3 += y[k + 3];
  }
  for (; k < count; ++k) s0 += y[k];
  return (s0 + s1) + (s2 + s3);
}

// The hot loops of the overlapping estimators: sum over k of (p2 - 2 p1 + p0)^2 and of
// (p3 - 3 p2 + 3 p1 - p0)^2, in eight accumulators. Compiled twice, for AVX2 and for the baseline,
// and chosen at load time, so the build stays portable.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define IMUFIT_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define IMUFIT_VECTOR_CLONES
#endif

IMUFIT_VECTOR_CLONES double SecondDifferenceSquares(const double* p0, const double* p1, const double* p2,
                                                    int64_t count) {
  double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int64_t k = 0;
  for (; k + 8 <= count; k += 8) {
    for (int l = 0; l < 8; ++l) {
      const double d = p2[k + l] - 2.0 * p1[k + l] + p0[k + l];
      s[l] += d * d;
    }
  }
  for (; k < count; ++k) {
    const double d = p2[k] - 2.0 * p1[k] + p0[k];
    s[0] += d * d;
  }
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

IMUFIT_VECTOR_CLONES double ThirdDifferenceSquares(const double* p0, const double* p1, const double* p2,
                                                   const double* p3, int64_t count) {
  double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int64_t k = 0;
  for (; k + 8 <= count; k += 8) {
    for (int l = 0; l < 8; ++l) {
      const double d = p3[k + l] - 3.0 * p2[k + l] + 3.0 * p1[k + l] - p0[k + l];
      s[l] += d * d;
    }
  }
  for (; k < count; ++k) {
    const double d = p3[k] - 3.0 * p2[k] + 3.0 * p1[k] - p0[k];
    s[0] += d * d;
  }
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// Sum of squares of term(k), k = 0 .. count-1, in four independent accumulators (so the compiler
// can vectorize and the adds need not wait for each other).
template <typename Term>
inline double SumSquares(int64_t count, Term term) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int64_t k = 0;
  for (; k + 4 <= count; k += 4) {
    const double a = term(k), b = term(k + 1), c = term(k + 2), d = term(k + 3);
    s0 += a * a;
    s1 += b * b;
    s2 += c * c;
    s3 += d * d;
  }
  for (; k < count; ++k) {
    const double a = term(k);
    s0 += a * a;
  }
  return (s0 + s1) + (s2 + s3);
}

// The sweep: for every averaging factor t, sum over terms k in [0, terms[t]) of the squared term,
// with the term range split across threads and walked in blocks; each thread owns a kernel
// (which may keep per-factor state) from make_kernel(). Kernel::Block(t, begin, end) returns the
// sum of squares over [begin, end) for factor t.
template <typename MakeKernel>
std::vector<long double> Sweep(const std::vector<int64_t>& terms, int threads, MakeKernel make_kernel) {
  const size_t count = terms.size();
  int64_t max_terms = 0;
  for (int64_t t : terms) max_terms = std::max(max_terms, t);
  const int workers = static_cast<int>(
      std::max<int64_t>(1, std::min<int64_t>(ResolveThreads(threads), max_terms / kMinTermsPerThread)));
  std::vector<std::vector<long double>> partial(workers, std::vector<long double>(count, 0.0L));
  RunParallel(workers, [&](int w) {
    auto kernel = make_kernel();
    const int64_t begin = max_terms * w / workers;
    const int64_t end = max_terms * (w + 1) / workers;
    std::vector<long double>& sums = partial[w];
    for (int64_t b = begin; b < end; b += kBlock) {
      const int64_t e = std::min(b + kBlock, end);
      for (size_t t = 0; t < count; ++t) {
        const int64_t hi = std::min(e, terms[t]);
        if (b < hi) sums[t] += kernel.Block(t, b, hi);
      }
    }
  });
  std::vector<long double> total(count, 0.0L);
  for (const auto& sums : partial) {
    for (size_t t = 0; t < count; ++t) total[t] += sums[t];
  }
  return total;
}

// ---- kernels: X is the phase (n + 1 values), m[t] the averaging factors.

struct AdevKernel {  // second differences at stride m
  const double* x;
  const std::vector<int64_t>* m;
  double Block(size_t t, int64_t begin, int64_t end) const {
    const int64_t s = (*m)[t];
    const double* p = x + begin * s;
    return SumSquares(end - begin, [p, s](int64_t k) {
      const double* q = p + k * s;
      return q[2 * s] - 2.0 * q[s] + q[0];
    });
  }
};

struct OadevKernel {  // second differences at stride 1
  const double* x;
  const std::vector<int64_t>* m;
  double Block(size_t t, int64_t begin, int64_t end) const {
    const int64_t s = (*m)[t];
    const double* p0 = x + begin;
    return SecondDifferenceSquares(p0, p0 + s, p0 + 2 * s, end - begin);
  }
};

struct HdevKernel {  // third differences at stride m
  const double* x;
  const std::vector<int64_t>* m;
  double Block(size_t t, int64_t begin, int64_t end) const {
    const int64_t s = (*m)[t];
    const double* p = x + begin * s;
    return SumSquares(end - begin, [p, s](int64_t k) {
      const double* q = p + k * s;
      return q[3 * s] - 3.0 * q[2 * s] + 3.0 * q[s] - q[0];
    });
  }
};

struct OhdevKernel {  // third differences at stride 1
  const double* x;
  const std::vector<int64_t>* m;
  double Block(size_t t, int64_t begin, int64_t end) const {
    const int64_t s = (*m)[t];
    const double* p0 = x + begin;
    return ThirdDifferenceSquares(p0, p0 + s, p0 + 2 * s, p0 + 3 * s, end - begin);
  }
};

// Modified Allan: z_j = sum_{i=j}^{j+m-1} d_i with d_i = X_{i+2m} - 2 X_{i+m} + X_i, slid along
// z_{j+1} = z_j + d_{j+m} - d_j. The window is summed afresh where a thread starts a factor, and at
// every block for small m (cheap then) so rounding cannot accumulate along 1e8 slides.
struct MdevKernel {
  const double* x;
  const std::vector<int64_t>* m;
  std::vector<double> z;      // window sum at next[t]
  std::vector<int64_t> next;  // the term index z belongs to; -2 = not started
  double D(int64_t i, int64_t s) const { return x[i + 2 * s] - 2.0 * x[i + s] + x[i]; }
  double Window(int64_t j, int64_t s) const {
    double sum = 0.0;
    for (int64_t i = j; i < j + s; ++i) sum += D(i, s);
    return sum;
  }
  double Block(size_t t, int64_t begin, int64_t end) {
    if (z.empty()) {
      z.assign(m->size(), 0.0);
      next.assign(m->size(), -2);
    }
    const int64_t s = (*m)[t];
    // z[t] holds the window at next[t]; the last term's window is never slid past (it would read
    // beyond X_n).
    double w = (next[t] == begin - 1 && s > kBlock / 4) ? z[t] + D(begin - 1 + s, s) - D(begin - 1, s)
                                                        : Window(begin, s);
    double sum = 0.0;
    for (int64_t j = begin; j < end; ++j) {
      sum += w * w;
      if (j + 1 < end) w += D(j + s, s) - D(j, s);
    }
    z[t] = w;
    next[t] = end - 1;
    return sum;
  }
};

// Total deviation: second differences of the phase reflected about both ends; term k is centred
// on i = k + 1 (i = 1 .. N-2).
struct TotdevKernel {
  const double* x;
  const std::vector<int64_t>* m;
  int64_t n;  // last phase index, N - 1
  double Star(int64_t i) const {
    if (i < 0) return 2.0 * x[0] - x[-i];
    if (i > n) return 2.0 * x[n] - x[2 * n - i];
    return x[i];
  }
  double Block(size_t t, int64_t begin, int64_t end) const {
    const int64_t s = (*m)[t];
    // Terms whose three points lie inside the record: k in [s - 1, n - s - 1].
    const int64_t inner_begin = std::clamp<int64_t>(s - 1, begin, end);
    const int64_t inner_end = std::clamp<int64_t>(n - s, inner_begin, end);
    auto reflected = [&](int64_t from, int64_t to) {
      double sum = 0.0;
      for (int64_t k = from; k < to; ++k) {
        const double d = Star(k + 1 - s) - 2.0 * x[k + 1] + Star(k + 1 + s);
        sum += d * d;
      }
      return sum;
    };
    const double* p0 = x + inner_begin + 1 - s;
    const double inner = SecondDifferenceSquares(p0, p0 + s, p0 + 2 * s, inner_end - inner_begin);
    return reflected(begin, inner_begin) + inner + reflected(inner_end, end);
  }
};

int DifferenceOrder(AllanEstimator estimator) {
  return (estimator == AllanEstimator::kHdev || estimator == AllanEstimator::kOhdev) ? 3 : 2;
}

std::optional<double> Edf(AllanEstimator estimator, int alpha, int64_t m, int64_t n_phase) {
  switch (estimator) {
    case AllanEstimator::kAdev:
      return GreenhallEdf(alpha, 2, m, false, false, n_phase);
    case AllanEstimator::kOadev:
      return GreenhallEdf(alpha, 2, m, false, true, n_phase);
    case AllanEstimator::kMdev:
    case AllanEstimator::kTdev:
      return GreenhallEdf(alpha, 2, m, true, true, n_phase);
    case AllanEstimator::kHdev:
      return GreenhallEdf(alpha, 3, m, false, false, n_phase);
    case AllanEstimator::kOhdev:
      return GreenhallEdf(alpha, 3, m, false, true, n_phase);
    case AllanEstimator::kTotdev:
      return TotdevEdf(alpha, m, n_phase);
  }
  return std::nullopt;
}

}  // namespace

const char* ToString(AllanEstimator estimator) { return NameOf(kEstimatorNames, estimator); }
bool ParseAllanEstimator(std::string_view text, AllanEstimator* estimator) {
  return ValueOf(kEstimatorNames, text, estimator);
}
std::string AllanEstimatorNames() { return AllNames(kEstimatorNames); }

const char* ToString(EdfNoise noise) { return NameOf(kEdfNoiseNames, noise); }
bool ParseEdfNoise(std::string_view text, EdfNoise* noise) { return ValueOf(kEdfNoiseNames, text, noise); }
std::string EdfNoiseNames() { return AllNames(kEdfNoiseNames); }

std::string ParseTauSpec(std::string_view text, TauSpec* spec) {
  const std::string allowed =
      "allowed: octave, decade, all, per-decade:K (K = 1..1000 taus per decade), or a list of taus in "
      "seconds such as 1,10,100";
  TauSpec result;
  if (text == "octave") {
    result.kind = TauSpec::Kind::kOctave;
  } else if (text == "decade") {
    result.kind = TauSpec::Kind::kDecade;
  } else if (text == "all") {
    result.kind = TauSpec::Kind::kAll;
  } else if (text.substr(0, 11) == "per-decade:") {
    const std::string_view digits = text.substr(11);
    int k = 0;
    const auto parsed = std::from_chars(digits.data(), digits.data() + digits.size(), k);
    if (parsed.ec != std::errc() || parsed.ptr != digits.data() + digits.size() || k < 1 || k > 1000) {
      return "\"" + std::string(text) + "\" is not a valid tau set; " + allowed;
    }
    result.kind = TauSpec::Kind::kPerDecade;
    result.per_decade = k;
  } else {
    result.kind = TauSpec::Kind::kList;
    size_t start = 0;
    while (start <= text.size()) {
      const size_t comma = std::min(text.find(',', start), text.size());
      std::string_view item = text.substr(start, comma - start);
      while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
      while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
      double tau = 0.0;
      const auto parsed = std::from_chars(item.data(), item.data() + item.size(), tau);
      if (item.empty() || parsed.ec != std::errc() || parsed.ptr != item.data() + item.size() ||
          !(tau > 0.0) || !std::isfinite(tau)) {
        return "\"" + std::string(item) + "\" in \"" + std::string(text) +
               "\" is not a positive number of seconds; " + allowed;
      }
      result.taus_s.push_back(tau);
      start = comma + 1;
    }
  }
  *spec = result;
  return "";
}

int64_t EstimatorTerms(AllanEstimator estimator, int64_t m, int64_t n) {
  if (m < 1 || n < 1) return 0;
  switch (estimator) {
    case AllanEstimator::kAdev:
      return n / m - 1;
    case AllanEstimator::kOadev:
      return n + 1 - 2 * m;
    case AllanEstimator::kMdev:
    case AllanEstimator::kTdev:
      return n + 2 - 3 * m;
    case AllanEstimator::kHdev:
      return n / m - 2;
    case AllanEstimator::kOhdev:
      return n + 1 - 3 * m;
    case AllanEstimator::kTotdev:
      return 2 * m <= n ? n - 1 : 0;
  }
  return 0;
}

int64_t MaxAveragingFactor(AllanEstimator estimator, int64_t n) {
  switch (estimator) {
    case AllanEstimator::kAdev:
    case AllanEstimator::kOadev:
    case AllanEstimator::kTotdev:
      return n / 2;
    case AllanEstimator::kMdev:
    case AllanEstimator::kTdev:
      return (n + 1) / 3;
    case AllanEstimator::kHdev:
    case AllanEstimator::kOhdev:
      return n / 3;
  }
  return 0;
}

int64_t MaxGeneratedAveragingFactor(AllanEstimator estimator, int64_t n) {
  return estimator == AllanEstimator::kTotdev ? n / 2 : n / 4;
}

std::string AveragingFactors(const TauSpec& spec, AllanEstimator estimator, int64_t n, double tau0_s,
                             std::vector<int64_t>* factors) {
  std::vector<int64_t> m;
  const int64_t max_generated = MaxGeneratedAveragingFactor(estimator, n);
  switch (spec.kind) {
    case TauSpec::Kind::kOctave:
      for (int64_t f = 1; f <= max_generated; f *= 2) m.push_back(f);
      break;
    case TauSpec::Kind::kDecade:
      for (int64_t base = 1; base <= max_generated; base *= 10) {
        for (int64_t f : {base, 2 * base, 4 * base}) {
          if (f <= max_generated) m.push_back(f);
        }
      }
      break;
    case TauSpec::Kind::kAll:
      if (static_cast<double>(n) * static_cast<double>(max_generated) > kMaxAllWork) {
        char message[256];
        std::snprintf(message, sizeof message,
                      "--taus all would evaluate %lld taus over %lld samples (O(N^2)); use per-decade:K "
                      "(e.g. per-decade:100) for long records",
                      static_cast<long long>(max_generated), static_cast<long long>(n));
        return message;
      }
      for (int64_t f = 1; f <= max_generated; ++f) m.push_back(f);
      break;
    case TauSpec::Kind::kPerDecade:
      for (int i = 0;; ++i) {
        const double f = std::round(std::pow(10.0, static_cast<double>(i) / spec.per_decade));
        if (f > static_cast<double>(max_generated)) break;
        if (m.empty() || m.back() != static_cast<int64_t>(f)) m.push_back(static_cast<int64_t>(f));
      }
      break;
    case TauSpec::Kind::kList: {
      const int64_t max_factor = MaxAveragingFactor(estimator, n);
      for (double tau : spec.taus_s) {
        const double ratio = tau / tau0_s;
        const double f = std::round(ratio);
        char message[320];
        if (f < 1.0 || std::fabs(ratio - f) > kTauMultipleTolerance) {
          std::snprintf(
              message, sizeof message,
              "tau %g s is not a whole multiple of the sample interval %.9g s (it is %.6g intervals)", tau,
              tau0_s, ratio);
          return message;
        }
        if (f > static_cast<double>(max_factor)) {
          std::snprintf(message, sizeof message,
                        "tau %g s is too long for %lld samples at %.9g s: %s reaches at most tau = %.9g s",
                        tau, static_cast<long long>(n), tau0_s, ToString(estimator),
                        static_cast<double>(max_factor) * tau0_s);
          return message;
        }
        m.push_back(static_cast<int64_t>(f));
      }
      std::sort(m.begin(), m.end());
      m.erase(std::unique(m.begin(), m.end()), m.end());
      break;
    }
  }
  if (m.empty()) {
    char message[256];
    std::snprintf(
        message, sizeof message, "too short: %lld samples are not enough for %s (at least %d are needed)",
        static_cast<long long>(n), ToString(estimator), estimator == AllanEstimator::kTotdev ? 2 : 4);
    return message;
  }
  *factors = std::move(m);
  return "";
}

std::string AllanOptions::Validate() const {
  if (std::string problem = ValidateOptions(AllanOptionTable(), *this); !problem.empty()) return problem;
  if (max_noise_id_points < kMinNoiseIdPoints) {
    return "max_noise_id_points must be at least " + std::to_string(kMinNoiseIdPoints);
  }
  return "";
}

double RatesToPhase(std::vector<double>* samples, int threads) {
  std::vector<double>& y = *samples;
  const int64_t n = static_cast<int64_t>(y.size());
  const int workers = static_cast<int>(
      std::max<int64_t>(1, std::min<int64_t>(ResolveThreads(threads), n / kMinTermsPerThread)));
  // Pass 1: chunk sums, hence the mean. Short runs are summed in double, the runs in long double.
  std::vector<long double> chunk_sum(workers, 0.0L);
  RunParallel(workers, [&](int w) {
    long double sum = 0.0L;
    const int64_t end = n * (w + 1) / workers;
    for (int64_t i = n * w / workers; i < end; i += kPhaseRun) {
      const int64_t stop = std::min(i + kPhaseRun, end);
      sum += SumOf(y.data() + i, stop - i);
    }
    chunk_sum[w] = sum;
  });
  long double total = 0.0L;
  for (long double s : chunk_sum) total += s;
  const long double mean_exact = n > 0 ? total / n : 0.0L;
  const double mean = static_cast<double>(mean_exact);
  // The mean as double plus the rest, so that (y - mean) - rest is the exact deviation to long
  // double precision while the inner loop stays in double.
  const long double mean_rest = mean_exact - mean;
  // Pass 2, in place (slot k takes X_k while y_k is read out of it). Within a run of kPhaseRun
  // samples X is the run's start (long double) plus a short double sum, so rounding never
  // accumulates beyond one run; each chunk starts from the exact running sum.
  std::vector<long double> start(workers, 0.0L);
  for (int w = 1; w < workers; ++w) {
    const int64_t length = n * w / workers - n * (w - 1) / workers;
    start[w] = start[w - 1] + (chunk_sum[w - 1] - mean_exact * length);
  }
  y.push_back(0.0);
  RunParallel(workers, [&](int w) {
    long double base = start[w];
    const int64_t end = n * (w + 1) / workers;
    for (int64_t i = n * w / workers; i < end; i += kPhaseRun) {
      const int64_t stop = std::min(i + kPhaseRun, end);
      const double origin = static_cast<double>(base);
      const double origin_rest = static_cast<double>(base - origin);
      double local = 0.0;
      for (int64_t k = i; k < stop; ++k) {
        const double rate = y[k];
        y[k] = origin + (origin_rest + local);
        local += rate - mean;
      }
      base += static_cast<long double>(local) - mean_rest * (stop - i);
    }
    if (w == workers - 1) y[n] = static_cast<double>(base);
  });
  return mean;
}

std::vector<double> Deviations(const std::vector<double>& phase, double tau0_s,
                               const std::vector<int64_t>& factors, AllanEstimator estimator, int threads) {
  const int64_t n = static_cast<int64_t>(phase.size()) - 1;
  std::vector<int64_t> terms;
  for (int64_t m : factors) {
    terms.push_back(EstimatorTerms(estimator, m, n));
    IMUFIT_CHECK(terms.back() >= 1, "every averaging factor leaves at least one term");
  }
  const double* x = phase.data();
  std::vector<long double> sums;
  switch (estimator) {
    case AllanEstimator::kAdev:
      sums = Sweep(terms, threads, [&] { return AdevKernel{x, &factors}; });
      break;
    case AllanEstimator::kOadev:
      sums = Sweep(terms, threads, [&] { return OadevKernel{x, &factors}; });
      break;
    case AllanEstimator::kMdev:
    case AllanEstimator::kTdev:
      sums = Sweep(terms, threads, [&] { return MdevKernel{x, &factors, {}, {}}; });
      break;
    case AllanEstimator::kHdev:
      sums = Sweep(terms, threads, [&] { return HdevKernel{x, &factors}; });
      break;
    case AllanEstimator::kOhdev:
      sums = Sweep(terms, threads, [&] { return OhdevKernel{x, &factors}; });
      break;
    case AllanEstimator::kTotdev:
      sums = Sweep(terms, threads, [&] { return TotdevKernel{x, &factors, n}; });
      break;
  }
  std::vector<double> devs(factors.size());
  for (size_t t = 0; t < factors.size(); ++t) {
    const long double m = factors[t];
    const long double count = terms[t];
    long double variance = 0.0L;
    switch (estimator) {
      case AllanEstimator::kAdev:
      case AllanEstimator::kOadev:
      case AllanEstimator::kTotdev:
        variance = sums[t] / (2.0L * m * m * count);
        break;
      case AllanEstimator::kMdev:
      case AllanEstimator::kTdev:
        variance = sums[t] / (2.0L * m * m * m * m * count);
        break;
      case AllanEstimator::kHdev:
      case AllanEstimator::kOhdev:
        variance = sums[t] / (6.0L * m * m * count);
        break;
    }
    double dev = std::sqrt(static_cast<double>(variance));
    if (estimator == AllanEstimator::kTdev) dev *= static_cast<double>(m) * tau0_s / std::sqrt(3.0);
    devs[t] = dev;
  }
  return devs;
}

namespace {

// The lag-1 autocorrelation of the n / m rate averages (X_{(k+1)m} - X_{km}) / m (AllanPoint::lag1).
double Lag1OfAverages(const std::vector<double>& phase, int64_t m) {
  const int64_t count = (static_cast<int64_t>(phase.size()) - 1) / m;
  if (count < kMinLag1Averages) return std::nan("");
  const double mean = (phase[count * m] - phase[0]) / static_cast<double>(count * m);
  long double lagged = 0.0L;
  long double squares = 0.0L;
  double previous = 0.0;
  for (int64_t k = 0; k < count; ++k) {
    const double average = (phase[(k + 1) * m] - phase[k * m]) / static_cast<double>(m) - mean;
    squares += average * average;
    if (k > 0) lagged += average * previous;
    previous = average;
  }
  return squares > 0.0L ? static_cast<double>(lagged / squares) : std::nan("");
}

}  // namespace

AllanResult ComputeAllan(const std::vector<double>& phase, double tau0_s, const std::vector<int64_t>& factors,
                         const AllanOptions& options) {
  AllanResult result;
  result.estimator = options.estimator;
  result.tau0_s = tau0_s;
  const int64_t n = static_cast<int64_t>(phase.size()) - 1;
  result.n_samples = n;
  const std::vector<double> devs = Deviations(phase, tau0_s, factors, options.estimator, options.threads);

  const int d = DifferenceOrder(options.estimator);
  // Valid noise exponents for the edf: alpha + 2 d > 1, alpha in [-4, 2]; totdev's table stops at -2.
  const int alpha_min = options.estimator == AllanEstimator::kTotdev ? -2 : std::max(-4, 2 - 2 * d);
  int carried_alpha = 0;  // white FM until something is identified
  for (const EdfNoiseName& entry : kEdfNoiseNames) {
    if (entry.value == options.edf_noise) carried_alpha = entry.alpha;
  }
  std::vector<double> means;
  for (size_t t = 0; t < factors.size(); ++t) {
    AllanPoint point;
    point.m = factors[t];
    point.tau_s = static_cast<double>(point.m) * tau0_s;
    point.terms = EstimatorTerms(options.estimator, point.m, n);
    point.dev = devs[t];
    point.lag1 = Lag1OfAverages(phase, point.m);
    if (options.edf_noise == EdfNoise::kIdentify) {
      // Rate averages over tau from the phase: (X_{(k+1)m} - X_{km}) / m.
      const int64_t count = std::min(n / point.m, options.max_noise_id_points);
      if (count >= kMinNoiseIdPoints) {
        means.resize(count);
        for (int64_t k = 0; k < count; ++k) {
          means[k] = (phase[(k + 1) * point.m] - phase[k * point.m]) / static_cast<double>(point.m);
        }
        if (const auto id = IdentifyNoiseLag1(means.data(), count, d)) {
          const int alpha = std::clamp(id->alpha, alpha_min, 2);
          // With few averages the lag-1 estimate scatters by about 1/sqrt(count); a noise type
          // identified too high would inflate the edf (white PM has ten times white FM's), so
          // there the more conservative of this and the type from below is kept.
          carried_alpha = count >= kReliableNoiseIdPoints ? alpha : std::min(alpha, carried_alpha);
          point.alpha_identified = true;
        }
      }
    }
    point.alpha = std::clamp(carried_alpha, alpha_min, 2);
    const std::optional<double> edf = Edf(options.estimator, point.alpha, point.m, n + 1);
    if (edf && point.dev > 0.0) {
      point.edf = *edf;
      ChiSquaredInterval(point.dev, *edf, options.confidence, &point.dev_lo, &point.dev_hi);
    } else if (edf && point.dev == 0.0) {
      // A constant column: the interval scales with the estimate, so it is [0, 0], not nan.
      point.edf = *edf;
      point.dev_lo = point.dev_hi = 0.0;
    } else {
      point.edf = std::nan("");
      point.dev_lo = point.dev_hi = std::nan("");
    }
    result.points.push_back(point);
  }
  return result;
}

AllanResult ComputeAllanFromRates(std::vector<double> rates, double tau0_s,
                                  const std::vector<int64_t>& factors, const AllanOptions& options) {
  const double mean = RatesToPhase(&rates, options.threads);
  AllanResult result = ComputeAllan(rates, tau0_s, factors, options);
  result.mean = mean;
  return result;
}

}  // namespace imufit
