// Noise identification (lag-1 autocorrelation, B1 and R(n) ratios), Greenhall–Riley EDF and
// χ² confidence bounds, following Stable32's choices so that its tables are reproduced.
#include "rwcalc/confidence.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "allan/noise_id.hpp"
#include "allan/x86_dispatch.hpp"
#include "rwcalc/crew.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/thread.hpp"

namespace rwcalc {

namespace {

// ---- Noise identification -------------------------------------------------------------------

// Stable32 uses the lag-1 autocorrelation when at least this many points remain at τ.
constexpr std::size_t kMinAcfPoints = 30;
constexpr int kMaxDifferences = 2;  // d_max for Allan-type (two-sample) variances

/// Decimated phase p_k = x_{k·m} − x_0, k = 0 … ⌊(N−1)/m⌋, in arbitrary units (the ACF and the
/// B1 ratio do not depend on scale); offset-free and exact for counts.
std::vector<double> decimated_phase(const PhaseSeries& x, std::int64_t m) {
  const auto um = static_cast<std::size_t>(m);
  const std::size_t count = (x.points() - 1) / um + 1;
  std::vector<double> z(count);
  if (x.exact()) {
    const auto c0 = static_cast<std::uint64_t>(x.count(0));
    for (std::size_t k = 0; k < count; ++k)
      z[k] = static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(x.count(k * um)) - c0));
  } else {
    const double* v = x.values.data();
    for (std::size_t k = 0; k < count; ++k) z[k] = v[k * um] - v[0];
  }
  return z;
}

/// Averaged frequencies ȳ_k ∝ p_{k+1} − p_k (k < ⌊(N−1)/m⌋), same arbitrary units.
std::vector<double> averaged_frequency(const PhaseSeries& x, std::int64_t m) {
  std::vector<double> y = decimated_phase(x, m);
  for (std::size_t i = 0; i + 1 < y.size(); ++i) y[i] = y[i + 1] - y[i];
  y.pop_back();
  return y;
}

/// Value i of the level-th difference of p (level 0: p itself); p(i) gives the decimated phase.
template <class P>
inline __attribute__((always_inline)) double difference(const P& p, int level, std::size_t i) {
  switch (level) {
    case 0: return p(i);
    case 1: return p(i + 1) - p(i);
    case 2: return (p(i + 2) - p(i + 1)) - (p(i + 1) - p(i));
    default: return ((p(i + 3) - p(i + 2)) - (p(i + 2) - p(i + 1))) - ((p(i + 2) - p(i + 1)) - (p(i + 1) - p(i)));
  }
}

/// Lag-1 autocorrelation r1 = Σ(z_i − z̄)(z_{i+1} − z̄) / Σ(z_i − z̄)² (Riley & Greenhall eq. 2) of
/// the Level-th difference z of the `count` decimated phase points p(0) … p(count − 1), without
/// forming z or p: the mean of a difference follows from its end points, and the sums run in four
/// independent lanes (branch-free, vectorisable).
template <int Level, class P>
double lag1_autocorrelation(const P& p, std::size_t count) {
  if (count <= static_cast<std::size_t>(Level) + 1) return 0.0;
  const std::size_t len = count - static_cast<std::size_t>(Level);  // points of z
  double mean = 0;
  if constexpr (Level == 0) {
    double lane[4] = {};
    std::size_t i = 0;
    for (; i + 4 <= len; i += 4)
      for (int j = 0; j < 4; ++j) lane[j] += p(i + static_cast<std::size_t>(j));
    for (; i < len; ++i) lane[0] += p(i);
    mean = (lane[0] + lane[1] + lane[2] + lane[3]) / static_cast<double>(len);
  } else {
    mean = (difference(p, Level - 1, len) - difference(p, Level - 1, 0)) / static_cast<double>(len);
  }
  double num[4] = {}, den[4] = {};
  std::size_t i = 0;
  // Pairs (z_i, z_{i+1}) for i < len − 1; den over all i < len.
  for (; i + 4 < len; i += 4) {
    for (int j = 0; j < 4; ++j) {
      const auto k = i + static_cast<std::size_t>(j);
      const double a = difference(p, Level, k) - mean;
      const double b = difference(p, Level, k + 1) - mean;
      den[j] += a * a;
      num[j] += a * b;
    }
  }
  for (; i < len; ++i) {
    const double a = difference(p, Level, i) - mean;
    den[0] += a * a;
    if (i + 1 < len) num[0] += a * (difference(p, Level, i + 1) - mean);
  }
  const double n_sum = num[0] + num[1] + num[2] + num[3];
  const double d_sum = den[0] + den[1] + den[2] + den[3];
  return d_sum > 0 ? n_sum / d_sum : 0.0;
}

template <class P>
double lag1_autocorrelation(const P& p, std::size_t count, int level) {
  switch (level) {
    case 0: return lag1_autocorrelation<0>(p, count);
    case 1: return lag1_autocorrelation<1>(p, count);
    case 2: return lag1_autocorrelation<2>(p, count);
    default: return lag1_autocorrelation<3>(p, count);
  }
}

/// Lag-1 ACF method on the decimated phase p, starting at difference level `base` (0: phase data,
/// 1: frequency data): difference until δ = r1/(1 + r1) < 0.25 or d = d_max; p = −round(2δ) − 2d.
/// Returns p, the exponent of the analysed series' own spectrum.
template <class P>
int acf_exponent(const P& phase, std::size_t count, int base) {
  for (int d = 0;; ++d) {
    const double r1 = lag1_autocorrelation(phase, count, base + d);
    const double delta = r1 / (1.0 + r1);
    if (delta < 0.25 || d >= kMaxDifferences) return -static_cast<int>(std::lround(2.0 * delta)) - 2 * d;
  }
}

// ---- Floating lag-1 sums on the int32 view (offsets of 2^24 or more) -------------------------

#if defined(__x86_64__) || defined(__i386__)
// p(from) … p(from + n − 1) as doubles into w (stride 1: eight conversions per instruction).
__attribute__((target("avx2"))) void load_decimated(const std::int32_t* rel32, std::size_t stride, std::size_t from,
                                                    std::size_t n, double* w) {
  std::size_t t = 0;
  if (stride == 1) {
    for (; t + 4 <= n; t += 4)
      _mm256_storeu_pd(w + t, _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(rel32 + from + t))));
  }
  for (; t < n; ++t) w[t] = static_cast<double>(rel32[(from + t) * stride]);
}

// z_L(k) … z_L(k + 3), the level-L difference of the decimated phase at w[o] … (integers: exact).
template <int L>
__attribute__((target("avx2"), always_inline)) inline __m256d zvec(const double* w, std::size_t o) {
  if constexpr (L == 0)
    return _mm256_loadu_pd(w + o);
  else
    return _mm256_sub_pd(zvec<L - 1>(w, o + 1), zvec<L - 1>(w, o));
}

// Running lag-1 sums of one difference level in the scalar code's four lanes.
struct Lag1Sums {
  __m256d num, den, mean;
};

template <int L>
__attribute__((target("avx2"), always_inline)) inline void lag1_step(const double* w, Lag1Sums& s) {
  const __m256d a = _mm256_sub_pd(zvec<L>(w, 0), s.mean);
  const __m256d b = _mm256_sub_pd(zvec<L>(w, 1), s.mean);
  s.den = _mm256_add_pd(s.den, _mm256_mul_pd(a, a));
  s.num = _mm256_add_pd(s.num, _mm256_mul_pd(a, b));
}

// lag1_autocorrelation<L> (and, with Pair, lag1_autocorrelation<L + 1> in the same pass over the
// data) on the int32 view, four z values per instruction. Lane j takes the terms k ≡ j (mod 4) in
// the order the scalar loop's lanes do, the differences of integers are exact in double whatever
// the order, and products and sums are separate roundings (no fused multiply-add), so each r1 is
// the scalar one bit for bit. p(k) = rel32[k·stride].
template <int L, bool Pair>
__attribute__((target("avx2"))) void lag1_rel32_avx2(const std::int32_t* rel32, std::size_t stride, std::size_t count,
                                                     double r[2]) {
  auto p = [rel32, stride](std::size_t k) { return static_cast<double>(rel32[k * stride]); };
  constexpr int kLevels = Pair ? 2 : 1;
  r[0] = r[1] = 0.0;
  // The decimated phase goes through a small buffer, a chunk at a time (each value converted once).
  constexpr std::size_t kChunk = 2048;  // a multiple of 4: the lanes keep k ≡ j (mod 4)
  constexpr std::size_t kExtra = static_cast<std::size_t>(L) + 6;
  alignas(32) double buf[kChunk + kExtra + 3];
  double mean[2] = {0, 0};
  std::size_t len[2] = {0, 0};
  for (int q = 0; q < kLevels; ++q) {
    const int lev = L + q;
    if (count <= static_cast<std::size_t>(lev) + 1) return;  // as the scalar code: r1 = 0 (Pair: never here)
    len[q] = count - static_cast<std::size_t>(lev);
  }
  if constexpr (L == 0) {
    __m256d lane = _mm256_setzero_pd();
    std::size_t i = 0;
    while (i + 4 <= len[0]) {
      const std::size_t stop = std::min(i + kChunk, len[0]) & ~std::size_t{3};
      load_decimated(rel32, stride, i, stop - i, buf);
      for (std::size_t t = 0; i < stop; i += 4, t += 4) lane = _mm256_add_pd(lane, _mm256_loadu_pd(buf + t));
    }
    alignas(32) double l[4];
    _mm256_store_pd(l, lane);
    for (; i < len[0]; ++i) l[0] += p(i);
    mean[0] = (l[0] + l[1] + l[2] + l[3]) / static_cast<double>(len[0]);
  } else {
    mean[0] = (difference(p, L - 1, len[0]) - difference(p, L - 1, 0)) / static_cast<double>(len[0]);
  }
  if constexpr (Pair) mean[1] = (difference(p, L, len[1]) - difference(p, L, 0)) / static_cast<double>(len[1]);
  Lag1Sums s0{_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_set1_pd(mean[0])};
  Lag1Sums s1{_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_set1_pd(mean[1])};
  // Vector iterations i (multiples of 4) with i + 4 < len[q]; with Pair, both levels while the
  // shorter one lasts, then at most one more for level L alone.
  std::size_t i = 0;
  const std::size_t both = Pair ? len[1] : len[0];
  while (i + 4 < len[0]) {
    const std::size_t i0 = i;
    load_decimated(rel32, stride, i0, std::min(kChunk + kExtra, count - i0), buf);
    for (; i + 4 < both && i < i0 + kChunk; i += 4) {
      lag1_step<L>(buf + (i - i0), s0);
      if constexpr (Pair) lag1_step<L + 1>(buf + (i - i0), s1);
    }
    if (i + 4 < both) continue;  // the chunk ended, the loop did not
    for (; i + 4 < len[0] && i < i0 + kChunk; i += 4) lag1_step<L>(buf + (i - i0), s0);
    if (i + 4 < len[0]) continue;
    break;
  }
  const std::size_t i_end[2] = {i, Pair ? std::min(i, len[1] > 4 ? ((len[1] - 5) / 4 + 1) * 4 : 0) : 0};
  for (int q = 0; q < kLevels; ++q) {
    const Lag1Sums& sq = q == 0 ? s0 : s1;
    alignas(32) double nu[4], de[4];
    _mm256_store_pd(nu, sq.num);
    _mm256_store_pd(de, sq.den);
    const int lev = L + q;
    for (std::size_t k = i_end[q]; k < len[q]; ++k) {
      const double a = difference(p, lev, k) - mean[q];
      de[0] += a * a;
      if (k + 1 < len[q]) nu[0] += a * (difference(p, lev, k + 1) - mean[q]);
    }
    const double n_sum = nu[0] + nu[1] + nu[2] + nu[3];
    const double d_sum = de[0] + de[1] + de[2] + de[3];
    r[q] = d_sum > 0 ? n_sum / d_sum : 0.0;
  }
}

/// acf_exponent() on the int32 view with the AVX2 floating sums (same result bit for bit), for
/// views whose offsets reach 2^24 (the exact vector kernel needs them below). A level that
/// may be followed by the next has both computed in one pass over the data.
int acf_exponent_rel32_avx2(const std::int32_t* rel32, std::size_t stride, std::size_t count, int base) {
  double next = 0;  // r1 of level base + d, when computed with the previous level
  bool have_next = false;
  for (int d = 0;; ++d) {
    const int level = base + d;
    double r1 = 0;
    if (have_next) {
      r1 = next;
      have_next = false;
    } else {
      double r[2];
      const bool pair = d < kMaxDifferences && level < 3 && count > static_cast<std::size_t>(level) + 16;
      switch (level * 2 + (pair ? 1 : 0)) {
        case 0: lag1_rel32_avx2<0, false>(rel32, stride, count, r); break;
        case 1: lag1_rel32_avx2<0, true>(rel32, stride, count, r); break;
        case 2: lag1_rel32_avx2<1, false>(rel32, stride, count, r); break;
        case 3: lag1_rel32_avx2<1, true>(rel32, stride, count, r); break;
        case 4: lag1_rel32_avx2<2, false>(rel32, stride, count, r); break;
        case 5: lag1_rel32_avx2<2, true>(rel32, stride, count, r); break;
        default: lag1_rel32_avx2<3, false>(rel32, stride, count, r); break;
      }
      r1 = r[0];
      next = r[1];
      have_next = pair;
    }
    const double delta = r1 / (1.0 + r1);
    if (delta < 0.25 || d >= kMaxDifferences) return -static_cast<int>(std::lround(2.0 * delta)) - 2 * d;
  }
}
#endif

// ---- Exact integer lag-1 sums on the int32 view ----------------------------------------------
//
// On the int32 view of exact counts the level-L differences z are integers, so Σz, Σz² and
// Σz_k·z_{k+1} are taken exactly (int64 lanes, flushed into 128-bit totals) in any order, and r1 is
// formed once from them: only its final conversion rounds. The result therefore does not depend
// on the order of the sums (vector lanes, chunks, tails, AVX2 or not), and differs from the
// floating two-pass sum of lag1_autocorrelation() by that sum's rounding only.

__extension__ typedef __int128 i128;

/// Exact sums over z_0 … z_{len−1} of one difference level.
struct ExactLag1 {
  i128 s1 = 0;   // Σ z_k
  i128 s2 = 0;   // Σ z_k²
  i128 lag = 0;  // Σ z_k·z_{k+1}, k < len − 1
};

/// The view has fewer points than this: every total below stays inside 128 bits even for
/// |z| < 2^34 (level 3 of any int32 offset); longer records take the floating sums.
constexpr std::size_t kExactMaxPoints = std::size_t{1} << 28;

/// The cluster sizes up to this one take their first two levels from the start pass.
constexpr std::int64_t kStartPassMaxM = 256;

/// z_L(k) of p as an integer (|p| < 2^31: no overflow for L ≤ 3).
template <class P>
inline std::int64_t idiff(const P& p, int level, std::size_t k) {
  switch (level) {
    case 0: return p(k);
    case 1: return p(k + 1) - p(k);
    case 2: return p(k + 2) - 2 * p(k + 1) + p(k);
    default: return p(k + 3) - 3 * p(k + 2) + 3 * p(k + 1) - p(k);
  }
}

/// r1 = Σ(z_k − z̄)(z_{k+1} − z̄) / Σ(z_k − z̄)² from the exact sums, with z̄ = S1/n:
/// n·num = U − S1²/n, U = n·Slag − S1² + S1·(z_0 + z_{n−1});  n·den = n·S2 − S1²
/// (integers but for the fraction of S1²/n, which is added last).
double r1_from_exact(const ExactLag1& s, std::size_t len, std::int64_t z_first, std::int64_t z_last) {
  const auto n = static_cast<i128>(len);
  const i128 s1sq = s.s1 * s.s1;
  const i128 den = n * s.s2 - s1sq;
  if (den <= 0) return 0.0;
  const i128 u = n * s.lag - s1sq + s.s1 * (static_cast<i128>(z_first) + z_last);
  const i128 q = s1sq / n;
  const i128 rem = s1sq % n;
  const long double num =
      static_cast<long double>(u - q) - static_cast<long double>(rem) / static_cast<long double>(len);
  return static_cast<double>(num / static_cast<long double>(den));
}

/// Adds the terms k ∈ [from, len) of level `level` to s (lag terms for k + 1 < len). small: every
/// |p| < 2^24, so |z| < 2^27 and 256 terms of each sum stay inside int64 between flushes.
void exact_terms(const std::int32_t* rel32, std::size_t stride, int level, std::size_t from, std::size_t len,
                 ExactLag1& s, bool small = false) {
  auto p = [rel32, stride](std::size_t k) { return static_cast<std::int64_t>(rel32[k * stride]); };
  if (small) {
    std::size_t k = from;
    while (k + 1 < len) {
      const std::size_t stop = std::min(len - 1, k + 256);
      std::int64_t s1 = 0, s2 = 0, lag = 0;
      std::int64_t z = idiff(p, level, k);
      for (; k < stop; ++k) {
        const std::int64_t zn = idiff(p, level, k + 1);
        s1 += z;
        s2 += z * z;
        lag += z * zn;
        z = zn;
      }
      s.s1 += s1;
      s.s2 += s2;
      s.lag += lag;
    }
    if (k < len) {  // the last term: no lag product
      const std::int64_t z = idiff(p, level, k);
      s.s1 += z;
      s.s2 += static_cast<i128>(z) * z;
    }
    return;
  }
  for (std::size_t k = from; k < len; ++k) {
    const std::int64_t z = idiff(p, level, k);
    s.s1 += z;
    s.s2 += static_cast<i128>(z) * z;
    if (k + 1 < len) s.lag += static_cast<i128>(z) * idiff(p, level, k + 1);
  }
}

double r1_exact_finish(const std::int32_t* rel32, std::size_t stride, int level, std::size_t len,
                       const ExactLag1& s) {
  auto p = [rel32, stride](std::size_t k) { return static_cast<std::int64_t>(rel32[k * stride]); };
  return r1_from_exact(s, len, idiff(p, level, 0), idiff(p, level, len - 1));
}

/// r1 of level `level` with the exact sums, one term at a time (the portable path).
double lag1_exact_scalar(const std::int32_t* rel32, std::size_t stride, std::size_t count, int level,
                         bool small = false) {
  if (count <= static_cast<std::size_t>(level) + 1) return 0.0;
  const std::size_t len = count - static_cast<std::size_t>(level);
  ExactLag1 s;
  exact_terms(rel32, stride, level, 0, len, s, small);
  return r1_exact_finish(rel32, stride, level, len, s);
}

#if defined(__x86_64__) || defined(__i386__)
// z_L(k) … z_L(k + 3) of the int32 values at w[o] … as int64 lanes.
template <int L>
__attribute__((target("avx2"), always_inline)) inline __m256i izvec(const std::int32_t* w, std::size_t o) {
  if constexpr (L == 0)
    return _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(w + o)));
  else
    return _mm256_sub_epi64(izvec<L - 1>(w, o + 1), izvec<L - 1>(w, o));
}

struct ExactLanes {
  __m256i s1, s2, lag;
};

// One vector step: terms k … k + 3 (z_{k+4} read for the last lag product). _mm256_mul_epi32
// multiplies the low 32 bits of each lane as signed: exact while |z| < 2^31.
template <int L>
__attribute__((target("avx2"), always_inline)) inline void exact_step(const std::int32_t* w, ExactLanes& a) {
  const __m256i z = izvec<L>(w, 0);
  const __m256i zn = izvec<L>(w, 1);
  a.s1 = _mm256_add_epi64(a.s1, z);
  a.s2 = _mm256_add_epi64(a.s2, _mm256_mul_epi32(z, z));
  a.lag = _mm256_add_epi64(a.lag, _mm256_mul_epi32(z, zn));
}

__attribute__((target("avx2"))) inline void exact_flush(const ExactLanes& a, ExactLag1& s) {
  alignas(32) std::int64_t l[3][4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(l[0]), a.s1);
  _mm256_store_si256(reinterpret_cast<__m256i*>(l[1]), a.s2);
  _mm256_store_si256(reinterpret_cast<__m256i*>(l[2]), a.lag);
  for (int j = 0; j < 4; ++j) {
    s.s1 += l[0][j];
    s.s2 += l[1][j];
    s.lag += l[2][j];
  }
}

// Vector steps of the exact sums of level L (and, with Pair, of level L + 1) at the positions
// i ∈ {from, from + 4, …} below `to`, each adding the terms k = i … i + 3 to s; requires
// to ≤ vlen − 4 (vlen: the points of the highest level summed), so that every z_{k+1} exists.
// Four int64 lanes per instruction. Requires every |p| < 2^24 (PreparedCounts::small24): then
// |z| < 2^27 for L ≤ 3, each product < 2^54, and a chunk of 256 steps per lane stays below 2^63.
// Returns the first position not taken.
template <int L, bool Pair>
__attribute__((target("avx2"))) std::size_t lag1_exact_steps_avx2(const std::int32_t* rel32, std::size_t stride,
                                                                  std::size_t count, std::size_t from,
                                                                  std::size_t to, ExactLag1 s[2]) {
  constexpr std::size_t kChunk = 1024;  // 256 steps: one flush per chunk
  alignas(32) std::int32_t buf[kChunk + L + 8];
  std::size_t i = from;
  while (i < to) {
    const std::int32_t* w = rel32 + i;
    if (stride != 1) {  // the decimated phase into the buffer (each value read once), eight per gather
      const std::size_t n = std::min(kChunk + L + 6, count - i);
      const std::int32_t* base = rel32 + i * stride;
      const __m256i step = _mm256_set1_epi32(static_cast<std::int32_t>(8 * stride));
      __m256i idx = _mm256_mullo_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
                                       _mm256_set1_epi32(static_cast<std::int32_t>(stride)));
      std::size_t t = 0;
      if (stride < (std::size_t{1} << 20))  // the int32 indices (t·stride, t < 1040) do not overflow
        for (; t + 8 <= n; t += 8, idx = _mm256_add_epi32(idx, step))
          _mm256_store_si256(reinterpret_cast<__m256i*>(buf + t), _mm256_i32gather_epi32(base, idx, 4));
      for (; t < n; ++t) buf[t] = base[t * stride];
      w = buf;
    }
    ExactLanes a0{_mm256_setzero_si256(), _mm256_setzero_si256(), _mm256_setzero_si256()};
    ExactLanes a1 = a0;
    const std::size_t i0 = i;
    for (; i < to && i < i0 + kChunk; i += 4) {
      exact_step<L>(w + (i - i0), a0);
      if constexpr (Pair) exact_step<L + 1>(w + (i - i0), a1);
    }
    exact_flush(a0, s[0]);
    if constexpr (Pair) exact_flush(a1, s[1]);
  }
  return i;
}

// The same with AVX-512: eight int64 lanes, positions i ∈ {from, from + 8, …} below `to`, each
// step adding the terms k = i … i + 7; requires to ≤ vlen − 8. A chunk gives a lane 128 steps.
RWCALC_AVX512_WARNINGS_OFF
template <int L>
__attribute__((target("avx512f"), always_inline)) inline __m512i izvec512(const std::int32_t* w, std::size_t o) {
  if constexpr (L == 0)
    return _mm512_cvtepi32_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(w + o)));
  else
    return _mm512_sub_epi64(izvec512<L - 1>(w, o + 1), izvec512<L - 1>(w, o));
}

struct ExactLanes512 {
  __m512i s1, s2, lag;
};

template <int L>
__attribute__((target("avx512f"), always_inline)) inline void exact_step512(const std::int32_t* w, ExactLanes512& a) {
  const __m512i z = izvec512<L>(w, 0);
  const __m512i zn = izvec512<L>(w, 1);
  a.s1 = _mm512_add_epi64(a.s1, z);
  a.s2 = _mm512_add_epi64(a.s2, _mm512_mul_epi32(z, z));
  a.lag = _mm512_add_epi64(a.lag, _mm512_mul_epi32(z, zn));
}

// Each lane into the 128-bit totals on its own (eight lanes of up to 2^61 could pass 2^63 together).
__attribute__((target("avx512f"))) inline void exact_flush512(const ExactLanes512& a, ExactLag1& s) {
  alignas(64) std::int64_t l[3][8];
  _mm512_store_si512(l[0], a.s1);
  _mm512_store_si512(l[1], a.s2);
  _mm512_store_si512(l[2], a.lag);
  for (int j = 0; j < 8; ++j) {
    s.s1 += l[0][j];
    s.s2 += l[1][j];
    s.lag += l[2][j];
  }
}

template <int L, bool Pair>
__attribute__((target("avx512f"))) std::size_t lag1_exact_steps_avx512(const std::int32_t* rel32, std::size_t stride,
                                                                       std::size_t count, std::size_t from,
                                                                       std::size_t to, ExactLag1 s[2]) {
  constexpr std::size_t kChunk = 1024;  // 128 steps: one flush per chunk
  alignas(64) std::int32_t buf[kChunk + L + 16];
  std::size_t i = from;
  while (i < to) {
    const std::int32_t* w = rel32 + i;
    if (stride != 1) {  // the decimated phase into the buffer, sixteen per gather
      const std::size_t n = std::min(kChunk + L + 10, count - i);
      const std::int32_t* base = rel32 + i * stride;
      const __m512i step = _mm512_set1_epi32(static_cast<std::int32_t>(16 * stride));
      __m512i idx = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                       _mm512_set1_epi32(static_cast<std::int32_t>(stride)));
      std::size_t t = 0;
      if (stride < (std::size_t{1} << 20))  // the int32 indices (t·stride, t < 1050) do not overflow
        for (; t + 16 <= n; t += 16, idx = _mm512_add_epi32(idx, step))
          _mm512_store_si512(buf + t, _mm512_i32gather_epi32(idx, base, 4));
      for (; t < n; ++t) buf[t] = base[t * stride];
      w = buf;
    }
    ExactLanes512 a0{_mm512_setzero_si512(), _mm512_setzero_si512(), _mm512_setzero_si512()};
    ExactLanes512 a1 = a0;
    const std::size_t i0 = i;
    for (; i < to && i < i0 + kChunk; i += 8) {
      exact_step512<L>(w + (i - i0), a0);
      if constexpr (Pair) exact_step512<L + 1>(w + (i - i0), a1);
    }
    exact_flush512(a0, s[0]);
    if constexpr (Pair) exact_flush512(a1, s[1]);
  }
  return i;
}
RWCALC_AVX512_WARNINGS_ON

// Points of level L and the end of the vector steps of width W (0: none), for `count` phase points.
template <int L, bool Pair, std::size_t W = 4>
std::size_t vector_end(std::size_t count) {
  const std::size_t vlen = count - static_cast<std::size_t>(L + (Pair ? 1 : 0));
  return vlen > W ? vlen - W : 0;
}

// The scalar tail from `covered` and r1 of each level.
template <int L, bool Pair>
void lag1_exact_tail(const std::int32_t* rel32, std::size_t stride, std::size_t count, std::size_t covered,
                     ExactLag1 s[2], double r[2]) {
  for (int q = 0; q < (Pair ? 2 : 1); ++q) {
    const std::size_t len = count - static_cast<std::size_t>(L + q);
    exact_terms(rel32, stride, L + q, covered, len, s[q]);
    r[q] = r1_exact_finish(rel32, stride, L + q, len, s[q]);
  }
}

// r1 of level L (and, with Pair, of level L + 1 in the same pass over the data) with the exact
// sums in AVX2.
template <int L, bool Pair>
__attribute__((target("avx2"))) void lag1_exact_avx2(const std::int32_t* rel32, std::size_t stride,
                                                     std::size_t count, double r[2]) {
  r[0] = r[1] = 0.0;
  if (count <= static_cast<std::size_t>(L) + 1) return;  // r1 = 0: no pair of points at level L
  if (Pair && count <= static_cast<std::size_t>(L) + 2) {  // none at level L + 1 (r[1] = 0)
    r[0] = lag1_exact_scalar(rel32, stride, count, L);
    return;
  }
  ExactLag1 s[2];
  const std::size_t covered = lag1_exact_steps_avx2<L, Pair>(rel32, stride, count, 0, vector_end<L, Pair>(count), s);
  lag1_exact_tail<L, Pair>(rel32, stride, count, covered, s, r);
}

// r1 of `level` (and of level + 1 into r[1] when pair) on the view, exact sums in AVX2.
void lag1_exact_avx2_at(const std::int32_t* rel32, std::size_t stride, std::size_t count, int level, bool pair,
                        double r[2]) {
  switch (level * 2 + (pair ? 1 : 0)) {
    case 0: lag1_exact_avx2<0, false>(rel32, stride, count, r); break;
    case 1: lag1_exact_avx2<0, true>(rel32, stride, count, r); break;
    case 2: lag1_exact_avx2<1, false>(rel32, stride, count, r); break;
    case 3: lag1_exact_avx2<1, true>(rel32, stride, count, r); break;
    case 4: lag1_exact_avx2<2, false>(rel32, stride, count, r); break;
    case 5: lag1_exact_avx2<2, true>(rel32, stride, count, r); break;
    default: lag1_exact_avx2<3, false>(rel32, stride, count, r); break;
  }
}

// The start pass (detail::lag1_start_pass) of one thread: the vector steps of every stride j at
// positions [lo[j], hi[j]), walking the view in blocks so that all strides read a block while it
// is in the core's cache.
template <int L, std::size_t W>
__attribute__((target("avx2"))) void lag1_start_part(const std::int32_t* rel32, std::size_t b_lo, std::size_t b_hi,
                                                     const std::vector<std::size_t>& stride,
                                                     const std::vector<std::size_t>& count,
                                                     const std::vector<std::size_t>& lo,
                                                     const std::vector<std::size_t>& hi, ExactLag1* s) {
  constexpr std::size_t kBlock = 16384;  // 64 KB of the view
  std::vector<std::size_t> pos = lo;
  for (std::size_t b0 = b_lo; b0 < b_hi; b0 += kBlock) {
    const std::size_t b1 = std::min(b_hi, b0 + kBlock);
    for (std::size_t j = 0; j < stride.size(); ++j) {
      const std::size_t kb = std::min(hi[j], (b1 + stride[j] - 1) / stride[j]);
      if (pos[j] >= kb) continue;
      if constexpr (W == 8)
        pos[j] = lag1_exact_steps_avx512<L, true>(rel32, stride[j], count[j], pos[j], kb, s + 2 * j);
      else
        pos[j] = lag1_exact_steps_avx2<L, true>(rel32, stride[j], count[j], pos[j], kb, s + 2 * j);
    }
  }
}

template <int L, std::size_t W>
void lag1_start_pass_impl(const std::int32_t* rel32, std::size_t points, const std::vector<std::size_t>& stride,
                          const std::vector<std::size_t>& count, unsigned threads, Crew* crew,
                          std::vector<double>& r) {
  const std::size_t n = stride.size();
  std::vector<std::size_t> vend(n);
  for (std::size_t j = 0; j < n; ++j) vend[j] = vector_end<L, true, W>(count[j]);
  // The view in parts: halves on two threads, or stretches that a crew's threads take as they
  // are free. Part c reads the view from edge(c) and takes the steps of stride j from bound(c, j)
  // to bound(c + 1, j) (multiples of W, so every part keeps the positions 0, W, 2W, …); the sums
  // are exact, so the split changes no bit.
  constexpr std::size_t kStretch = std::size_t{1} << 16;
  const std::size_t parts = crew ? std::max<std::size_t>(1, (points + kStretch - 1) / kStretch) : threads > 1 ? 2 : 1;
  auto edge = [&](std::size_t c) { return c >= parts ? points : crew ? c * kStretch : points / 2 * c; };
  auto bound = [&](std::size_t c, std::size_t j) -> std::size_t {
    if (c == 0) return 0;
    if (c >= parts) return vend[j];
    return std::min(vend[j], ((edge(c) + stride[j] - 1) / stride[j]) & ~(W - 1));
  };
  std::vector<ExactLag1> sums(parts * 2 * n);
  auto run_part = [&](std::size_t c) {
    std::vector<std::size_t> lo(n), hi(n);
    for (std::size_t j = 0; j < n; ++j) {
      lo[j] = bound(c, j);
      hi[j] = bound(c + 1, j);
    }
    lag1_start_part<L, W>(rel32, edge(c), edge(c + 1), stride, count, lo, hi, sums.data() + c * 2 * n);
  };
  if (crew) {
    crew->share(parts, run_part);
  } else if (parts == 2) {
    Thread second([&] { run_part(1); });
    run_part(0);
  } else {
    run_part(0);
  }
  r.assign(2 * n, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    ExactLag1 s[2];
    for (std::size_t c = 0; c < parts; ++c)
      for (int q = 0; q < 2; ++q) {
        const ExactLag1& part = sums[c * 2 * n + 2 * j + static_cast<std::size_t>(q)];
        s[q].s1 += part.s1;
        s[q].s2 += part.s2;
        s[q].lag += part.lag;
      }
    const std::size_t covered = (vend[j] + W - 1) & ~(W - 1);  // the terms of the steps 0, W, …
    lag1_exact_tail<L, true>(rel32, stride[j], count[j], covered, s, &r[2 * j]);
  }
}
#endif

/// The ACF method (see acf_exponent) on the int32 view with the exact sums; with AVX2 and
/// small24, a level that may be followed by the next has both computed in one pass.
int acf_exponent_exact(const std::int32_t* rel32, std::size_t stride, std::size_t count, int base, bool small24,
                       const double* start) {
#if defined(__x86_64__) || defined(__i386__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  const bool vector = avx2 && small24;
#else
  const bool vector = false;
  (void)small24;
#endif
  double next = 0;  // r1 of level base + d, when computed with the previous level
  bool have_next = false;
  for (int d = 0;; ++d) {
    const int level = base + d;
    double r1 = 0;
    if (start && d < 2) {  // levels base and base + 1 from the start pass
      r1 = start[d];
    } else if (have_next) {
      r1 = next;
      have_next = false;
    } else if (vector) {
#if defined(__x86_64__) || defined(__i386__)
      double r[2];
      const bool pair = d < kMaxDifferences && level < 3 && count > static_cast<std::size_t>(level) + 16;
      lag1_exact_avx2_at(rel32, stride, count, level, pair, r);
      r1 = r[0];
      next = r[1];
      have_next = pair;
#endif
    } else {
      r1 = lag1_exact_scalar(rel32, stride, count, level, small24);
    }
    const double delta = r1 / (1.0 + r1);
    if (delta < 0.25 || d >= kMaxDifferences) return -static_cast<int>(std::lround(2.0 * delta)) - 2 * d;
  }
}

/// The ACF method on the phase decimated by m, read in place (no copy): p(k) = x_{k·m} − x_0 as
/// decimated_phase() forms it; on the int32 view with the exact integer sums.
int acf_exponent_at(const PhaseSeries& x, std::int64_t m, std::size_t count, int base, const std::int32_t* rel32,
                    bool small24, const double* start) {
  const auto um = static_cast<std::size_t>(m);
  if (rel32 && x.points() < kExactMaxPoints && small24) return acf_exponent_exact(rel32, um, count, base, true, start);
#if defined(__x86_64__) || defined(__i386__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (rel32 && avx2) return acf_exponent_rel32_avx2(rel32, um, count, base);
#endif
  if (rel32) {
    if (um == 1) return acf_exponent([rel32](std::size_t k) { return static_cast<double>(rel32[k]); }, count, base);
    return acf_exponent([rel32, um](std::size_t k) { return static_cast<double>(rel32[k * um]); }, count, base);
  }
  if (x.exact()) {
    const auto c0 = static_cast<std::uint64_t>(x.count(0));
    return acf_exponent(
        [&x, c0, um](std::size_t k) {
          return static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(x.count(k * um)) - c0));
        },
        count, base);
  }
  const double* v = x.values.data();
  return acf_exponent([v, um](std::size_t k) { return v[k * um] - v[0]; }, count, base);
}

/// Expected B1 = (standard variance)/(Allan variance) for N averages and phase exponent μ
/// (Howe, Beard, Greenhall & Riley, PTTI 2000, Table 3). μ = 2 … −2 ↔ α = −3 … +1/+2.
double b1_expected(double n, int mu) {
  switch (mu) {
    case 2: return n * (n + 1.0) / 6.0;
    case 1: return n / 2.0;
    case 0: return n * std::log(n) / (2.0 * (n - 1.0) * std::numbers::ln2);
    case -1: return 1.0;
    case -2: return (n * n - 1.0) / (1.5 * n * (n - 1.0));
    default: return n * (1.0 - std::pow(n, mu)) / (2.0 * (n - 1.0) * (1.0 - std::pow(2.0, mu)));
  }
}

/// μ from a measured B1: the largest μ whose boundary with μ − 1 the ratio exceeds. Boundaries are
/// geometric means of neighbouring expectations, except the arithmetic mean between μ = 2 and 1.
int b1_mu(double measured, double n) {
  for (int mu = 2; mu > -2; --mu) {
    const double hi = b1_expected(n, mu), lo = b1_expected(n, mu - 1);
    const double boundary = mu == 2 ? 0.5 * (hi + lo) : std::sqrt(hi * lo);
    if (measured > boundary) return mu;
  }
  return -2;
}

double sample_variance(const std::vector<double>& y) {
  double mean = 0;
  for (double v : y) mean += v;
  mean /= static_cast<double>(y.size());
  double s = 0;
  for (double v : y) s += (v - mean) * (v - mean);
  return s / static_cast<double>(y.size() - 1);
}

double nonoverlapping_avar(const std::vector<double>& y) {
  double s = 0;
  for (std::size_t i = 0; i + 1 < y.size(); ++i) s += (y[i + 1] - y[i]) * (y[i + 1] - y[i]);
  return 0.5 * s / static_cast<double>(y.size() - 1);
}

// The expectations are taken for N = the estimator's number of terms at this τ (not the number of
// averages): that is what reproduces every α of Stable32's tables in the B1 region.
int noise_id_b1(const PhaseSeries& x, std::int64_t m, Estimator est) {
  const std::vector<double> y = averaged_frequency(x, m);
  if (y.size() < 2) return 0;
  const double avar = nonoverlapping_avar(y);
  if (!(avar > 0)) return 0;
  const double b1 = sample_variance(y) / avar;
  const int mu = b1_mu(b1, static_cast<double>(term_count(est, m, x.points())));
  if (mu == -2) {
    // μ = −2 covers white and flicker PM; Stable32 reports flicker PM (α = 1) unless R(n) can
    // tell them apart, which it uses for the modified variance only.
    if (est != Estimator::Modified) return 1;
    // R(n) = MVAR/AVAR tells white (1/m) from flicker PM (NIST TN 1337 Table 2, f_h = 1/(2τ0)).
    // y is in phase units per cluster: bring AVAR to deviation units before the ratio.
    const double unit = (x.exact() ? x.arcsec_per_count : 1.0) / (static_cast<double>(m) * x.tau0_s);
    const double mvar = allan_variance(x, m, Estimator::Modified);
    const double rn = mvar / (avar * unit * unit);
    const double md = static_cast<double>(m);
    const double r_flicker = 3.37 / (1.04 + 3.0 * std::log(std::numbers::pi * md));
    const double r_white = 1.0 / md;
    return rn > std::sqrt(r_flicker * r_white) ? 1 : 2;
  }
  return std::clamp(-mu - 1, -2, 2);  // μ = 1, 0, −1 ↔ α = −2, −1, 0 (μ = 2: α = −3, clamped)
}

// ---- Greenhall–Riley EDF --------------------------------------------------------------------

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
    default: throw AnalysisError(fmt::format("EDF: unsupported noise exponent alpha = {}", alpha));
  }
}

constexpr Real kInfinite = std::numeric_limits<Real>::infinity();

Real sx(Real t, Real f, int alpha) {
  if (std::isinf(f)) return sw(t, alpha + 2);
  return f * f * (2 * sw(t, alpha) - sw(t - 1 / f, alpha) - sw(t + 1 / f, alpha));
}

Real sz(Real t, Real f, int alpha, int d) {
  switch (d) {
    case 1: return 2 * sx(t, f, alpha) - sx(t - 1, f, alpha) - sx(t + 1, f, alpha);
    case 2:
      return 6 * sx(t, f, alpha) - 4 * sx(t - 1, f, alpha) - 4 * sx(t + 1, f, alpha) + sx(t - 2, f, alpha) +
             sx(t + 2, f, alpha);
    case 3:
      return 20 * sx(t, f, alpha) - 15 * sx(t - 1, f, alpha) - 15 * sx(t + 1, f, alpha) +
             6 * sx(t - 2, f, alpha) + 6 * sx(t + 2, f, alpha) - sx(t - 3, f, alpha) - sx(t + 3, f, alpha);
    default: throw AnalysisError(fmt::format("EDF: unsupported difference order d = {}", d));
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

int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain) {
  return detail::identify_noise(x, m, est, domain, nullptr, false, nullptr);
}

namespace detail {

int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain,
                   const std::int32_t* rel32, bool small24, const double* start) {
  if (m < 1 || x.points() < 3 || static_cast<std::size_t>(m) > x.points() - 1) return 0;
  // Points at τ: phase samples for phase data, averaged frequencies (one fewer) for frequency data.
  const std::size_t phase_points = (x.points() - 1) / static_cast<std::size_t>(m) + 1;
  if (domain == NoiseIdDomain::Phase && phase_points >= kMinAcfPoints)
    return std::clamp(acf_exponent_at(x, m, phase_points, 0, rel32, small24, start) + 2, -2, 2);
  if (domain == NoiseIdDomain::Frequency && phase_points - 1 >= kMinAcfPoints)
    return std::clamp(acf_exponent_at(x, m, phase_points, 1, rel32, small24, start), -2, 2);
  return noise_id_b1(x, m, est);
}

std::vector<double> lag1_start_pass(const PhaseSeries& x, const std::int64_t* ms, std::size_t n_ms,
                                    NoiseIdDomain domain, const std::int32_t* rel32, bool small24, unsigned threads,
                                    Crew* crew) {
  std::vector<double> out;
#if defined(__x86_64__) || defined(__i386__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  const std::size_t points = x.points();
  if (!avx2 || !rel32 || !small24 || points < 3 || points >= kExactMaxPoints) return out;
  const int base = domain == NoiseIdDomain::Phase ? 0 : 1;
  std::vector<std::size_t> stride, count, index;
  for (std::size_t j = 0; j < n_ms; ++j) {
    if (ms[j] < 1 || ms[j] > kStartPassMaxM || static_cast<std::size_t>(ms[j]) > points - 1) continue;
    const std::size_t phase_points = (points - 1) / static_cast<std::size_t>(ms[j]) + 1;
    if (phase_points - static_cast<std::size_t>(base) < kMinAcfPoints) continue;  // B1 at this m
    stride.push_back(static_cast<std::size_t>(ms[j]));
    count.push_back(phase_points);
    index.push_back(j);
  }
  if (stride.empty()) return out;
  std::vector<double> r;
  // Eight lanes where the processor has AVX-512, else four: the same exact integer sums.
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  if (avx512)
    (base == 0 ? lag1_start_pass_impl<0, 8> : lag1_start_pass_impl<1, 8>)(rel32, points, stride, count, threads, crew,
                                                                         r);
  else
    (base == 0 ? lag1_start_pass_impl<0, 4> : lag1_start_pass_impl<1, 4>)(rel32, points, stride, count, threads, crew,
                                                                         r);
  out.assign(2 * n_ms, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < index.size(); ++i) {
    out[2 * index[i]] = r[2 * i];
    out[2 * index[i] + 1] = r[2 * i + 1];
  }
#else
  (void)x, (void)ms, (void)n_ms, (void)domain, (void)rel32, (void)small24, (void)threads, (void)crew;
#endif
  return out;
}

void lag1_exact(const std::int32_t* rel32, std::size_t stride, std::size_t count, int level, bool vector, bool pair,
                double r[2]) {
  pair = pair && level < 3;
#if defined(__x86_64__) || defined(__i386__)
  if (vector && __builtin_cpu_supports("avx2")) {
    lag1_exact_avx2_at(rel32, stride, count, level, pair, r);
    if (!pair) r[1] = 0.0;
    return;
  }
#endif
  (void)vector;
  std::int64_t top = 0;  // the one-term path takes int64 sums between flushes when every |p| < 2^24
  for (std::size_t k = 0; k < count; ++k) top = std::max<std::int64_t>(top, std::abs(std::int64_t{rel32[k * stride]}));
  const bool small = top < (std::int64_t{1} << 24);
  r[0] = lag1_exact_scalar(rel32, stride, count, level, small);
  r[1] = pair ? lag1_exact_scalar(rel32, stride, count, level + 1, small) : 0.0;
}

}  // namespace detail

double edf_greenhall(int alpha, int d, std::int64_t m, std::size_t n_phase, bool overlapping,
                     bool modified) {
  if (d < 1 || d > 3) throw AnalysisError(fmt::format("EDF: unsupported difference order d = {}", d));
  if (alpha + 2 * d <= 1 || alpha > 2 || alpha < -4)
    throw AnalysisError(fmt::format("EDF: noise exponent alpha = {} not allowed with d = {}", alpha, d));
  const Real mr = static_cast<Real>(m);
  const Real f = modified ? 1 : mr;                 // filter factor
  const Real s = overlapping ? mr : 1;              // stride factor
  const Real l = mr / f + mr * d;                   // filter length in phase samples
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
  }
  return 0;
}

DevInterval chi2_interval(double var, double edf, double p) {
  if (!(p > 0 && p < 1)) throw UsageError(fmt::format("confidence must lie strictly between 0 and 1, got {}", p));
  if (!(edf > 0) || !(var >= 0)) return {0.0, 0.0};
  const boost::math::chi_squared dist(edf);
  const double chi_hi = boost::math::quantile(dist, 0.5 * (1 + p));
  const double chi_lo = boost::math::quantile(dist, 0.5 * (1 - p));
  return {std::sqrt(edf * var / chi_hi), std::sqrt(edf * var / chi_lo)};
}

}  // namespace rwcalc
