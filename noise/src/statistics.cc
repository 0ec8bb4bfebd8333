#include "imufit/noise/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

constexpr double kRelativeEpsilon = 1e-16;
constexpr int kMaxGammaIterations = 100000000;

// log(x^a e^-x / Gamma(a)), the prefactor of both incomplete gamma expansions. For large a the
// naive a log x - x - lgamma(a) cancels to a small number from terms of size a log a; instead
// write x = a (1 + t): a log x - x - lgamma(a) = a (log1p(t) - t) + [a log a - a - lgamma(a)],
// and the bracket has the Stirling expansion 0.5 log(a / 2 pi) - 1/(12 a) + 1/(360 a^3) - ...
double LogGammaPrefactor(double a, double x) {
  if (a < 10.0) return a * std::log(x) - x - std::lgamma(a);
  const double t = (x - a) / a;
  const double stirling = 0.5 * std::log(a / (2.0 * kPi)) - 1.0 / (12.0 * a) + 1.0 / (360.0 * a * a * a) -
                          1.0 / (1260.0 * std::pow(a, 5));
  return a * (std::log1p(t) - t) + stirling;
}

}  // namespace

void RegularizedGamma(double a, double x, double* p, double* q) {
  if (x <= 0.0) {
    *p = 0.0;
    *q = 1.0;
    return;
  }
  const double prefactor = std::exp(LogGammaPrefactor(a, x));
  if (x < a + 1.0) {
    // Series: P = prefactor * sum_n x^n / (a (a+1) ... (a+n)).
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < kMaxGammaIterations; ++n) {
      term *= x / (a + n);
      sum += term;
      if (term < sum * kRelativeEpsilon) break;
    }
    *p = std::min(1.0, sum * prefactor);
    *q = 1.0 - *p;
    return;
  }
  // Continued fraction for Q (modified Lentz): Q = prefactor / (x+1-a - 1(1-a)/(x+3-a - ...)).
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxGammaIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kRelativeEpsilon) break;
  }
  *q = std::min(1.0, prefactor * h);
  *p = 1.0 - *q;
}

double NormalQuantile(double probability) {
  // Start from Abramowitz & Stegun 26.2.23 (|error| < 4.5e-4), then polish with Halley steps on
  // Phi(z) = erfc(-z / sqrt 2) / 2.
  const double tail = std::min(probability, 1.0 - probability);
  const double t = std::sqrt(-2.0 * std::log(tail));
  double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                     (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  if (probability < 0.5) z = -z;
  for (int i = 0; i < 3; ++i) {
    const double error = 0.5 * std::erfc(-z / std::sqrt(2.0)) - probability;
    const double density = std::exp(-0.5 * z * z) / std::sqrt(2.0 * kPi);
    const double newton = error / density;
    z -= newton / (1.0 + 0.5 * z * newton);
  }
  return z;
}

double ChiSquaredQuantile(double probability, double dof) {
  // Solve P(a, x) = probability for the gamma variate x (a = dof / 2); chi2 = 2 x. Near the upper
  // tail the equation is written as Q(a, x) = 1 - probability so that no digits are lost.
  const double a = 0.5 * dof;
  const bool upper = probability > 0.5;
  const double target = upper ? 1.0 - probability : probability;
  // Wilson-Hilferty start: chi2 ~ k (1 - 2/(9k) + z sqrt(2/(9k)))^3.
  const double h = 2.0 / (9.0 * dof);
  const double cube = 1.0 - h + NormalQuantile(probability) * std::sqrt(h);
  double x = cube > 0.05 ? 0.5 * dof * cube * cube * cube : a * std::pow(probability, 1.0 / a);
  if (!(x > 0.0) || !std::isfinite(x)) x = a;
  double lo = 0.0;
  double hi = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 500; ++iteration) {
    double p = 0.0;
    double q = 0.0;
    RegularizedGamma(a, x, &p, &q);
    // f > 0 means x is beyond the quantile.
    const double f = upper ? target - q : p - target;
    if (f > 0.0) {
      hi = x;
    } else {
      lo = x;
    }
    const double density = std::exp(LogGammaPrefactor(a, x)) / x;
    const double step = f / density;
    if (f == 0.0 || std::fabs(step) <= 1e-15 * x) return 2.0 * (x - step);
    double next = x - step;
    if (!(next > lo && next < hi) || !std::isfinite(next)) {
      next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * x;
    }
    x = next;
  }
  return 2.0 * x;
}

void ChiSquaredInterval(double dev, double edf, double confidence, double* dev_lo, double* dev_hi) {
  const double chi2_upper = ChiSquaredQuantile(0.5 * (1.0 + confidence), edf);
  const double chi2_lower = ChiSquaredQuantile(0.5 * (1.0 - confidence), edf);
  *dev_lo = dev * std::sqrt(edf / chi2_upper);
  *dev_hi = dev * std::sqrt(edf / chi2_lower);
}

// ------------------------------------------------------------------ Greenhall's edf algorithm
//
// Notation of Greenhall & Riley (2003): the variance is a mean of squared filtered phase,
// z_n = sum_k w_k x_{n-k}, whose normalized covariance at lag t (in units of m tau0) is built
// from the generalized autocovariance of the phase, sw(t) (their eq. 7), smoothed by the
// averaging filter (sx, eq. 8) and differenced d times (sz, eq. 9). 1/edf is the sum of squared
// correlations (eq. 10), evaluated exactly when few lags matter and from their fitted
// asymptotics (tables 1 to 3) otherwise.
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kJMax = 100;

double Sw(double t, int alpha) {
  const double at = std::fabs(t);
  switch (alpha) {
    case 2:
      return -at;
    case 1:
      return t == 0.0 ? 0.0 : t * t * std::log(at);
    case 0:
      return at * at * at;
    case -1:
      return t == 0.0 ? 0.0 : std::pow(t, 4) * std::log(at);
    case -2:
      return std::pow(at, 5);
    case -3:
      return t == 0.0 ? 0.0 : std::pow(t, 6) * std::log(at);
    case -4:
      return std::pow(at, 7);
  }
  return 0.0;
}

// sx(t) = F^2 (2 sw(t) - sw(t - 1/F) - sw(t + 1/F)), and sw(t, alpha + 2) for F = infinity.
double Sx(double t, double f, int alpha) {
  if (std::isinf(f)) return Sw(t, alpha + 2);
  if (alpha == 1 && f > 1000.0) {
    // Flicker PM at a large filter factor: the second difference of t^2 log|t| cancels badly.
    // At t = 0 it is exactly 2 log F; elsewhere use its Taylor series -(sw'' + h^2 sw''''/12).
    if (t == 0.0) return 2.0 * std::log(f);
    const double h = 1.0 / f;
    return -(2.0 * std::log(std::fabs(t)) + 3.0 - h * h / (6.0 * t * t));
  }
  return f * f * (2.0 * Sw(t, alpha) - Sw(t - 1.0 / f, alpha) - Sw(t + 1.0 / f, alpha));
}

// sz(t) = sum_{k=-d..d} (-1)^k C(2d, d+k) sx(t + k).
double Sz(double t, double f, int alpha, int d) {
  static constexpr double kBinomial[4][4] = {{1, 0, 0, 0}, {2, 1, 0, 0}, {6, 4, 1, 0}, {20, 15, 6, 1}};
  double sum = kBinomial[d][0] * Sx(t, f, alpha);
  for (int k = 1; k <= d; ++k) {
    const double sign = (k % 2 == 1) ? -1.0 : 1.0;
    sum += sign * kBinomial[d][k] * (Sx(t - k, f, alpha) + Sx(t + k, f, alpha));
  }
  return sum;
}

double BasicSum(double j, double m_terms, double s, double f, int alpha, int d) {
  const double s0 = Sz(0.0, f, alpha, d);
  double sum = s0 * s0;
  const double sj = Sz(j / s, f, alpha, d);
  sum += (1.0 - j / m_terms) * sj * sj;
  for (int64_t k = 1; k < static_cast<int64_t>(j); ++k) {
    const double sk = Sz(k / s, f, alpha, d);
    sum += 2.0 * (1.0 - k / m_terms) * sk * sk;
  }
  return sum;
}

// Asymptotic coefficients (a0, a1) of 1/edf = (a0 - a1 / r) / r; row alpha = 2 - index, column d-1.
// Zeros mark combinations outside alpha + 2 d > 1.
struct Coefficients {
  double a0;
  double a1;
};
constexpr Coefficients kTable1Modified[7][3] = {
    {{2.0 / 3.0, 1.0 / 3.0}, {7.0 / 9.0, 1.0 / 2.0}, {22.0 / 25.0, 2.0 / 3.0}},  // alpha = 2
    {{0.840, 0.345}, {0.997, 0.616}, {1.141, 0.843}},                            // 1
    {{1.079, 0.368}, {1.033, 0.607}, {1.184, 0.848}},                            // 0
    {{0, 0}, {1.048, 0.534}, {1.180, 0.816}},                                    // -1
    {{0, 0}, {1.302, 0.535}, {1.175, 0.777}},                                    // -2
    {{0, 0}, {0, 0}, {1.194, 0.703}},                                            // -3
    {{0, 0}, {0, 0}, {1.489, 0.702}}};                                           // -4
constexpr Coefficients kTable2Unmodified[7][3] = {
    {{3.0 / 2.0, 1.0 / 2.0}, {35.0 / 18.0, 1.0}, {231.0 / 100.0, 3.0 / 2.0}},  // alpha = 2
    {{78.6, 25.2}, {790.0, 410.0}, {9950.0, 6520.0}},                          // 1
    {{2.0 / 3.0, 1.0 / 6.0}, {2.0 / 3.0, 1.0 / 3.0}, {7.0 / 9.0, 1.0 / 2.0}},  // 0
    {{0, 0}, {0.852, 0.375}, {0.997, 0.617}},                                  // -1
    {{0, 0}, {1.079, 0.368}, {1.033, 0.607}},                                  // -2
    {{0, 0}, {0, 0}, {1.053, 0.553}},                                          // -3
    {{0, 0}, {0, 0}, {1.302, 0.535}}};                                         // -4
// Flicker PM, unmodified: sz(0)^2 grows like (b0 + b1 ln m)^2.
constexpr Coefficients kTable3FlickerPm[3] = {{6.0, 4.0}, {15.23, 12.0}, {47.8, 40.0}};

double Binomial(int n, int k) {
  double result = 1.0;
  for (int i = 1; i <= k; ++i) result = result * (n - k + i) / i;
  return result;
}

}  // namespace

std::optional<double> GreenhallEdf(int alpha, int d, int64_t m, bool modified, bool overlapping,
                                   int64_t n_phase) {
  if (d < 1 || d > 3 || alpha > 2 || alpha < -4 || alpha + 2 * d <= 1 || m < 1) return std::nullopt;
  const double md = static_cast<double>(m);
  const double f = modified ? 1.0 : md;
  const double s = overlapping ? md : 1.0;
  const double n = static_cast<double>(n_phase);
  const double l = md / f + md * d;
  if (n < l) return std::nullopt;
  const double m_terms = 1.0 + std::floor(s * (n - l) / md);
  const double j = std::min(m_terms, (d + 1) * s);
  const double r = m_terms / s;
  const int row = 2 - alpha;
  double inverse = 0.0;
  if (modified) {
    if (j <= kJMax) {
      const double s0 = Sz(0.0, 1.0, alpha, d);
      inverse = BasicSum(j, m_terms, s, 1.0, alpha, d) / (s0 * s0 * m_terms);
    } else if (r > d + 1) {
      const Coefficients c = kTable1Modified[row][d - 1];
      inverse = (c.a0 - c.a1 / r) / r;
    } else {
      const double s0 = Sz(0.0, 1.0, alpha, d);
      inverse = BasicSum(kJMax, kJMax, kJMax / r, 1.0, alpha, d) / (s0 * s0 * kJMax);
    }
  } else if (alpha <= 0) {
    if (j <= kJMax) {
      const double f_prime = md * (d + 1) <= kJMax ? md : kInfinity;
      const double s0 = Sz(0.0, f_prime, alpha, d);
      inverse = BasicSum(j, m_terms, s, f_prime, alpha, d) / (s0 * s0 * m_terms);
    } else if (r > d + 1) {
      const Coefficients c = kTable2Unmodified[row][d - 1];
      inverse = (c.a0 - c.a1 / r) / r;
    } else {
      const double s0 = Sz(0.0, kInfinity, alpha, d);
      inverse = BasicSum(kJMax, kJMax, kJMax / r, kInfinity, alpha, d) / (s0 * s0 * kJMax);
    }
  } else if (alpha == 1) {
    const Coefficients b = kTable3FlickerPm[d - 1];
    const double log_term = b.a0 + b.a1 * std::log(md);
    if (j <= kJMax) {
      const double s0 = Sz(0.0, md, 1, d);
      inverse = BasicSum(j, m_terms, s, md, 1, d) / (s0 * s0 * m_terms);
    } else if (r > d + 1) {
      const Coefficients c = kTable2Unmodified[row][d - 1];
      inverse = (c.a0 - c.a1 / r) / (log_term * log_term * r);
    } else {
      const double m_prime = kJMax / r;
      inverse = BasicSum(kJMax, kJMax, m_prime, m_prime, 1, d) / (log_term * log_term * kJMax);
    }
  } else {  // alpha == 2, unmodified
    const double k = std::ceil(r);
    if (k > d) {
      const double a0 = Binomial(4 * d, 2 * d) / (Binomial(2 * d, d) * Binomial(2 * d, d));
      const double a1 = d / 2.0;
      inverse = (a0 - a1 / r) / m_terms;
    } else if (j <= kJMax) {
      // Few terms: the exact sum (white PM decorrelates beyond d + 1 lags).
      const double s0 = Sz(0.0, md, 2, d);
      inverse = BasicSum(j, m_terms, s, md, 2, d) / (s0 * s0 * m_terms);
    } else {
      const double m_prime = kJMax / r;
      const double s0 = Sz(0.0, md, 2, d);
      inverse = BasicSum(kJMax, kJMax, m_prime, md, 2, d) / (s0 * s0 * kJMax);
    }
  }
  if (!(inverse > 0.0) || !std::isfinite(inverse)) return std::nullopt;
  return 1.0 / inverse;
}

std::optional<double> TotdevEdf(int alpha, int64_t m, int64_t n_phase) {
  static constexpr Coefficients kTable7[3] = {{1.50, 0.0}, {1.17, 0.22}, {0.93, 0.36}};
  if (alpha > 0) return GreenhallEdf(alpha, 2, m, /*modified=*/false, /*overlapping=*/true, n_phase);
  if (alpha < -2 || m < 1) return std::nullopt;
  const Coefficients c = kTable7[-alpha];
  const double edf = c.a0 * static_cast<double>(n_phase) / static_cast<double>(m) - c.a1;
  if (!(edf > 0.0)) return std::nullopt;
  return edf;
}

// ------------------------------------------------------------------ noise identification

std::optional<NoiseIdentification> IdentifyNoiseLag1(const double* means, int64_t count, int d_max) {
  if (count < kMinNoiseIdPoints) return std::nullopt;
  std::vector<double> z(means, means + count);
  // Remove a straight line (least squares, abscissa centred so the fit is well conditioned).
  const double centre = 0.5 * static_cast<double>(count - 1);
  long double sum_z = 0.0L;
  long double sum_kz = 0.0L;
  long double sum_kk = 0.0L;
  for (int64_t k = 0; k < count; ++k) {
    const double u = static_cast<double>(k) - centre;
    sum_z += z[k];
    sum_kz += static_cast<long double>(u) * z[k];
    sum_kk += static_cast<long double>(u) * u;
  }
  const double offset = static_cast<double>(sum_z / count);
  const double slope = sum_kk > 0 ? static_cast<double>(sum_kz / sum_kk) : 0.0;
  for (int64_t k = 0; k < count; ++k) z[k] -= offset + slope * (static_cast<double>(k) - centre);

  for (int d = 0;; ++d) {
    const int64_t size = static_cast<int64_t>(z.size());
    if (size < 2) return std::nullopt;
    long double mean = 0.0L;
    for (double v : z) mean += v;
    mean /= size;
    long double numerator = 0.0L;
    long double denominator = 0.0L;
    for (int64_t k = 0; k < size; ++k) {
      const long double a = z[k] - mean;
      denominator += a * a;
      if (k + 1 < size) numerator += a * (z[k + 1] - mean);
    }
    if (!(denominator > 0.0L)) return std::nullopt;
    const double r1 = static_cast<double>(numerator / denominator);
    const double rho = r1 / (1.0 + r1);
    if (rho < 0.25 || d >= d_max) {
      NoiseIdentification id;
      id.differences = d;
      id.alpha_estimate = -2.0 * (rho + d);
      id.alpha = static_cast<int>(-std::lround(2.0 * rho)) - 2 * d;
      return id;
    }
    for (int64_t k = 0; k + 1 < size; ++k) z[k] = z[k + 1] - z[k];
    z.pop_back();
  }
}

}  // namespace imufit
