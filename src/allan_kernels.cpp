// Hot loops of the Allan-variance estimators. Written as plain loops over contiguous arrays with
// several independent accumulators so that the compiler vectorises them; built for AVX2 and for
// the baseline ISA, the better one chosen at load time (function multiversioning).
#include "allan_kernels.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define RWCALC_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RWCALC_CLONES
#endif

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

}  // namespace rwcalc::detail
