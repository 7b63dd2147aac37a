// Outlier detection by the neighbour median, and the remove/replace helpers. See outliers.hpp.
#include "rwcalc/outliers.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <thread>

#include "rwcalc/thread.hpp"
#include "io/select.hpp"
#include "allan/x86_dispatch.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace rwcalc {

namespace {

constexpr std::size_t kMinSamples = 7;
// The scale is estimated from at most this many residuals (an evenly strided subset): the MAD of
// 2e5 values is within ~0.3 % of the whole record's, and it keeps long records fast.
constexpr std::size_t kScaleSamples = 200000;
constexpr double kMadToSigma = 1.482602218505602;  // 1/Φ⁻¹(3/4)

inline void sort2(double& a, double& b) {
  const double lo = std::min(a, b);
  b = std::max(a, b);
  a = lo;
}

// An optimal 12-comparator sorting network for six values a … f (branch-free), with S(x, y)
// putting the smaller of x, y in x: afterwards c and d are the middle two. The scalar median and
// the vector screens use the same network.
#define RWCALC_SORT6(S, a, b, c, d, e, f) \
  S(a, f); S(b, d); S(c, e);              \
  S(b, c); S(d, e);                       \
  S(a, d); S(c, f);                       \
  S(a, b); S(c, d); S(e, f);              \
  S(b, c); S(d, e)

// Median of six values: the sorting network, then the mean of the middle two.
inline double median6(double a, double b, double c, double d, double e, double f) {
  RWCALC_SORT6(sort2, a, b, c, d, e, f);
  return 0.5 * (c + d);
}

// Indices of the six samples nearest to i (i excluded), three per side where the record allows.
inline void neighbours(std::size_t i, std::size_t n, std::size_t out[6]) {
  std::size_t first = i >= 3 ? i - 3 : 0;
  if (first + 6 >= n) first = n - 7;  // n ≥ 7
  std::size_t k = 0;
  for (std::size_t j = first; k < 6; ++j)
    if (j != i) out[k++] = j;
}

inline double interior_residual(const double* y, std::size_t i) {
  return y[i] - median6(y[i - 3], y[i - 2], y[i - 1], y[i + 1], y[i + 2], y[i + 3]);
}

// Residual of sample i from the median of its neighbours.
inline double residual(const double* y, std::size_t i, std::size_t n) {
  if (i >= 3 && i + 3 < n) return interior_residual(y, i);
  std::size_t nb[6];
  neighbours(i, n, nb);
  return y[i] - median6(y[nb[0]], y[nb[1]], y[nb[2]], y[nb[3]], y[nb[4]], y[nb[5]]);
}

// ---- rate sources ----------------------------------------------------------------------------
// The scan reads the rates through a window of one block plus three samples either side: from a
// vector in place, or computed block by block from a phase series (no copy of the whole record).
// Both give the same doubles, so every result is the same whichever source is scanned.

constexpr std::size_t kBlock = 1024;
constexpr std::size_t kHalo = 3;

struct VectorRates {
  const double* y;
  std::size_t n;
  // p with p[k] = rate(b − 3 + k) for k < e − b + 6; 3 ≤ b, e + 3 ≤ n.
  const double* window(std::size_t b, [[maybe_unused]] std::size_t e, double* /*buf*/) const { return y + b - kHalo; }
  void fill(std::size_t from, std::size_t to, double* out) const { std::copy(y + from, y + to, out); }
};

#if defined(__x86_64__) || defined(__i386__)
// Rates of exact counts, four at a time: the int64 increments become doubles exactly (the
// 1.5·2^52 bias trick, valid for |d| < 2^51), then (d·q)/τ0 as PhaseSeries::rate computes it
// (same IEEE operations, no fused multiply-add), so the doubles are bit-identical. Returns false
// when an increment is out of that range (the caller then takes the scalar path).
__attribute__((target("avx2"))) bool count_rates_avx2(const std::int64_t* c, std::size_t from, std::size_t to,
                                                      double q, double tau0, double* out) {
  const __m256i bias_i = _mm256_set1_epi64x(0x4338000000000000LL);
  const __m256d bias_d = _mm256_set1_pd(6755399441055744.0);  // 1.5·2^52
  const __m256i half = _mm256_set1_epi64x(std::int64_t{1} << 51);
  const __m256d vq = _mm256_set1_pd(q), vt = _mm256_set1_pd(tau0);
  __m256i bad = _mm256_setzero_si256();
  std::size_t i = from;
  for (; i + 4 <= to; i += 4) {
    const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + i + 1));
    const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + i));
    const __m256i d = _mm256_sub_epi64(a, b);
    bad = _mm256_or_si256(bad, _mm256_srli_epi64(_mm256_add_epi64(d, half), 52));
    const __m256d x = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(d, bias_i)), bias_d);
    _mm256_storeu_pd(out + (i - from), _mm256_div_pd(_mm256_mul_pd(x, vq), vt));
  }
  for (; i < to; ++i) {
    const auto d = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[i + 1]) - static_cast<std::uint64_t>(c[i]));
    out[i - from] = static_cast<double>(d) * q / tau0;
  }
  return _mm256_testz_si256(bad, bad) != 0;
}

// Rates of counts held in 32 bits, four at a time: the increment converted exactly, then
// multiplied and divided as PhaseSeries::rate does, so the same bits.
__attribute__((target("avx2"))) void count_rates32_avx2(const std::int32_t* c, std::size_t from, std::size_t to,
                                                        double q, double tau0, double* out) {
  const __m256d vq = _mm256_set1_pd(q), vt = _mm256_set1_pd(tau0);
  std::size_t i = from;
  for (; i + 4 <= to; i += 4) {
    const __m128i d = _mm_sub_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + i + 1)),
                                    _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + i)));
    _mm256_storeu_pd(out + (i - from), _mm256_div_pd(_mm256_mul_pd(_mm256_cvtepi32_pd(d), vq), vt));
  }
  for (; i < to; ++i) out[i - from] = static_cast<double>(std::int64_t{c[i + 1]} - std::int64_t{c[i]}) * q / tau0;
}
#endif

bool have_avx2() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
#else
  return false;
#endif
}

bool have_avx512() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool yes = __builtin_cpu_supports("avx512f");
  return yes;
#else
  return false;
#endif
}

/// The rates of sixteen consecutive count increments lo … lo + 15, each computed as
/// PhaseSeries::rate computes it: a window whose increments all lie in that range is filled by
/// lookup, bit-identical to dividing (exact counts only; `ok` false otherwise).
struct RateTable {
  bool ok = false;
  std::int64_t lo = 0;
  alignas(64) double v[16] = {};
};

RateTable rate_table(const PhaseSeries& ph, std::size_t n) {
  RateTable t;
  if (!ph.exact() || n == 0) return t;
  // The smallest increment among the first ones, less a margin: pulse records keep their
  // increments in a narrow band around the mean rate.
  std::int64_t lo = std::numeric_limits<std::int64_t>::max();
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 4096); ++i)
    lo = std::min(lo, static_cast<std::int64_t>(static_cast<std::uint64_t>(ph.count(i + 1)) -
                                                 static_cast<std::uint64_t>(ph.count(i))));
  if (lo < -(std::int64_t{1} << 40) || lo > (std::int64_t{1} << 40)) return t;
  t.lo = lo - 4;
  for (int k = 0; k < 16; ++k)
    t.v[k] = static_cast<double>(t.lo + k) * ph.arcsec_per_count / ph.tau0_s;
  t.ok = true;
  return t;
}

#if defined(__x86_64__) || defined(__i386__)
RWCALC_AVX512_WARNINGS_OFF
// Rates of exact counts by lookup in the table, eight at a time; false (the window then needs
// the division) when an increment lies outside the table's range. Counts held in 32 bits
// (PhaseSeries::counts32: |C| < 2^30, so every increment fits in 32 bits) are subtracted in 32-bit
// lanes and widened.
template <class Count>
__attribute__((target("avx512f"))) bool table_rates_avx512(const Count* c, std::size_t from, std::size_t to,
                                                         const RateTable& t, double q, double tau0, double* out) {
  const __m512i lo = _mm512_set1_epi64(t.lo), top = _mm512_set1_epi64(15);
  const __m512d t0 = _mm512_load_pd(t.v), t1 = _mm512_load_pd(t.v + 8);
  __mmask8 bad = 0;
  std::size_t i = from;
  for (; i + 8 <= to; i += 8) {
    __m512i d;
    if constexpr (sizeof(Count) == 4)
      d = _mm512_cvtepi32_epi64(_mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + i + 1)),
                                                 _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + i))));
    else
      d = _mm512_sub_epi64(_mm512_loadu_si512(c + i + 1), _mm512_loadu_si512(c + i));
    const __m512i idx = _mm512_sub_epi64(d, lo);
    bad |= _mm512_cmpgt_epu64_mask(idx, top);
    _mm512_storeu_pd(out + (i - from), _mm512_permutex2var_pd(t0, idx, t1));
  }
  for (; i < to; ++i) {
    const auto d = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[i + 1]) - static_cast<std::uint64_t>(c[i]));
    out[i - from] = static_cast<double>(d) * q / tau0;
  }
  return bad == 0;
}

__attribute__((target("avx512f"))) inline void s2_512(__m512d& a, __m512d& b) {
  const __m512d lo = _mm512_min_pd(a, b);
  b = _mm512_max_pd(a, b);
  a = lo;
}

// screen_avx2 with eight samples at a time.
__attribute__((target("avx512f"))) bool screen_avx512(const double* w, std::size_t len, double limit) {
  const __m512d lim = _mm512_set1_pd(limit);
  const __m512d halfv = _mm512_set1_pd(0.5);
  __mmask8 hit = 0;
  std::size_t k = kHalo;
  for (; k + 8 <= kHalo + len; k += 8) {
    __m512d a = _mm512_loadu_pd(w + k - 3), b = _mm512_loadu_pd(w + k - 2), c = _mm512_loadu_pd(w + k - 1);
    __m512d d = _mm512_loadu_pd(w + k + 1), e = _mm512_loadu_pd(w + k + 2), f = _mm512_loadu_pd(w + k + 3);
    RWCALC_SORT6(s2_512, a, b, c, d, e, f);
    const __m512d r = _mm512_sub_pd(_mm512_loadu_pd(w + k), _mm512_mul_pd(halfv, _mm512_add_pd(c, d)));
    hit |= _mm512_cmp_pd_mask(_mm512_abs_pd(r), lim, _CMP_GT_OQ);
  }
  bool any = hit != 0;
  for (; k < kHalo + len; ++k) any |= std::abs(interior_residual(w, k)) > limit;
  return any;
}

// min_step_avx2 with eight steps at a time.
__attribute__((target("avx512f"))) double min_step_avx512(const double* w, std::size_t len, double res) {
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d zero = _mm512_setzero_pd();
  __m512d acc = _mm512_set1_pd(res);
  std::size_t i = 1;
  for (; i + 8 <= len; i += 8) {
    const __m512d d = _mm512_abs_pd(_mm512_sub_pd(_mm512_loadu_pd(w + i), _mm512_loadu_pd(w + i - 1)));
    acc = _mm512_min_pd(acc, _mm512_mask_blend_pd(_mm512_cmp_pd_mask(d, zero, _CMP_GT_OQ), inf, d));
  }
  res = std::min(res, _mm512_reduce_min_pd(acc));
  for (; i < len; ++i) {
    const double d = std::abs(w[i] - w[i - 1]);
    res = std::min(res, d > 0 ? d : std::numeric_limits<double>::infinity());
  }
  return res;
}
RWCALC_AVX512_WARNINGS_ON
#endif

struct PhaseRates {
  const PhaseSeries& ph;
  std::size_t n;
  RateTable table{};
  void fill(std::size_t from, std::size_t to, double* out) const {
    if (ph.narrow()) {
      const std::int32_t* c = ph.counts32.data();
#if defined(__x86_64__) || defined(__i386__)
      if (table.ok && have_avx512() && table_rates_avx512(c, from, to, table, ph.arcsec_per_count, ph.tau0_s, out))
        return;
      if (have_avx2()) return count_rates32_avx2(c, from, to, ph.arcsec_per_count, ph.tau0_s, out);
#endif
      for (std::size_t i = from; i < to; ++i) out[i - from] = ph.rate(i);
    } else if (ph.exact()) {
#if defined(__x86_64__) || defined(__i386__)
      if (table.ok && have_avx512() &&
          table_rates_avx512(ph.counts.data(), from, to, table, ph.arcsec_per_count, ph.tau0_s, out))
        return;
      if (have_avx2() && count_rates_avx2(ph.counts.data(), from, to, ph.arcsec_per_count, ph.tau0_s, out)) return;
#endif
      for (std::size_t i = from; i < to; ++i) out[i - from] = ph.rate(i);
    } else {
      const double* x = ph.values.data();
      for (std::size_t i = from; i < to; ++i) out[i - from] = (x[i + 1] - x[i]) / ph.tau0_s + ph.rate_offset;
    }
  }
  const double* window(std::size_t b, std::size_t e, double* buf) const {
    fill(b - kHalo, e + kHalo, buf);
    return buf;
  }
};

PhaseRates phase_rates(const PhaseSeries& phase) {
  const std::size_t n = phase.points() > 0 ? phase.points() - 1 : 0;
  return {phase, n, rate_table(phase, n)};
}

// The first and the last seven rates (the samples whose neighbours are not centred).
template <class Src>
void edges(const Src& src, double head[7], double tail[7]) {
  src.fill(0, 7, head);
  src.fill(src.n - 7, src.n, tail);
}

#if defined(__x86_64__) || defined(__i386__)
// Smallest non-zero |y_i − y_{i−1}| for i in [1, len) of w, four at a time (min is exact, so
// the order does not matter).
__attribute__((target("avx2"))) double min_step_avx2(const double* w, std::size_t len, double res) {
  const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  const __m256d zero = _mm256_setzero_pd();
  const __m256d sign = _mm256_set1_pd(-0.0);
  __m256d acc = _mm256_set1_pd(res);
  std::size_t i = 1;
  for (; i + 4 <= len; i += 4) {
    const __m256d d = _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(w + i), _mm256_loadu_pd(w + i - 1)));
    acc = _mm256_min_pd(acc, _mm256_blendv_pd(inf, d, _mm256_cmp_pd(d, zero, _CMP_GT_OQ)));
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, acc);
  for (double v : lanes) res = std::min(res, v);
  for (; i < len; ++i) {
    const double d = std::abs(w[i] - w[i - 1]);
    res = std::min(res, d > 0 ? d : std::numeric_limits<double>::infinity());
  }
  return res;
}

__attribute__((target("avx2"))) inline void s2(__m256d& a, __m256d& b) {
  const __m256d lo = _mm256_min_pd(a, b);
  b = _mm256_max_pd(a, b);
  a = lo;
}

// Does any interior sample of the window (local indices [3, 3 + len)) have a residual beyond
// `limit`? The median-of-six network on four samples at a time; only the yes/no is used, the
// samples of a block that trips are tested again one by one.
__attribute__((target("avx2"))) bool screen_avx2(const double* w, std::size_t len, double limit) {
  const __m256d lim = _mm256_set1_pd(limit);
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d halfv = _mm256_set1_pd(0.5);
  __m256d hit = _mm256_setzero_pd();
  std::size_t k = kHalo;
  for (; k + 4 <= kHalo + len; k += 4) {
    __m256d a = _mm256_loadu_pd(w + k - 3), b = _mm256_loadu_pd(w + k - 2), c = _mm256_loadu_pd(w + k - 1);
    __m256d d = _mm256_loadu_pd(w + k + 1), e = _mm256_loadu_pd(w + k + 2), f = _mm256_loadu_pd(w + k + 3);
    RWCALC_SORT6(s2, a, b, c, d, e, f);
    const __m256d r = _mm256_sub_pd(_mm256_loadu_pd(w + k), _mm256_mul_pd(halfv, _mm256_add_pd(c, d)));
    hit = _mm256_or_pd(hit, _mm256_cmp_pd(_mm256_andnot_pd(sign, r), lim, _CMP_GT_OQ));
  }
  bool any = _mm256_movemask_pd(hit) != 0;
  for (; k < kHalo + len; ++k) any |= std::abs(interior_residual(w, k)) > limit;
  return any;
}
#endif

double min_step(const double* w, std::size_t len, double res) {
#if defined(__x86_64__) || defined(__i386__)
  if (have_avx512()) return min_step_avx512(w, len, res);
  if (have_avx2()) return min_step_avx2(w, len, res);
#endif
  for (std::size_t i = 1; i < len; ++i) {
    const double d = std::abs(w[i] - w[i - 1]);
    res = std::min(res, d > 0 ? d : std::numeric_limits<double>::infinity());
  }
  return res;
}

bool screen_block(const double* w, std::size_t len, double limit) {
#if defined(__x86_64__) || defined(__i386__)
  if (have_avx512()) return screen_avx512(w, len, limit);
  if (have_avx2()) return screen_avx2(w, len, limit);
#endif
  bool hit = false;
  for (std::size_t k = kHalo; k < kHalo + len; ++k) hit |= std::abs(interior_residual(w, k)) > limit;
  return hit;
}

// The scale pass in three parts, so that its interior can be split between threads in any way:
// the first samples (constructor), interior stretches of whole blocks, each into a Part of its
// own (`interior`, from any thread), and the last samples with the merge of the parts (`finish`,
// the parts given in the order of their stretches). With `pre` > 0 the same pass also screens
// every interior block against that provisional limit and lists the blocks (their first index)
// where some |residual| exceeds it. A minimum and a set of values: the scale is the same
// whatever the split.
template <class Src>
struct ScalePass {
  struct Part {
    double res = std::numeric_limits<double>::infinity();
    std::vector<double> a;
    std::vector<std::size_t> hits;
  };
  const Src& src;
  std::size_t n, stride, end;
  double pre;
  double head[7], tail[7];

  ScalePass(const Src& s, double pre_limit) : src(s), n(s.n), stride(1), end(0), pre(pre_limit) {
    if (n < kMinSamples) return;
    edges(src, head, tail);
    stride = (n + kScaleSamples - 1) / kScaleSamples;
    end = n - 3;  // interior [3, n − 3)
  }
  /// Interior blocks [from, to): their steps i in [b+1, e+1) (the window's local [3, e − b + 4)
  /// with its previous sample) and the subset's indices among them.
  void interior(std::size_t from, std::size_t to, Part& p) const {
    std::vector<double> buf(kBlock + 2 * kHalo);
    std::size_t next = (from + stride - 1) / stride * stride;
    p.a.reserve(p.a.size() + (to - from) / stride + 1);
    for (std::size_t b = from; b < to; b += kBlock) {
      const std::size_t e = std::min(to, b + kBlock);
      const double* w = src.window(b, e, buf.data());
      p.res = min_step(w + kHalo, e - b + 1, p.res);
      for (; next < e; next += stride) p.a.push_back(std::abs(interior_residual(w, next - b + kHalo)));
      if (pre > 0 && screen_block(w, e - b, pre)) p.hits.push_back(b);
    }
  }
  OutlierScale finish(const std::vector<Part*>& parts, std::vector<std::size_t>* flagged) const {
    OutlierScale s;
    if (n < kMinSamples) return s;
    // Resolution: the smallest non-zero step, over i in [1, n).
    double res = min_step(head, 4, std::numeric_limits<double>::infinity());  // steps 1..3
    // Robust scale: 1.4826 × the median |residual| of an evenly strided subset: the parts' values
    // where they are, and the edges' few.
    std::vector<double> a;
    auto add_edge = [&](std::size_t i) {
      if (i < 3) a.push_back(std::abs(residual(head, i, 7)));
      else a.push_back(std::abs(residual(tail, i - (n - 7), 7)));
    };
    for (std::size_t i = 0; i < 3 && i < n; i += stride) add_edge(i);
    if (flagged) flagged->clear();
    for (const Part* p : parts) {
      res = std::min(res, p->res);
      if (flagged) flagged->insert(flagged->end(), p->hits.begin(), p->hits.end());
    }
    // Remaining steps of the tail: i in [max(4, n − 2), n) — locals of tail.
    for (std::size_t i = std::max<std::size_t>(4, n - 2); i < n; ++i) {
      const double d = std::abs(tail[i - (n - 7)] - tail[i - 1 - (n - 7)]);
      res = std::min(res, d > 0 ? d : std::numeric_limits<double>::infinity());
    }
    for (std::size_t i = std::max<std::size_t>(3, (end + stride - 1) / stride * stride); i < n; i += stride) add_edge(i);
    s.resolution = std::isfinite(res) ? res : 0.0;
    std::vector<std::span<const double>> sets{a};
    std::size_t total = a.size();
    for (const Part* p : parts) {
      sets.emplace_back(p->a);
      total += p->a.size();
    }
    s.mad_sigma = kMadToSigma * detail::select_nonnegative(sets, total / 2);
    s.scale = std::max(s.mad_sigma, s.resolution);
    return s;
  }
};

// Records of at least this many samples split their passes between two threads when allowed.
constexpr std::size_t kParallelFrom = std::size_t{1} << 20;

// With `flagged`, the same pass also screens every interior block against the provisional limit
// `pre` (see ScalePass).
template <class Src>
OutlierScale scale_of(const Src& src, unsigned threads, double pre = 0, std::vector<std::size_t>* flagged = nullptr) {
  if (src.n < kMinSamples) return {};
  const ScalePass<Src> pass(src, flagged ? pre : 0.0);
  using Part = typename ScalePass<Src>::Part;
  Part first, second;
  if (threads == 0) threads = std::thread::hardware_concurrency();
  const std::size_t end = pass.end;
  // Long records: the second half of the interior on another thread.
  if (end > 3 && end - 3 >= kParallelFrom && threads > 1) {
    const std::size_t mid = 3 + ((end - 3) / 2 / kBlock) * kBlock;
    Thread worker([&] { pass.interior(mid, end, second); });
    pass.interior(3, mid, first);
  } else {
    pass.interior(3, end, first);
  }
  return pass.finish({&first, &second}, flagged);
}

// With `only`, the interior blocks outside that list (first indices, ascending) are known to hold
// no residual beyond the limit and are not read again.
template <class Src>
std::vector<Outlier> outliers_of(const Src& src, double threshold, const OutlierScale& s, unsigned threads,
                                 const std::vector<std::size_t>* only = nullptr) {
  std::vector<Outlier> out;
  const std::size_t n = src.n;
  if (n < kMinSamples) return out;
  if (!(s.scale > 0)) return out;  // a constant record has no outliers
  const double limit = threshold * s.scale;
  double head[7], tail[7];
  edges(src, head, tail);
  auto test_edge = [&](std::size_t i) {
    const bool front = i < 3;
    const double* w = front ? head : tail;
    const std::size_t k = front ? i : i - (n - 7);
    const double r = residual(w, k, 7);
    if (std::abs(r) > limit) out.push_back({i, 0, w[k], r / s.scale});
  };
  // Interior in blocks: a branch-free screen, then a sample-by-sample look at blocks that trip.
  auto screen = [&](std::size_t from, std::size_t to_end, std::vector<Outlier>& to) {
    std::vector<double> buf(kBlock + 2 * kHalo);
    for (std::size_t b = from; b < to_end; b += kBlock) {
      const std::size_t e = std::min(to_end, b + kBlock);
      const double* w = src.window(b, e, buf.data());
      if (!screen_block(w, e - b, limit)) continue;
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t k = i - b + kHalo;
        const double r = interior_residual(w, k);
        if (std::abs(r) > limit) to.push_back({i, 0, w[k], r / s.scale});
      }
    }
  };
  test_edge(0);
  test_edge(1);
  test_edge(2);
  const std::size_t end = n - 3;
  // Long records: the second half of the interior on another thread (results joined in order).
  if (threads == 0) threads = std::thread::hardware_concurrency();
  if (only) {
    std::vector<double> buf(kBlock + 2 * kHalo);
    for (const std::size_t b : *only) {
      const std::size_t e = std::min(end, b + kBlock);
      const double* w = src.window(b, e, buf.data());
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t k = i - b + kHalo;
        const double r = interior_residual(w, k);
        if (std::abs(r) > limit) out.push_back({i, 0, w[k], r / s.scale});
      }
    }
  } else if (end > 3 && end - 3 >= kParallelFrom && threads > 1) {
    const std::size_t mid = 3 + ((end - 3) / 2 / kBlock) * kBlock;
    std::vector<Outlier> second;
    {
      Thread worker([&] { screen(mid, end, second); });
      screen(3, mid, out);
    }
    out.insert(out.end(), second.begin(), second.end());
  } else {
    screen(3, end, out);
  }
  test_edge(n - 3);
  test_edge(n - 2);
  test_edge(n - 1);
  return out;
}


}  // namespace

OutlierScale outlier_scale(const std::vector<double>& rates) { return scale_of(VectorRates{rates.data(), rates.size()}, 0); }

OutlierScale outlier_scale(const PhaseSeries& phase, unsigned threads) {
  return scale_of(phase_rates(phase), threads);
}

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold) {
  return find_outliers(rates, threshold, outlier_scale(rates));
}

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& s) {
  return outliers_of(VectorRates{rates.data(), rates.size()}, threshold, s, 0);
}

std::vector<Outlier> find_outliers(const PhaseSeries& phase, double threshold, const OutlierScale& s,
                                   unsigned threads) {
  return outliers_of(phase_rates(phase), threshold, s, threads);
}

namespace {

/// The provisional limit of the one-pass scan of exact counts: threshold × one count's rate step
/// (the resolution of integer data), just under it; 0 when that scan does not apply.
double one_pass_limit(const PhaseSeries& phase, std::size_t n, double threshold) {
  const double pre = threshold * (phase.arcsec_per_count / phase.tau0_s) * (1.0 - 1.0 / 1048576.0);
  if (!phase.exact() || n < kMinSamples || !(pre > 0) || !std::isfinite(pre)) return 0.0;
  return pre;
}

/// The outliers once the one-pass scale and its flagged blocks are known: only those blocks are
/// read again, unless the bound exceeds the real limit after all or too many blocks tripped.
std::vector<Outlier> after_one_pass(const PhaseRates& src, double threshold, const OutlierScale& scale, double pre,
                                    const std::vector<std::size_t>& flagged, unsigned threads) {
  const std::size_t blocks = (src.n - 6 + kBlock - 1) / kBlock;
  if (threshold * scale.scale >= pre && flagged.size() <= blocks / 16)
    return outliers_of(src, threshold, scale, threads, &flagged);
  return outliers_of(src, threshold, scale, threads);
}

}  // namespace

std::vector<Outlier> scan_outliers(const PhaseSeries& phase, double threshold, OutlierScale& scale, unsigned threads) {
  const PhaseRates src = phase_rates(phase);
  // Exact counts: the limit is at least threshold × one count's rate step (the resolution of
  // integer data), so one pass can compute the scale and screen every block against (just under)
  // that bound; only the blocks that trip are read again, against the real limit. If the bound
  // should exceed the real limit after all, or too many blocks trip (the spread, not the
  // resolution, sets the scale), the ordinary screen runs instead: the result is the same.
  const double pre = one_pass_limit(phase, src.n, threshold);
  if (!(pre > 0)) {
    scale = scale_of(src, threads);
    return outliers_of(src, threshold, scale, threads);
  }
  std::vector<std::size_t> flagged;
  scale = scale_of(src, threads, pre, &flagged);
  return after_one_pass(src, threshold, scale, pre, flagged, threads);
}

struct SharedOutlierScan::Impl {
  static constexpr std::size_t kChunk = kBlock * 64;  ///< samples per stretch a helper takes
  PhaseRates src;
  double threshold;
  double pre;
  std::optional<ScalePass<PhaseRates>> pass;
  std::vector<ScalePass<PhaseRates>::Part> parts;
  std::atomic<std::size_t> next{0};
  // Other data (not the one-pass case): the first helper runs the whole scan.
  std::atomic<bool> claimed{false};
  OutlierScale scale;
  std::vector<Outlier> found;

  Impl(const PhaseSeries& phase, double thr)
      : src(phase_rates(phase)), threshold(thr), pre(one_pass_limit(phase, src.n, thr)) {
    if (!(pre > 0)) return;
    pass.emplace(src, pre);
    const std::size_t interior = pass->end > 3 ? pass->end - 3 : 0;
    parts.resize((interior + kChunk - 1) / kChunk);
  }
};

SharedOutlierScan::SharedOutlierScan(const PhaseSeries& phase, double threshold)
    : impl_(std::make_unique<Impl>(phase, threshold)) {}

SharedOutlierScan::~SharedOutlierScan() = default;

void SharedOutlierScan::help() {
  Impl& m = *impl_;
  if (!m.pass) {
    if (!m.claimed.exchange(true)) m.found = scan_outliers(m.src.ph, m.threshold, m.scale, 1);
    return;
  }
  for (std::size_t k = m.next++; k < m.parts.size(); k = m.next++) {
    const std::size_t from = 3 + k * Impl::kChunk;
    m.pass->interior(from, std::min(m.pass->end, from + Impl::kChunk), m.parts[k]);
  }
}

std::vector<Outlier> SharedOutlierScan::finish(OutlierScale& scale, unsigned threads) {
  Impl& m = *impl_;
  if (!m.pass) {
    help();  // nobody took it yet: run it here
    scale = m.scale;
    return std::move(m.found);
  }
  help();  // whatever is left
  std::vector<ScalePass<PhaseRates>::Part*> ptrs;
  for (auto& p : m.parts) ptrs.push_back(&p);
  std::vector<std::size_t> flagged;
  scale = m.pass->finish(ptrs, &flagged);
  return after_one_pass(m.src, m.threshold, scale, m.pre, flagged, threads);
}

std::vector<Outlier> find_outliers(const Recording& recording, double threshold) {
  auto out = find_outliers(recording.phase, threshold, outlier_scale(recording.phase));
  for (auto& o : out) o.line = recording.line_of_rate(o.index);
  return out;
}

namespace {

std::vector<char> outlier_mask(std::size_t n, const std::vector<Outlier>& outliers) {
  std::vector<char> bad(n, 0);
  for (const auto& o : outliers)
    if (o.index < n) bad[o.index] = 1;
  return bad;
}

// Median of the (up to) four nearest non-outlier neighbours of i; NaN when there are none.
double local_median(const std::vector<double>& y, const std::vector<char>& bad, std::size_t i) {
  double v[4];
  std::size_t k = 0;
  const std::size_t n = y.size();
  for (std::size_t d = 1; k < 4 && (d <= i || i + d < n); ++d) {
    if (d <= i && !bad[i - d] && k < 4) v[k++] = y[i - d];
    if (i + d < n && !bad[i + d] && k < 4) v[k++] = y[i + d];
  }
  if (k == 0) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v, v + k);
  return k % 2 ? v[k / 2] : 0.5 * (v[k / 2 - 1] + v[k / 2]);
}

}  // namespace

std::vector<double> remove_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers) {
  const auto bad = outlier_mask(rates.size(), outliers);
  std::vector<double> out;
  out.reserve(rates.size());
  for (std::size_t i = 0; i < rates.size(); ++i)
    if (!bad[i]) out.push_back(rates[i]);
  return out;
}

std::vector<double> replace_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers) {
  const auto bad = outlier_mask(rates.size(), outliers);
  std::vector<double> out = rates;
  for (const auto& o : outliers) {
    if (o.index >= rates.size()) continue;
    const double m = local_median(rates, bad, o.index);
    if (!std::isnan(m)) out[o.index] = m;
  }
  return out;
}

PhaseSeries apply_outliers(const PhaseSeries& phase, const std::vector<Outlier>& outliers, OutlierAction action) {
  if (action == OutlierAction::Keep || outliers.empty()) return phase;
  PhaseSeries out = phase;
  const std::size_t m = phase.points() > 0 ? phase.points() - 1 : 0;  // increments
  const auto bad = outlier_mask(m, outliers);
  if (phase.exact()) {
    // Work on the integer increments (modular differences, as PhaseSeries::diff).
    std::vector<double> inc(m);
    std::vector<std::int64_t> c(m);
    for (std::size_t i = 0; i < m; ++i) {
      c[i] = static_cast<std::int64_t>(static_cast<std::uint64_t>(phase.count(i + 1)) -
                                       static_cast<std::uint64_t>(phase.count(i)));
      inc[i] = static_cast<double>(c[i]);
    }
    if (action == OutlierAction::Replace)
      for (const auto& o : outliers)
        if (o.index < m) {
          const double med = local_median(inc, bad, o.index);
          if (!std::isnan(med)) c[o.index] = static_cast<std::int64_t>(std::llround(med));
        }
    out.counts32.clear();
    out.counts.assign(1, 0);
    std::uint64_t acc = 0;
    for (std::size_t i = 0; i < m; ++i) {
      if (action == OutlierAction::Remove && bad[i]) continue;
      acc += static_cast<std::uint64_t>(c[i]);
      out.counts.push_back(static_cast<std::int64_t>(acc));
    }
    return out;
  }
  std::vector<double> inc(m);
  for (std::size_t i = 0; i < m; ++i) inc[i] = phase.values[i + 1] - phase.values[i];
  if (action == OutlierAction::Replace)
    for (const auto& o : outliers)
      if (o.index < m) {
        const double med = local_median(inc, bad, o.index);
        if (!std::isnan(med)) inc[o.index] = med;
      }
  out.values.assign(1, phase.values.empty() ? 0.0 : phase.values.front());
  long double acc = out.values.front();
  for (std::size_t i = 0; i < m; ++i) {
    if (action == OutlierAction::Remove && bad[i]) continue;
    acc += inc[i];
    out.values.push_back(static_cast<double>(acc));
  }
  return out;
}

}  // namespace rwcalc
