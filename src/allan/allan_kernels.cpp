// Hot loops of the Allan-variance estimators. Written as plain loops over contiguous arrays with
// several independent accumulators so that the compiler vectorises them; built for AVX2 and for
// the baseline ISA, the better one chosen at load time (function multiversioning).
#include "allan/allan_kernels.hpp"

#include "rwcalc/crew.hpp"
#include "rwcalc/thread.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define RWCALC_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RWCALC_CLONES
#endif
#include "allan/x86_dispatch.hpp"

namespace rwcalc::detail {

namespace {

constexpr int kLanes = 8;
// Block length and magnitude limit of the exact floating path: with |d| ≤ 2^21 every square is an
// integer ≤ 2^42 and a block of 1024 sums to ≤ 2^52, so every partial sum is an exactly
// representable integer and the block total is exact whatever the summation order.
constexpr std::int64_t kBlock = 1024;
constexpr std::uint64_t kHalfRange = std::uint64_t{1} << 21;

// int64 → double without a scalar conversion instruction: exact for |d| < 2^51 (the magic
// constant 1.5·2^52 puts d in the mantissa). Out-of-range blocks are redone exactly anyway.
inline double to_double_small(std::uint64_t d) {
  constexpr std::uint64_t kMagicBits = 0x4338000000000000ULL;  // bit pattern of 1.5·2^52
  constexpr double kMagic = 6755399441055744.0;
  return std::bit_cast<double>(d + kMagicBits) - kMagic;
}

inline std::int64_t second_diff(const std::int64_t* c, std::int64_t k, std::int64_t m) {
  const auto a = static_cast<std::uint64_t>(c[k]);
  const auto b = static_cast<std::uint64_t>(c[k + m]);
  const auto e = static_cast<std::uint64_t>(c[k + 2 * m]);
  return static_cast<std::int64_t>(e - 2 * b + a);
}

u128 exact_block(const std::int64_t* c, std::int64_t k0, std::int64_t len, std::int64_t m,
                 std::int64_t stride) {
  u128 s = 0;
  for (std::int64_t i = 0; i < len; ++i) {
    const i128 d = second_diff(c, k0 + i * stride, m);
    s += static_cast<u128>(d * d);
  }
  return s;
}

RWCALC_CLONES
bool block_sumsq_contiguous(const std::int64_t* __restrict a, const std::int64_t* __restrict b,
                            const std::int64_t* __restrict e, std::int64_t len, double* out) {
  double acc[kLanes] = {};
  std::uint64_t range[kLanes] = {};
  std::int64_t i = 0;
  for (; i + kLanes <= len; i += kLanes) {
    for (int j = 0; j < kLanes; ++j) {
      const std::uint64_t d = static_cast<std::uint64_t>(e[i + j]) - 2 * static_cast<std::uint64_t>(b[i + j]) +
                              static_cast<std::uint64_t>(a[i + j]);
      range[j] |= d + kHalfRange;
      const double v = to_double_small(d);
      acc[j] += v * v;
    }
  }
  for (; i < len; ++i) {
    const std::uint64_t d =
        static_cast<std::uint64_t>(e[i]) - 2 * static_cast<std::uint64_t>(b[i]) + static_cast<std::uint64_t>(a[i]);
    range[0] |= d + kHalfRange;
    const double v = to_double_small(d);
    acc[0] += v * v;
  }
  std::uint64_t r = 0;
  double s = 0;
  for (int j = 0; j < kLanes; ++j) {
    r |= range[j];
    s += acc[j];
  }
  *out = s;
  return (r >> 22) == 0;  // every d + 2^21 < 2^22, i.e. −2^21 ≤ d < 2^21
}

}  // namespace

u128 second_diff_sumsq_counts(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  u128 total = 0;
  if (stride != 1) {  // non-overlapping: few terms, strided; exact 128-bit path
    return exact_block(c, 0, n, m, stride);
  }
  for (std::int64_t k0 = 0; k0 < n; k0 += kBlock) {
    const std::int64_t len = std::min(kBlock, n - k0);
    double s = 0;
    if (block_sumsq_contiguous(c + k0, c + k0 + m, c + k0 + 2 * m, len, &s))
      total += static_cast<std::uint64_t>(s);
    else
      total += exact_block(c, k0, len, m, 1);
  }
  return total;
}

RWCALC_CLONES
double second_diff_sumsq_values(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride) {
  double acc[kLanes] = {};
  if (stride == 1) {
    const double* __restrict a = x;
    const double* __restrict b = x + m;
    const double* __restrict e = x + 2 * m;
    std::int64_t i = 0;
    for (; i + kLanes <= n; i += kLanes) {
      for (int j = 0; j < kLanes; ++j) {
        const double d = e[i + j] - 2.0 * b[i + j] + a[i + j];
        acc[j] += d * d;
      }
    }
    for (; i < n; ++i) {
      const double d = e[i] - 2.0 * b[i] + a[i];
      acc[0] += d * d;
    }
  } else {
    for (std::int64_t i = 0; i < n; ++i) {
      const std::int64_t k = i * stride;
      const double d = x[k + 2 * m] - 2.0 * x[k + m] + x[k];
      acc[i % kLanes] += d * d;
    }
  }
  double s = 0;
  for (double v : acc) s += v;
  return s;
}

RWCALC_CLONES
double modified_sumsq_counts(const std::uint64_t* prefix, std::int64_t n, std::int64_t m) {
  const std::uint64_t* __restrict p0 = prefix;
  const std::uint64_t* __restrict p1 = prefix + m;
  const std::uint64_t* __restrict p2 = prefix + 2 * m;
  const std::uint64_t* __restrict p3 = prefix + 3 * m;
  double acc[kLanes] = {};
  std::int64_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int j = 0; j < kLanes; ++j) {
      // S_j = P[j+3m] − 3P[j+2m] + 3P[j+m] − P[j]: exact modulo 2^64, hence exact as int64.
      const std::uint64_t s = p3[i + j] - 3 * p2[i + j] + 3 * p1[i + j] - p0[i + j];
      const double v = static_cast<double>(static_cast<std::int64_t>(s));
      acc[j] += v * v;
    }
  }
  for (; i < n; ++i) {
    const std::uint64_t s = p3[i] - 3 * p2[i] + 3 * p1[i] - p0[i];
    const double v = static_cast<double>(static_cast<std::int64_t>(s));
    acc[0] += v * v;
  }
  double s = 0;
  for (double v : acc) s += v;
  return s;
}

double modified_sumsq_values(const double* x, std::int64_t n, std::int64_t m) {
  // Running sums S_{j+1} = S_j + z_{j+m} − z_j in up to kLanes interleaved segments, each started
  // from a direct O(m) sum, so the dependency chains run side by side and rounding drift stays
  // short. Fewer segments when m is large compared with the number of terms.
  auto z = [x, m](std::int64_t i) { return x[i + 2 * m] - 2.0 * x[i + m] + x[i]; };
  const std::int64_t lanes = std::clamp<std::int64_t>(n / (4 * m), 1, kLanes);
  const std::int64_t seg = (n + lanes - 1) / lanes;
  double acc[kLanes] = {};
  double s[kLanes] = {};
  std::int64_t start[kLanes] = {}, stop[kLanes] = {};
  for (std::int64_t j = 0; j < lanes; ++j) {
    start[j] = std::min(n, j * seg);
    stop[j] = std::min(n, start[j] + seg);
    if (start[j] < stop[j])
      for (std::int64_t i = start[j]; i < start[j] + m; ++i) s[j] += z(i);
  }
  for (std::int64_t t = 0; t < seg; ++t) {
    for (std::int64_t j = 0; j < lanes; ++j) {
      const std::int64_t jj = start[j] + t;
      if (jj >= stop[j]) continue;
      acc[j] += s[j] * s[j];
      if (jj + 1 < stop[j]) s[j] += z(jj + m) - z(jj);
    }
  }
  double total = 0;
  for (double v : acc) total += v;
  return total;
}

std::vector<std::uint64_t> count_prefix_sums(const std::vector<std::int64_t>& c) {
  std::vector<std::uint64_t> p;
  p.reserve(c.size() + 1);
  std::uint64_t run = 0;
  p.push_back(run);
  for (std::int64_t v : c) {
    run += static_cast<std::uint64_t>(v);
    p.push_back(run);
  }
  return p;
}

namespace {

// GCC/Clang vector extensions: four lanes of double, four of int32; the AVX2 clone maps them
// onto single instructions (vcvtdq2pd, vmaxpd, vfmadd…), the baseline clone onto SSE2 pairs.
typedef double v4d __attribute__((vector_size(32)));
typedef std::int32_t v4i __attribute__((vector_size(16)));

// A macro rather than a function: a function returning v4d would be compiled for the baseline ISA.
#define RWCALC_LOAD_V4D(p) __builtin_convertvector(load_v4i(p), v4d)
inline v4i load_v4i(const std::int32_t* p) {
  v4i v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

bool block_sumsq_i32_generic(const std::int32_t* __restrict a, const std::int32_t* __restrict b,
                     const std::int32_t* __restrict e, std::int64_t len, double* out) {
  v4d acc0 = {}, acc1 = {}, mx0 = {}, mx1 = {};
  std::int64_t i = 0;
  for (; i + 8 <= len; i += 8) {
    // |values| < 2^30, so d is an exact double; d² is exact while |d| ≤ 2^21 (checked below).
    const v4d d0 = RWCALC_LOAD_V4D(e + i) - 2.0 * RWCALC_LOAD_V4D(b + i) + RWCALC_LOAD_V4D(a + i);
    const v4d d1 = RWCALC_LOAD_V4D(e + i + 4) - 2.0 * RWCALC_LOAD_V4D(b + i + 4) + RWCALC_LOAD_V4D(a + i + 4);
    const v4d s0 = d0 * d0, s1 = d1 * d1;
    acc0 += s0;
    acc1 += s1;
    mx0 = mx0 > s0 ? mx0 : s0;
    mx1 = mx1 > s1 ? mx1 : s1;
  }
  double s = 0, top = 0;
  for (int j = 0; j < 4; ++j) {
    s += acc0[j] + acc1[j];
    top = std::max({top, mx0[j], mx1[j]});
  }
  for (; i < len; ++i) {
    const double d = static_cast<double>(e[i]) - 2.0 * static_cast<double>(b[i]) + static_cast<double>(a[i]);
    top = std::max(top, d * d);
    s += d * d;
  }
  *out = s;
  return top <= static_cast<double>(kHalfRange) * static_cast<double>(kHalfRange);
}

#if RWCALC_X86_DISPATCH
// The same block with AVX2 intrinsics: GCC's generic tuning splits the int32 → double vector
// conversion into halves, which doubles the cost of the loop. Four accumulators hide the add
// latency. d = fma(−2, b, e + a) is exact: every step is an integer below 2^33.
__attribute__((target("avx2,fma"))) bool block_sumsq_i32_avx2(const std::int32_t* __restrict a,
                                                              const std::int32_t* __restrict b,
                                                              const std::int32_t* __restrict e,
                                                              std::int64_t len, double* out) {
  const __m256d minus2 = _mm256_set1_pd(-2.0);
  __m256d acc[4], mx[4];
  for (int j = 0; j < 4; ++j) acc[j] = mx[j] = _mm256_setzero_pd();
#define RWCALC_LOAD4(p) _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)))
  std::int64_t i = 0;
  for (; i + 16 <= len; i += 16) {
    for (int j = 0; j < 4; ++j) {
      const std::int64_t o = i + 4 * j;
      const __m256d d = _mm256_fmadd_pd(minus2, RWCALC_LOAD4(b + o), _mm256_add_pd(RWCALC_LOAD4(e + o), RWCALC_LOAD4(a + o)));
      const __m256d sq = _mm256_mul_pd(d, d);
      acc[j] = _mm256_add_pd(acc[j], sq);
      mx[j] = _mm256_max_pd(mx[j], sq);
    }
  }
#undef RWCALC_LOAD4
  alignas(32) double lanes[4], tops[4];
  _mm256_store_pd(lanes, _mm256_add_pd(_mm256_add_pd(acc[0], acc[1]), _mm256_add_pd(acc[2], acc[3])));
  _mm256_store_pd(tops, _mm256_max_pd(_mm256_max_pd(mx[0], mx[1]), _mm256_max_pd(mx[2], mx[3])));
  double s = lanes[0] + lanes[1] + lanes[2] + lanes[3];
  double top = std::max({tops[0], tops[1], tops[2], tops[3]});
  for (; i < len; ++i) {
    const double d = static_cast<double>(e[i]) - 2.0 * static_cast<double>(b[i]) + static_cast<double>(a[i]);
    top = std::max(top, d * d);
    s += d * d;
  }
  *out = s;
  return top <= static_cast<double>(kHalfRange) * static_cast<double>(kHalfRange);
}
#endif

#if RWCALC_X86_DISPATCH
// All-integer block for offsets below 2^29 in magnitude: d = e + a − 2b cannot leave int32
// (|d| < 2^31), so it is formed in 32-bit lanes, eight at a time, and squared exactly into 64-bit
// lanes (vpmuldq on the even and the shifted odd lanes). Exact while every |d| < 2^26: a lane then
// holds at most len/8 squares below 2^52 (len ≤ 1024 keeps the sum below 2^62).
__attribute__((target("avx2"))) bool block_sumsq_i29_avx2(const std::int32_t* __restrict a,
                                                          const std::int32_t* __restrict b,
                                                          const std::int32_t* __restrict e, std::int64_t len,
                                                          std::uint64_t* out) {
  __m256i acc0 = _mm256_setzero_si256(), acc1 = _mm256_setzero_si256(), top = _mm256_setzero_si256();
  std::int64_t i = 0;
  for (; i + 8 <= len; i += 8) {
    const __m256i va = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + i));
    const __m256i vb = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + i));
    const __m256i ve = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(e + i));
    const __m256i d = _mm256_sub_epi32(_mm256_add_epi32(ve, va), _mm256_add_epi32(vb, vb));
    top = _mm256_max_epu32(top, _mm256_abs_epi32(d));
    const __m256i hi = _mm256_srli_epi64(d, 32);
    acc0 = _mm256_add_epi64(acc0, _mm256_mul_epi32(d, d));
    acc1 = _mm256_add_epi64(acc1, _mm256_mul_epi32(hi, hi));
  }
  alignas(32) std::uint64_t lanes[4];
  alignas(32) std::uint32_t tops[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), _mm256_add_epi64(acc0, acc1));
  _mm256_store_si256(reinterpret_cast<__m256i*>(tops), top);
  std::uint64_t s = lanes[0] + lanes[1] + lanes[2] + lanes[3];
  std::uint32_t t = 0;
  for (std::uint32_t v : tops) t = std::max(t, v);
  for (; i < len; ++i) {
    const std::int64_t d = std::int64_t{e[i]} + std::int64_t{a[i]} - 2 * std::int64_t{b[i]};
    t = std::max(t, static_cast<std::uint32_t>(d < 0 ? -d : d));
    s += static_cast<std::uint64_t>(d * d);
  }
  *out = s;
  return t < (std::uint32_t{1} << 26);
}
#endif

#if RWCALC_X86_DISPATCH
// The same sum when every |C_k − C_0| < 2^24 (PreparedCounts::small24): then |d| ≤ |e| + |a| + 2|b| < 2^26
// for every term, so the range check of block_sumsq_i29_avx2 is not needed; a 64-bit lane
// holds up to 1024 squares below 2^52, and a block of 4096 terms sums to below 2^64 (blocks of 4096,
// sixteen terms per iteration in four accumulators). The result is the exact integer sum, as above.
constexpr std::int64_t kBlock24 = 4096;
__attribute__((target("avx2"))) std::uint64_t block_sumsq_i24_avx2(const std::int32_t* __restrict a,
                                                                   const std::int32_t* __restrict b,
                                                                   const std::int32_t* __restrict e,
                                                                   std::int64_t len) {
  __m256i acc0 = _mm256_setzero_si256(), acc1 = _mm256_setzero_si256();
  __m256i acc2 = _mm256_setzero_si256(), acc3 = _mm256_setzero_si256();
#define RWCALC_LOAD8(p) _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))
  std::int64_t i = 0;
  for (; i + 16 <= len; i += 16) {
    const __m256i vb0 = RWCALC_LOAD8(b + i), vb1 = RWCALC_LOAD8(b + i + 8);
    const __m256i d0 = _mm256_sub_epi32(_mm256_add_epi32(RWCALC_LOAD8(e + i), RWCALC_LOAD8(a + i)),
                                        _mm256_add_epi32(vb0, vb0));
    const __m256i d1 = _mm256_sub_epi32(_mm256_add_epi32(RWCALC_LOAD8(e + i + 8), RWCALC_LOAD8(a + i + 8)),
                                        _mm256_add_epi32(vb1, vb1));
    const __m256i h0 = _mm256_srli_epi64(d0, 32), h1 = _mm256_srli_epi64(d1, 32);
    acc0 = _mm256_add_epi64(acc0, _mm256_mul_epi32(d0, d0));
    acc1 = _mm256_add_epi64(acc1, _mm256_mul_epi32(h0, h0));
    acc2 = _mm256_add_epi64(acc2, _mm256_mul_epi32(d1, d1));
    acc3 = _mm256_add_epi64(acc3, _mm256_mul_epi32(h1, h1));
  }
#undef RWCALC_LOAD8
  alignas(32) std::uint64_t lanes[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes),
                     _mm256_add_epi64(_mm256_add_epi64(acc0, acc1), _mm256_add_epi64(acc2, acc3)));
  std::uint64_t s = lanes[0] + lanes[1] + lanes[2] + lanes[3];  // len ≤ 4096 squares < 2^52: < 2^64
  for (; i < len; ++i) {
    const std::int64_t d = std::int64_t{e[i]} + std::int64_t{a[i]} - 2 * std::int64_t{b[i]};
    s += static_cast<std::uint64_t>(d * d);
  }
  return s;
}
#endif

#if RWCALC_X86_DISPATCH
// The same exact sum with AVX-512: sixteen 32-bit differences per vector, squared into eight
// 64-bit lanes twice (vpmuldq on the even and the shifted odd lanes); 32 terms per iteration in
// four accumulators. A lane holds at most 4096/16 = 256 squares below 2^52; the block sum stays
// below 2^64 as above. Integer operations only: the same sum as the AVX2 kernel, bit for bit.
// (GCC 12's AVX-512 headers trip its own uninitialised-value warnings: silenced here only.)
RWCALC_AVX512_WARNINGS_OFF
__attribute__((target("avx512f"))) std::uint64_t block_sumsq_i24_avx512(const std::int32_t* __restrict a,
                                                                         const std::int32_t* __restrict b,
                                                                         const std::int32_t* __restrict e,
                                                                         std::int64_t len) {
  __m512i acc0 = _mm512_setzero_si512(), acc1 = _mm512_setzero_si512();
  __m512i acc2 = _mm512_setzero_si512(), acc3 = _mm512_setzero_si512();
  std::int64_t i = 0;
  for (; i + 32 <= len; i += 32) {
    const __m512i vb0 = _mm512_loadu_si512(b + i), vb1 = _mm512_loadu_si512(b + i + 16);
    const __m512i d0 = _mm512_sub_epi32(_mm512_add_epi32(_mm512_loadu_si512(e + i), _mm512_loadu_si512(a + i)),
                                        _mm512_add_epi32(vb0, vb0));
    const __m512i d1 = _mm512_sub_epi32(
        _mm512_add_epi32(_mm512_loadu_si512(e + i + 16), _mm512_loadu_si512(a + i + 16)), _mm512_add_epi32(vb1, vb1));
    const __m512i h0 = _mm512_srli_epi64(d0, 32), h1 = _mm512_srli_epi64(d1, 32);
    acc0 = _mm512_add_epi64(acc0, _mm512_mul_epi32(d0, d0));
    acc1 = _mm512_add_epi64(acc1, _mm512_mul_epi32(h0, h0));
    acc2 = _mm512_add_epi64(acc2, _mm512_mul_epi32(d1, d1));
    acc3 = _mm512_add_epi64(acc3, _mm512_mul_epi32(h1, h1));
  }
  // The lanes are added as unsigned (the block's sum is below 2^64, a lane's below 2^63 is not
  // promised once the four accumulators are combined): no signed reduction.
  alignas(64) std::uint64_t lanes[8];
  _mm512_store_si512(lanes, _mm512_add_epi64(_mm512_add_epi64(acc0, acc1), _mm512_add_epi64(acc2, acc3)));
  std::uint64_t s = 0;
  for (std::uint64_t v : lanes) s += v;
  for (; i < len; ++i) {
    const std::int64_t d = std::int64_t{e[i]} + std::int64_t{a[i]} - 2 * std::int64_t{b[i]};
    s += static_cast<std::uint64_t>(d * d);
  }
  return s;
}
RWCALC_AVX512_WARNINGS_ON

using SumsqI24 = std::uint64_t (*)(const std::int32_t*, const std::int32_t*, const std::int32_t*, std::int64_t);
/// The widest of the two kernels this processor runs (AVX-512 where the OS keeps its registers).
SumsqI24 sumsq_i24_kernel() {
  static const SumsqI24 k = __builtin_cpu_supports("avx512f") ? block_sumsq_i24_avx512 : block_sumsq_i24_avx2;
  return k;
}
#endif

bool block_sumsq_i32(const std::int32_t* a, const std::int32_t* b, const std::int32_t* e, std::int64_t len,
                     double* out) {
#if RWCALC_X86_DISPATCH
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) return block_sumsq_i32_avx2(a, b, e, len, out);
#endif
  return block_sumsq_i32_generic(a, b, e, len, out);
}

u128 exact_block_i32(const std::int32_t* c, std::int64_t k0, std::int64_t len, std::int64_t m, std::int64_t stride) {
  u128 s = 0;
  for (std::int64_t i = 0; i < len; ++i) {
    const std::int64_t k = k0 + i * stride;
    const std::int64_t d = std::int64_t{c[k + 2 * m]} - 2 * std::int64_t{c[k + m]} + std::int64_t{c[k]};
    s += static_cast<u128>(static_cast<i128>(d) * d);
  }
  return s;
}

RWCALC_CLONES
double modified_sumsq_f64_prefix(const double* prefix, std::int64_t n, std::int64_t m) {
  const double* __restrict p0 = prefix;
  const double* __restrict p1 = prefix + m;
  const double* __restrict p2 = prefix + 2 * m;
  const double* __restrict p3 = prefix + 3 * m;
  double acc[kLanes] = {};
  std::int64_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int j = 0; j < kLanes; ++j) {
      const double s = (p3[i + j] - p0[i + j]) - 3.0 * (p2[i + j] - p1[i + j]);  // exact integers
      acc[j] += s * s;
    }
  }
  for (; i < n; ++i) {
    const double s = (p3[i] - p0[i]) - 3.0 * (p2[i] - p1[i]);
    acc[0] += s * s;
  }
  double t = 0;
  for (double v : acc) t += v;
  return t;
}

// The offsets pass of prepare_counts: out[i] = (int32)(in[i] − c0) for i in [begin, end), with the
// smallest and largest offset (as int64). Scalar; GCC leaves it unvectorised at -O2.
void offsets_pass_scalar(const std::int64_t* __restrict in, std::int32_t* __restrict out, std::size_t begin,
                         std::size_t end, std::uint64_t c0, std::int64_t& lo_out, std::int64_t& hi_out) {
  std::int64_t lo = 0, hi = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const auto r = static_cast<std::int64_t>(static_cast<std::uint64_t>(in[i]) - c0);
    lo = r < lo ? r : lo;
    hi = r > hi ? r : hi;
    out[i] = static_cast<std::int32_t>(r);
  }
  lo_out = lo;
  hi_out = hi;
}

#if RWCALC_X86_DISPATCH
// The same, eight offsets per step: four int64 lanes twice, min/max by compare and blend, the low
// halves packed into eight int32. Integer operations only, so the same values as the scalar pass.
__attribute__((target("avx2"))) void offsets_pass_avx2(const std::int64_t* __restrict in,
                                                       std::int32_t* __restrict out, std::size_t begin,
                                                       std::size_t end, std::uint64_t c0, std::int64_t& lo_out,
                                                       std::int64_t& hi_out) {
  const __m256i base = _mm256_set1_epi64x(static_cast<std::int64_t>(c0));
  const __m256i low_halves = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  __m256i lo = _mm256_setzero_si256(), hi = _mm256_setzero_si256();
  std::size_t i = begin;
  for (; i + 8 <= end; i += 8) {
    const __m256i a = _mm256_sub_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i)), base);
    const __m256i b = _mm256_sub_epi64(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i + 4)), base);
    lo = _mm256_blendv_epi8(lo, a, _mm256_cmpgt_epi64(lo, a));
    hi = _mm256_blendv_epi8(hi, a, _mm256_cmpgt_epi64(a, hi));
    lo = _mm256_blendv_epi8(lo, b, _mm256_cmpgt_epi64(lo, b));
    hi = _mm256_blendv_epi8(hi, b, _mm256_cmpgt_epi64(b, hi));
    const __m128i pa = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(a, low_halves));
    const __m128i pb = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(b, low_halves));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), _mm256_set_m128i(pb, pa));
  }
  alignas(32) std::int64_t l[4], h[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(l), lo);
  _mm256_store_si256(reinterpret_cast<__m256i*>(h), hi);
  std::int64_t tl = 0, th = 0;
  offsets_pass_scalar(in, out, i, end, c0, tl, th);
  for (int k = 0; k < 4; ++k) {
    tl = std::min(tl, l[k]);
    th = std::max(th, h[k]);
  }
  lo_out = tl;
  hi_out = th;
}
#endif

#if RWCALC_X86_DISPATCH
// The same with AVX-512: eight int64 offsets per vector, min/max in 64-bit lanes, the low halves
// narrowed by vpmovqd. Integer operations only, so the same values as the scalar pass.
RWCALC_AVX512_WARNINGS_OFF
__attribute__((target("avx512f"))) void offsets_pass_avx512(const std::int64_t* __restrict in,
                                                           std::int32_t* __restrict out, std::size_t begin,
                                                           std::size_t end, std::uint64_t c0, std::int64_t& lo_out,
                                                           std::int64_t& hi_out) {
  const __m512i base = _mm512_set1_epi64(static_cast<std::int64_t>(c0));
  __m512i lo = _mm512_setzero_si512(), hi = _mm512_setzero_si512();
  __m512i lo2 = lo, hi2 = hi;
  std::size_t i = begin;
  for (; i + 16 <= end; i += 16) {
    const __m512i a = _mm512_sub_epi64(_mm512_loadu_si512(in + i), base);
    const __m512i b = _mm512_sub_epi64(_mm512_loadu_si512(in + i + 8), base);
    lo = _mm512_min_epi64(lo, a);
    hi = _mm512_max_epi64(hi, a);
    lo2 = _mm512_min_epi64(lo2, b);
    hi2 = _mm512_max_epi64(hi2, b);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), _mm512_cvtepi64_epi32(a));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i + 8), _mm512_cvtepi64_epi32(b));
  }
  std::int64_t tl = 0, th = 0;
  offsets_pass_scalar(in, out, i, end, c0, tl, th);
  lo_out = std::min<std::int64_t>(tl, _mm512_reduce_min_epi64(_mm512_min_epi64(lo, lo2)));
  hi_out = std::max<std::int64_t>(th, _mm512_reduce_max_epi64(_mm512_max_epi64(hi, hi2)));
}
RWCALC_AVX512_WARNINGS_ON
#endif

}  // namespace

namespace {
// Modular 64-bit prefix sums of the counts: of `raw`, or of the view's offsets when the series
// holds no 64-bit counts (an offset common to all counts cancels in the modified variance).
std::vector<std::uint64_t> wide_prefix_sums(const PreparedCounts& p) {
  return count_prefix_sums(p.raw ? *p.raw : std::vector<std::int64_t>(p.view, p.view + p.points));
}

// The range flags of the view's offsets (largest |C_k − C_0| = top) and, for the modified
// variance, the prefix sums: exact doubles from the view while 8·top·(N+1) < 2^53 (then the
// prefix sums and S = (P3 − P0) − 3(P2 − P1) stay exact), else modular 64-bit sums.
void finish_prepared(PreparedCounts& p, std::uint64_t top, bool need_prefix) {
  p.small29 = top < (std::uint64_t{1} << 29);
  p.small24 = top < (std::uint64_t{1} << 24);
  if (!need_prefix) return;
  const double bound = 8.0 * static_cast<double>(top) * static_cast<double>(p.points + 1);
  if (p.view && bound < 9007199254740992.0) {
    p.prefix_f64.resize(p.points + 1);
    double run = 0;
    p.prefix_f64[0] = 0;
    for (std::size_t i = 0; i < p.points; ++i) {
      run += static_cast<double>(p.view[i]);
      p.prefix_f64[i + 1] = run;
    }
  } else {
    p.prefix_u64 = wide_prefix_sums(p);
  }
}

// Records of at least this many points share their range passes with a crew.
constexpr std::size_t kSharedRangeFrom = std::size_t{1} << 20;

/// pass(begin, end, lo, hi) over [0, n) in stretches of 2^18 that the calling thread and the
/// crew's lenders take as they are free; lo and hi the smallest and largest of the stretches'.
template <class Pass>
void shared_range(Crew& crew, std::size_t n, Pass&& pass, std::int64_t& lo, std::int64_t& hi) {
  constexpr std::size_t kStretch = std::size_t{1} << 18;
  const std::size_t parts = (n + kStretch - 1) / kStretch;
  std::vector<std::int64_t> los(parts, 0), his(parts, 0);
  crew.share(parts, [&](std::size_t k) { pass(k * kStretch, std::min(n, (k + 1) * kStretch), los[k], his[k]); });
  lo = *std::min_element(los.begin(), los.end());
  hi = *std::max_element(his.begin(), his.end());
}

}  // namespace

PreparedCounts prepare_counts(const std::vector<std::int64_t>& c, bool need_prefix, unsigned threads, Crew* crew) {
  PreparedCounts p;
  p.raw = &c;
  p.points = c.size();
  if (c.empty()) return p;
  const auto c0 = static_cast<std::uint64_t>(c[0]);
  constexpr std::int64_t kLimit = std::int64_t{1} << 30;
  // One branch-free (vectorisable) pass: offsets, their range, and the int32 copy; the copy is
  // dropped if the range turns out too wide.
  p.rel32.resize(c.size());  // uninitialised: the pages are mapped in one call, then written once
#if RWCALC_X86_DISPATCH
  static const bool avx2 = __builtin_cpu_supports("avx2");
  static const bool avx512 = __builtin_cpu_supports("avx512f");
#else
  constexpr bool avx2 = false;
#endif
  auto pass = [&c, c0, &p](std::size_t begin, std::size_t end, std::int64_t& lo_out, std::int64_t& hi_out) {
#if RWCALC_X86_DISPATCH
    if (avx512) return offsets_pass_avx512(c.data(), p.rel32.data(), begin, end, c0, lo_out, hi_out);
    if (avx2) return offsets_pass_avx2(c.data(), p.rel32.data(), begin, end, c0, lo_out, hi_out);
#endif
    offsets_pass_scalar(c.data(), p.rel32.data(), begin, end, c0, lo_out, hi_out);
  };
  std::int64_t lo = 0, hi = 0;
  if (crew && c.size() >= kSharedRangeFrom) {  // stretches for whoever is free
    shared_range(*crew, c.size(), pass, lo, hi);
  } else if (threads > 1 && c.size() >= kSharedRangeFrom) {  // long records: the two halves side by side
    std::int64_t lo2 = 0, hi2 = 0;
    const std::size_t mid = c.size() / 2;
    {
      Thread helper([&] { pass(mid, c.size(), lo2, hi2); });
      pass(0, mid, lo, hi);
    }
    lo = std::min(lo, lo2);
    hi = std::max(hi, hi2);
  } else {
    pass(0, c.size(), lo, hi);
  }
  const bool small = lo > -kLimit && hi < kLimit;
  // lo ≤ 0 ≤ hi (the first offset is 0); |lo| in unsigned arithmetic, exact even for lo = −2^63.
  const std::uint64_t top = std::max(std::uint64_t{0} - static_cast<std::uint64_t>(lo), static_cast<std::uint64_t>(hi));
  if (!small) {
    p.rel32.clear();
    p.rel32.shrink_to_fit();
  } else {
    p.view = p.rel32.data();
  }
  finish_prepared(p, top, need_prefix);
  return p;
}

namespace {

// Smallest and largest of n int32 values (0 included).
RWCALC_CLONES
void range_i32(const std::int32_t* c, std::size_t n, std::int64_t& lo_out, std::int64_t& hi_out) {
  std::int32_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = c[i] < lo ? c[i] : lo;
    hi = c[i] > hi ? c[i] : hi;
  }
  lo_out = lo;
  hi_out = hi;
}

}  // namespace

PreparedCounts prepare_counts(const PhaseSeries& x, bool need_prefix, unsigned threads, Crew* crew) {
  if (!x.narrow()) return prepare_counts(x.counts, need_prefix, threads, crew);
  PreparedCounts p;
  const std::vector<std::int32_t>& c = x.counts32;
  p.points = c.size();
  if (c[0] == 0) {
    p.view = c.data();  // C_0 = 0: the offsets are the counts themselves
  } else {  // |C_k| < 2^30 (PhaseSeries::counts32), so every C_k − C_0 fits
    p.rel32.resize(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) p.rel32[i] = c[i] - c[0];
    p.view = p.rel32.data();
  }
  std::int64_t lo = 0, hi = 0;
  if (crew && c.size() >= kSharedRangeFrom) {  // stretches for whoever is free
    shared_range(
        *crew, c.size(),
        [&p](std::size_t b, std::size_t e, std::int64_t& l, std::int64_t& h) { range_i32(p.view + b, e - b, l, h); }, lo,
        hi);
  } else {
    range_i32(p.view, c.size(), lo, hi);
  }
  finish_prepared(p, static_cast<std::uint64_t>(std::max(-lo, hi)), need_prefix);
  return p;
}

PreparedCounts prepare_second_differences(const PhaseSeries& x) {
  constexpr std::int64_t kLimit = std::int64_t{1} << 30;
  if (x.narrow() || x.counts.size() < 2) return prepare_counts(x, false);
  const std::vector<std::int64_t>& c = x.counts;
  // The last offset is the span C_{P−1} − C_0: at 2^30 or more the plain view cannot be made, and
  // its pass over the counts is not taken at all.
  const i128 span = static_cast<i128>(c.back()) - static_cast<i128>(c.front());
  // s = round(span/(P − 1)), the line's whole pulses per sample.
  const auto steps = static_cast<i128>(c.size() - 1);
  const i128 half = steps / 2;
  const i128 s128 = span >= 0 ? (span + half) / steps : -((-span + half) / steps);
  if (span > -kLimit && span < kLimit) {
    PreparedCounts plain = prepare_counts(x, false);
    if (plain.view || s128 == 0) return plain;  // a line of 0 pulses per sample changes nothing
  }
  PreparedCounts p;
  p.raw = &c;
  p.points = c.size();
  // The offsets from the line modulo 2^64 (their second differences are exact in that ring, and
  // so in the int32 range checked below).
  const auto s = static_cast<std::uint64_t>(static_cast<std::int64_t>(s128));
  std::int64_t lo = 0, hi = 0;
  p.rel32.resize(c.size());
  std::uint64_t line = static_cast<std::uint64_t>(c.front());
  for (std::size_t k = 0; k < c.size(); ++k, line += s) {
    const auto d = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[k]) - line);
    lo = d < lo ? d : lo;
    hi = d > hi ? d : hi;
    p.rel32[k] = static_cast<std::int32_t>(d);
  }
  if (lo <= -kLimit || hi >= kLimit) {  // wide even off the line: the 64-bit sums
    p.rel32.clear();
    p.rel32.shrink_to_fit();
    return p;
  }
  p.view = p.rel32.data();
  finish_prepared(p, static_cast<std::uint64_t>(std::max(-lo, hi)), false);
  return p;
}

u128 second_diff_sumsq(const PreparedCounts& c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  if (!c.view) return second_diff_sumsq_counts(c.raw->data(), n, m, stride);
  const std::int32_t* r = c.view;
  if (stride != 1) return exact_block_i32(r, 0, n, m, stride);
  u128 total = 0;
#if RWCALC_X86_DISPATCH
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && c.small24) {
    const SumsqI24 kernel = sumsq_i24_kernel();
    for (std::int64_t k0 = 0; k0 < n; k0 += kBlock24) {
      const std::int64_t len = std::min(kBlock24, n - k0);
      total += kernel(r + k0, r + k0 + m, r + k0 + 2 * m, len);
    }
    return total;
  }
  if (avx2 && c.small29) {
    for (std::int64_t k0 = 0; k0 < n; k0 += kBlock) {
      const std::int64_t len = std::min(kBlock, n - k0);
      std::uint64_t s = 0;
      if (block_sumsq_i29_avx2(r + k0, r + k0 + m, r + k0 + 2 * m, len, &s))
        total += s;
      else
        total += exact_block_i32(r, k0, len, m, 1);
    }
    return total;
  }
#endif
  for (std::int64_t k0 = 0; k0 < n; k0 += kBlock) {
    const std::int64_t len = std::min(kBlock, n - k0);
    double s = 0;
    if (block_sumsq_i32(r + k0, r + k0 + m, r + k0 + 2 * m, len, &s))
      total += static_cast<std::uint64_t>(s);
    else
      total += exact_block_i32(r, k0, len, m, 1);
  }
  return total;
}

namespace {

// Terms per stretch of the shared sweep (a multiple of both block lengths).
constexpr std::int64_t kSweepStretch = std::int64_t{1} << 16;

/// The sweep over 64-bit counts (no int32 view: offsets of 2^30 or more): for the terms k in
/// [from, to), in the blocks of kBlock terms that second_diff_sumsq_counts takes (from 0), the
/// sums of every τ of ms[first], ms[first + step], … added to out[i] while the block is cached.
/// The same blocks and kernels as per τ, so the same exact sums.
void sweep_terms64(const std::int64_t* c, std::int64_t np, const std::int64_t* ms, std::size_t count,
                   std::size_t first, std::size_t step, std::int64_t from, std::int64_t to, u128* out) {
  for (std::int64_t k0 = from; k0 < to; k0 += kBlock) {
    for (std::size_t i = first; i < count; i += step) {
      const std::int64_t m = ms[i], n = np - 2 * m;
      if (k0 >= n) continue;
      const std::int64_t len = std::min(kBlock, n - k0);
      double s = 0;
      if (block_sumsq_contiguous(c + k0, c + k0 + m, c + k0 + 2 * m, len, &s))
        out[i] += static_cast<std::uint64_t>(s);
      else
        out[i] += exact_block(c, k0, len, m, 1);
    }
  }
}

#if RWCALC_X86_DISPATCH
/// Whether the int32 sweep applies: AVX2, offsets below 2^24, an int32 view.
bool sweep_applies(const PreparedCounts& c) {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2 && c.small24 && c.view;
}

/// The sweep's work: for the terms k in [from, to), in blocks of kBlock24 taken for every τ of
/// ms[first], ms[first + step], … while in cache, the squared second differences added to out[i].
void sweep_terms(const PreparedCounts& c, std::int64_t np, const std::int64_t* ms, std::size_t count,
                 std::size_t first, std::size_t step, std::int64_t from, std::int64_t to, u128* out) {
  const std::int32_t* r = c.view;
  const SumsqI24 kernel = sumsq_i24_kernel();
  for (std::int64_t k0 = from; k0 < to; k0 += kBlock24) {
    for (std::size_t i = first; i < count; i += step) {
      const std::int64_t m = ms[i], n = np - 2 * m;
      if (k0 >= n) continue;
      out[i] += kernel(r + k0, r + k0 + m, r + k0 + 2 * m, std::min({kBlock24, n - k0, to - k0}));
    }
  }
}
#else
bool sweep_applies(const PreparedCounts&) { return false; }
void sweep_terms(const PreparedCounts&, std::int64_t, const std::int64_t*, std::size_t, std::size_t, std::size_t,
                 std::int64_t, std::int64_t, u128*) {}
#endif

/// Which sweep applies: the int32 one, the 64-bit one (counts without a view), or none.
enum class Sweep { None, View24, Wide };
Sweep sweep_kind(const PreparedCounts& c) {
  if (sweep_applies(c)) return Sweep::View24;
  if (!c.view && c.raw && !c.raw->empty()) return Sweep::Wide;
  return Sweep::None;
}

void sweep_any(Sweep kind, const PreparedCounts& c, std::int64_t np, const std::int64_t* ms, std::size_t count,
               std::size_t first, std::size_t step, std::int64_t from, std::int64_t to, u128* out) {
  if (kind == Sweep::View24)
    sweep_terms(c, np, ms, count, first, step, from, to, out);
  else
    sweep_terms64(c.raw->data(), np, ms, count, first, step, from, to, out);
}

}  // namespace

bool second_diff_sumsq_sweep(const PreparedCounts& c, std::size_t points, const std::int64_t* ms,
                             std::size_t count, std::size_t first, std::size_t step, u128* out) {
  const Sweep kind = sweep_kind(c);
  if (kind == Sweep::None || step == 0) return false;
  const auto np = static_cast<std::int64_t>(points);
  std::int64_t longest = 0;
  for (std::size_t i = first; i < count; i += step) {
    out[i] = 0;
    longest = std::max(longest, np - 2 * ms[i]);
  }
  sweep_any(kind, c, np, ms, count, first, step, 0, longest, out);
  return true;
}

bool second_diff_sumsq_sweep_shared(const PreparedCounts& c, std::size_t points, const std::int64_t* ms,
                                    std::size_t count, Crew& crew, u128* out) {
  const Sweep kind = sweep_kind(c);
  if (kind == Sweep::None || count == 0) return false;
  const auto np = static_cast<std::int64_t>(points);
  std::int64_t longest = 0;
  for (std::size_t i = 0; i < count; ++i) longest = std::max(longest, np - 2 * ms[i]);
  const auto parts = static_cast<std::size_t>(std::max<std::int64_t>(0, (longest + kSweepStretch - 1) / kSweepStretch));
  std::vector<u128> sums(parts * count, 0);
  crew.share(parts, [&](std::size_t k) {
    const std::int64_t from = static_cast<std::int64_t>(k) * kSweepStretch;
    sweep_any(kind, c, np, ms, count, 0, 1, from, std::min(longest, from + kSweepStretch), sums.data() + k * count);
  });
  for (std::size_t i = 0; i < count; ++i) {
    u128 total = 0;
    for (std::size_t k = 0; k < parts; ++k) total += sums[k * count + i];
    out[i] = total;
  }
  return true;
}

double modified_sumsq(const PreparedCounts& c, std::int64_t n, std::int64_t m) {
  if (!c.prefix_f64.empty()) return modified_sumsq_f64_prefix(c.prefix_f64.data(), n, m);
  if (!c.prefix_u64.empty()) return modified_sumsq_counts(c.prefix_u64.data(), n, m);
  const std::vector<std::uint64_t> p = wide_prefix_sums(c);
  return modified_sumsq_counts(p.data(), n, m);
}

}  // namespace rwcalc::detail
