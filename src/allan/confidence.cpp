// Greenhall–Riley equivalent degrees of freedom and χ² confidence bounds of Allan-type variances,
// following Stable32's choices so that its tables are reproduced.
#include "rwcalc/confidence.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "rwcalc/error.hpp"

namespace rwcalc {

namespace {

using Real = long double;  // the BasicSum differences cancel heavily for large F

Real sw(Real t, int alpha) {
  const Real at = std::fabs(t);
  switch (alpha) {
    case 2: return -at;
    case 1: return t == 0 ? 0 : t * t * std::log(at);
    case 0: return at * at * at;
    case -1: return t == 0 ? 0 : t * t * t * t * std::log(at);
    case -2: return at * at * at * at * at;
    case -3: return t == 0 ? 0 : t * t * t * t * t * t * std::log(at);
    case -4: return at * at * at * at * at * at * at;
    default: throw AnalysisError(trf("EDF: unsupported noise exponent alpha = {}", alpha));
  }
}

constexpr Real kInfinite = std::numeric_limits<Real>::infinity();

// log1p(u)'s Taylor coefficient of u^n, (−1)^(n+1)/n (0 for n < 1).
constexpr Real log1p_coefficient(int n) { return n < 1 ? 0 : (n % 2 ? 1 : -1) / static_cast<Real>(n); }

constexpr int kLogSeriesTerms = 12;  // even k = 2 … 24: u^22 < 2e-20 at u ≤ 1/8

// c_k, the coefficient of u^k in (1 + u)^q·ln(1 + u), for the even k of the series, by q. They depend
// on q alone, and an `all` grid evaluates the series some 10^8 times: made once, at compile time.
using LogSeries = std::array<Real, kLogSeriesTerms>;
constexpr LogSeries log_series(int q) {
  LogSeries c{};
  for (int t = 0; t < kLogSeriesTerms; ++t) {
    const int k = 2 * t + 2;
    Real b = 1;  // C(q, i)
    for (int i = 0; i <= q; ++i) {
      c[static_cast<std::size_t>(t)] += b * log1p_coefficient(k - i);
      b = b * (q - i) / (i + 1);
    }
  }
  return c;
}
// Indexed by q = 3 − α for the α whose sw has a logarithm (+1, −1, −3: q = 2, 4, 6).
constexpr std::array<LogSeries, 7> kLogSeries = {LogSeries{},   LogSeries{}, log_series(2), LogSeries{},
                                                 log_series(4), LogSeries{}, log_series(6)};

// sx for |t| ≥ 8/f, where f²·(2·sw(t) − sw(t − 1/f) − sw(t + 1/f)) would lose about 2·log10(f·|t|)
// digits (11 at f = 524288): the difference is expanded in u = 1/(f·|t|) ≤ 1/8 and summed without
// cancellation. With sw = |t|^q (q odd), 2 − (1 − u)^q − (1 + u)^q = −2·Σ C(q, 2j)·u^(2j); with
// sw = t^q·ln|t| (q even) the ln(1 ± u) terms add −2·Σ c_k·u^k over even k, c_k the coefficient of
// u^k in (1 + u)^q·ln(1 + u). Both series are divided by u² (f²·|t|^q = |t|^(q−2)/u²).
Real sx_expanded(Real at, Real u, int alpha) {
  if (alpha == 2) return 0;  // −|t| is linear away from 0
  const bool has_log = alpha == 1 || alpha == -1 || alpha == -3;
  const int q = 3 - alpha;  // sw = t^q·ln|t| (q even) or |t|^q (q odd)
  Real even_poly = 0;       // Σ_{j≥1} C(q, 2j)·u^(2j−2)
  Real binom = 1, upow = 1;
  for (int j = 1; 2 * j <= q; ++j) {
    binom = binom * (q - 2 * j + 2) * (q - 2 * j + 1) / ((2 * j - 1) * (2 * j));
    even_poly += binom * upow;
    upow *= u * u;
  }
  Real scale = 1;  // |t|^(q−2)
  for (int i = 2; i < q; ++i) scale *= at;
  if (!has_log) return -2 * scale * even_poly;
  Real series = 0;  // Σ_{even k≥2} c_k·u^(k−2); |c_k| ≤ 2^q/(k − q)
  upow = 1;
  for (const Real c : kLogSeries[static_cast<std::size_t>(q)]) {
    series += c * upow;
    upow *= u * u;
  }
  return scale * (-2 * even_poly * std::log(at) - 2 * series);
}

Real sx(Real t, Real f, int alpha) {
  if (std::isinf(f)) return sw(t, alpha + 2);
  const Real at = std::fabs(t);
  if (at * f >= 8) return sx_expanded(at, 1 / (f * at), alpha);
  return f * f * (2 * sw(t, alpha) - sw(t - 1 / f, alpha) - sw(t + 1 / f, alpha));
}

Real sz(Real t, Real f, int alpha, int d) {
  switch (d) {
    case 1: return 2 * sx(t, f, alpha) - sx(t - 1, f, alpha) - sx(t + 1, f, alpha);
    case 2:
      return 6 * sx(t, f, alpha) - 4 * sx(t - 1, f, alpha) - 4 * sx(t + 1, f, alpha) + sx(t - 2, f, alpha) +
             sx(t + 2, f, alpha);
    case 3:
      return 20 * sx(t, f, alpha) - 15 * sx(t - 1, f, alpha) - 15 * sx(t + 1, f, alpha) + 6 * sx(t - 2, f, alpha) +
             6 * sx(t + 2, f, alpha) - sx(t - 3, f, alpha) - sx(t + 3, f, alpha);
    default: throw AnalysisError(trf("EDF: unsupported difference order d = {}", d));
  }
}

Real basic_sum(Real j_terms, Real m_terms, Real s, Real f, int alpha, int d) {
  const Real z0 = sz(0, f, alpha, d);
  const Real zj = sz(j_terms / s, f, alpha, d);
  Real sum = z0 * z0 + (1 - j_terms / m_terms) * zj * zj;
  const auto jn = static_cast<std::int64_t>(j_terms);
  for (std::int64_t j = 1; j < jn; ++j) {
    const Real z = sz(static_cast<Real>(j) / s, f, alpha, d);
    sum += 2 * (1 - static_cast<Real>(j) / m_terms) * z * z;
  }
  return sum;
}

struct A01 {
  double a0, a1;
};

// Asymptotic coefficients 1/EDF ≈ (a0 − a1/r)/r (Greenhall & Riley 2003, Tables 1 and 2); rows
// α = +2 … −4, columns d = 1, 2, 3. Zeros mark combinations outside α + 2d > 1.
constexpr std::array<std::array<A01, 3>, 7> kTable1 = {{
    {{{2.0 / 3, 1.0 / 3}, {7.0 / 9, 0.5}, {22.0 / 25, 2.0 / 3}}},
    {{{0.840, 0.345}, {0.997, 0.616}, {1.141, 0.843}}},
    {{{1.079, 0.368}, {1.033, 0.607}, {1.184, 0.848}}},
    {{{0, 0}, {1.048, 0.534}, {1.180, 0.816}}},
    {{{0, 0}, {1.302, 0.535}, {1.175, 0.777}}},
    {{{0, 0}, {0, 0}, {1.194, 0.703}}},
    {{{0, 0}, {0, 0}, {1.489, 0.702}}},
}};
constexpr std::array<std::array<A01, 3>, 7> kTable2 = {{
    {{{1.5, 0.5}, {35.0 / 18, 1.0}, {231.0 / 100, 1.5}}},
    {{{78.6, 25.2}, {790.0, 410.0}, {9950.0, 6520.0}}},
    {{{2.0 / 3, 1.0 / 6}, {2.0 / 3, 1.0 / 3}, {7.0 / 9, 0.5}}},
    {{{0, 0}, {0.852, 0.375}, {0.997, 0.617}}},
    {{{0, 0}, {1.079, 0.368}, {1.033, 0.607}}},
    {{{0, 0}, {0, 0}, {1.053, 0.553}}},
    {{{0, 0}, {0, 0}, {1.302, 0.535}}},
}};
// Table 3 (α = +1): sz(0)² ≈ (b0 + b1·ln m)², d = 1, 2, 3.
constexpr std::array<A01, 3> kTable3 = {{{6.0, 4.0}, {15.23, 12.0}, {47.8, 40.0}}};

double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

}  // namespace

double edf_greenhall(int alpha, int d, std::int64_t m, std::size_t n_phase, bool overlapping, bool modified) {
  if (d < 1 || d > 3) throw AnalysisError(trf("EDF: unsupported difference order d = {}", d));
  if (alpha + 2 * d <= 1 || alpha > 2 || alpha < -4)
    throw AnalysisError(trf("EDF: noise exponent alpha = {} not allowed with d = {}", alpha, d));
  const Real mr = static_cast<Real>(m);
  const Real f = modified ? 1 : mr;     // filter factor
  const Real s = overlapping ? mr : 1;  // stride factor
  const Real l = mr / f + mr * d;       // filter length in phase samples
  const Real nr = static_cast<Real>(n_phase);
  if (nr < l) return 0;
  const Real m_terms = 1 + std::floor(s * (nr - l) / mr);
  const Real j_terms = std::min(m_terms, (d + 1) * s);
  constexpr Real kJmax = 100;
  const Real r = m_terms / s;
  const A01 t1 = kTable1[static_cast<std::size_t>(2 - alpha)][static_cast<std::size_t>(d - 1)];
  const A01 t2 = kTable2[static_cast<std::size_t>(2 - alpha)][static_cast<std::size_t>(d - 1)];
  Real inv = 0;
  auto direct = [&](Real ff) {
    const Real z0 = sz(0, ff, alpha, d);
    return basic_sum(j_terms, m_terms, s, ff, alpha, d) / (z0 * z0 * m_terms);
  };
  if (modified) {  // case 1: modified variances, all α
    if (j_terms <= kJmax) {
      inv = direct(1);
    } else if (r > d + 1) {
      inv = (t1.a0 - t1.a1 / r) / r;
    } else {
      const Real z0 = sz(0, 1, alpha, d);
      inv = basic_sum(kJmax, kJmax, kJmax / r, 1, alpha, d) / (z0 * z0 * kJmax);
    }
  } else if (alpha <= 0) {  // case 2: unmodified, α ≤ 0
    if (j_terms <= kJmax) {
      inv = direct(mr * (d + 1) <= kJmax ? mr : kInfinite);
    } else if (r > d + 1) {
      inv = (t2.a0 - t2.a1 / r) / r;
    } else {
      const Real z0 = sz(0, kInfinite, alpha, d);
      inv = basic_sum(kJmax, kJmax, kJmax / r, kInfinite, alpha, d) / (z0 * z0 * kJmax);
    }
  } else if (alpha == 1) {  // case 3: unmodified, flicker PM
    const A01 t3 = kTable3[static_cast<std::size_t>(d - 1)];
    const Real b = t3.a0 + t3.a1 * std::log(mr);
    if (j_terms <= kJmax) {
      inv = direct(mr);
    } else if (r > d + 1) {
      inv = (t2.a0 - t2.a1 / r) / (b * b * r);
    } else {
      const Real mp = kJmax / r;
      inv = basic_sum(kJmax, kJmax, mp, mp, 1, d) / (b * b * kJmax);
    }
  } else {  // case 4: unmodified, white PM
    if (std::ceil(r) > d) {
      const Real a0 = binomial(4 * d, 2 * d) / std::pow(binomial(2 * d, d), 2);
      const Real a1 = d / 2.0L;
      inv = (a0 - a1 / r) / m_terms;
    } else {
      inv = direct(mr);  // very few terms: the exact sum is short
    }
  }
  if (!(inv > 0)) return 0;
  return static_cast<double>(1 / inv);
}

double edf_for(Estimator est, int alpha, std::int64_t m, std::size_t n_phase) {
  switch (est) {
    case Estimator::Overlapping: return edf_greenhall(alpha, 2, m, n_phase, true, false);
    case Estimator::NonOverlapping: return edf_greenhall(alpha, 2, m, n_phase, false, false);
    case Estimator::Modified: return edf_greenhall(alpha, 2, m, n_phase, true, true);
    case Estimator::OverlappingHadamard: return edf_greenhall(alpha, 3, m, n_phase, true, false);
    case Estimator::NonOverlappingHadamard: return edf_greenhall(alpha, 3, m, n_phase, false, false);
  }
  return 0;
}

DevInterval chi2_interval(double var, double edf, double p) {
  if (!(p > 0 && p < 1)) throw UsageError(trf("confidence must lie strictly between 0 and 1, got {}", p));
  if (!(edf > 0) || !(var >= 0)) return {0.0, 0.0};
  const boost::math::chi_squared dist(edf);
  const double chi_hi = boost::math::quantile(dist, 0.5 * (1 + p));
  const double chi_lo = boost::math::quantile(dist, 0.5 * (1 - p));
  return {std::sqrt(edf * var / chi_hi), std::sqrt(edf * var / chi_lo)};
}

}  // namespace rwcalc
