// Inner loops of the Allan-variance estimators: plain loops over contiguous arrays, with several
// independent accumulators where the sum is floating, so that the compiler may vectorise them.
#include "allan_kernels.hpp"

#include <algorithm>
#include <array>
#include <optional>

#include "rwcalc/narrow_counts.hpp"
#include "rwcalc/parallel.hpp"

namespace rwcalc::detail {

namespace {

constexpr int kLanes = 8;  // accumulators of the floating sums (their order fixes the rounding)
// Terms per block of the exact sums (exact_sums.hpp).
constexpr auto kBlock = static_cast<std::int64_t>(kExactBlock);
// Terms per stretch of the sweep that one parallel_for item takes (a multiple of kBlock).
constexpr std::int64_t kStretch = std::int64_t{1} << 16;
// Terms per block of the floating sweep: a block's three streams of every m stay in the core's
// cache while it is taken for each m (octave lags share their streams: k + 2m is k + m of 2m).
constexpr std::int64_t kFloatBlock = 2048;
static_assert(kFloatBlock % kLanes == 0);

/// The d-th difference of the counts at lag m from k (2: Allan, 3: Hadamard), modulo 2^64: the
/// signed difference whenever it fits in int64, whatever the counter's offset.
template <int Order>
inline std::uint64_t difference(const std::int64_t* c, std::int64_t k, std::int64_t m) {
  auto at = [c, k, m](std::int64_t j) { return static_cast<std::uint64_t>(c[k + j * m]); };
  if constexpr (Order == 2)
    return at(2) - 2 * at(1) + at(0);
  else
    return at(3) - 3 * at(2) + 3 * at(1) - at(0);
}

/// Σ (d-th difference at k = i·stride)², i < len (len ≤ kBlock), exactly.
template <int Order>
u128 block_sumsq(const std::int64_t* c, std::int64_t len, std::int64_t m, std::int64_t stride) {
  ExactSums s;
  const auto d = [c, m, stride](std::size_t i) {
    return difference<Order>(c, static_cast<std::int64_t>(i) * stride, m);
  };
  add_exact_sums<SumKinds::Squares>(static_cast<std::size_t>(len), 0, d, s);
  return s.squares;
}

template <int Order>
u128 difference_sumsq(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  u128 total = 0;
  for (std::int64_t i0 = 0; i0 < n; i0 += kBlock)
    total += block_sumsq<Order>(c + i0 * stride, std::min(kBlock, n - i0), m, stride);
  return total;
}

/// Adds the squared second differences of x at lag m, terms 0 … len − 1 (len a multiple of
/// kLanes), term i to lane i mod kLanes: the one inner loop of the floating overlapping sums.
void add_second_diff_lanes(const double* x, std::int64_t len, std::int64_t m, double* lanes) {
  double acc[kLanes];
  std::copy(lanes, lanes + kLanes, acc);  // in registers: the lanes cannot alias x
  const double* __restrict a = x;
  const double* __restrict b = x + m;
  const double* __restrict e = x + 2 * m;
  for (std::int64_t i = 0; i < len; i += kLanes) {
    for (int j = 0; j < kLanes; ++j) {
      const double d = e[i + j] - 2.0 * b[i + j] + a[i + j];
      acc[j] += d * d;
    }
  }
  std::copy(acc, acc + kLanes, lanes);
}

}  // namespace

u128 second_diff_sumsq(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  return difference_sumsq<2>(c, n, m, stride);
}

u128 third_diff_sumsq(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  return difference_sumsq<3>(c, n, m, stride);
}

std::vector<u128> second_diff_sumsq_sweep(const std::int64_t* c, std::size_t points, std::span<const std::int64_t> ms) {
  const auto np = static_cast<std::int64_t>(points);
  const std::size_t count = ms.size();
  if (count == 0) return {};
  std::int64_t longest = 0;
  for (std::int64_t m : ms) longest = std::max(longest, np - 2 * m);
  const auto parts = static_cast<std::size_t>((longest + kStretch - 1) / kStretch);
  std::vector<u128> part_sums(parts * count, 0);
  static_assert(kBlock <= static_cast<std::int64_t>(NarrowCounts::kMaxTerms));
  // Narrow sums pay for their pass over the record when several m share it.
  const std::optional<NarrowCounts> narrow =
      count > 1 ? std::optional<NarrowCounts>(std::in_place, c, points) : std::nullopt;
  parallel_for(parts, [&](std::size_t part) {
    const std::int64_t from = static_cast<std::int64_t>(part) * kStretch;
    const std::int64_t to = std::min(longest, from + kStretch);
    u128* out = part_sums.data() + part * count;
    for (std::int64_t k0 = from; k0 < to; k0 += kBlock) {
      for (std::size_t i = 0; i < count; ++i) {
        const std::int64_t n = np - 2 * ms[i];
        if (k0 >= n) continue;
        const std::int64_t len = std::min(kBlock, n - k0);
        const auto small = narrow
                               ? narrow->second_diff_sumsq(static_cast<std::size_t>(k0), static_cast<std::size_t>(len),
                                                           static_cast<std::size_t>(ms[i]))
                               : std::nullopt;
        out[i] += small ? u128{*small} : block_sumsq<2>(c + k0, len, ms[i], 1);
      }
    }
  });
  std::vector<u128> sums(count, 0);
  for (std::size_t part = 0; part < parts; ++part)
    for (std::size_t i = 0; i < count; ++i) sums[i] += part_sums[part * count + i];
  return sums;
}

double second_diff_sumsq(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride) {
  double acc[kLanes] = {};
  if (stride == 1) {
    const std::int64_t whole = n - n % kLanes;
    add_second_diff_lanes(x, whole, m, acc);
    for (std::int64_t i = whole; i < n; ++i) {
      const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
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

std::vector<double> second_diff_sumsq_sweep(const double* x, std::size_t points, std::span<const std::int64_t> ms) {
  const auto np = static_cast<std::int64_t>(points);
  const std::size_t count = ms.size();
  std::vector<double> sums(count, 0.0);
  if (count == 0) return sums;
  // Each part sweeps the whole record for its share of the m (every parts-th): a part's sums are
  // those of the per-m kernel, whichever part takes them.
  const std::size_t parts = std::min<std::size_t>(count, worker_count());
  parallel_for(parts, [&](std::size_t part) {
    std::vector<std::size_t> mine;
    std::int64_t longest = 0;
    for (std::size_t i = part; i < count; i += parts) {
      mine.push_back(i);
      longest = std::max(longest, np - 2 * ms[i]);
    }
    std::vector<std::array<double, kLanes>> acc(mine.size(), std::array<double, kLanes>{});
    for (std::int64_t k0 = 0; k0 < longest; k0 += kFloatBlock)
      for (std::size_t j = 0; j < mine.size(); ++j) {
        const std::int64_t n = np - 2 * ms[mine[j]], whole = n - n % kLanes;
        const std::int64_t end = std::min(k0 + kFloatBlock, whole);
        if (k0 < end) add_second_diff_lanes(x + k0, end - k0, ms[mine[j]], acc[j].data());
      }
    for (std::size_t j = 0; j < mine.size(); ++j) {  // the terms beyond the last whole group of lanes
      const std::int64_t m = ms[mine[j]], n = np - 2 * m;
      double* a = acc[j].data();
      for (std::int64_t i = n - n % kLanes; i < n; ++i) {
        const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
        a[0] += d * d;
      }
      double s = 0;
      for (double v : acc[j]) s += v;
      sums[mine[j]] = s;
    }
  });
  return sums;
}

double third_diff_sumsq(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride) {
  double acc[kLanes] = {};
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t k = i * stride;
    const double d = x[k + 3 * m] - 3.0 * x[k + 2 * m] + 3.0 * x[k + m] - x[k];
    acc[i % kLanes] += d * d;
  }
  double s = 0;
  for (double v : acc) s += v;
  return s;
}

std::vector<std::uint64_t> count_prefix_sums(const std::int64_t* c, std::size_t points) {
  std::vector<std::uint64_t> p(points + 1);
  std::uint64_t run = 0;
  p[0] = 0;
  for (std::size_t k = 0; k < points; ++k) p[k + 1] = run += static_cast<std::uint64_t>(c[k]);
  return p;
}

double modified_sumsq(const std::uint64_t* prefix, std::int64_t n, std::int64_t m) {
  const std::uint64_t* __restrict p0 = prefix;
  const std::uint64_t* __restrict p1 = prefix + m;
  const std::uint64_t* __restrict p2 = prefix + 2 * m;
  const std::uint64_t* __restrict p3 = prefix + 3 * m;
  auto s_at = [&](std::int64_t i) {  // S_j, exact modulo 2^64, hence exact as int64
    const std::uint64_t s = p3[i] - 3 * p2[i] + 3 * p1[i] - p0[i];
    return static_cast<double>(static_cast<std::int64_t>(s));
  };
  double acc[kLanes] = {};
  std::int64_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int j = 0; j < kLanes; ++j) {
      const double v = s_at(i + j);
      acc[j] += v * v;
    }
  }
  for (; i < n; ++i) {
    const double v = s_at(i);
    acc[0] += v * v;
  }
  double s = 0;
  for (double v : acc) s += v;
  return s;
}

double modified_sumsq(const double* x, std::int64_t n, std::int64_t m) {
  // Running sums S_{j+1} = S_j + z_{j+m} − z_j in up to kLanes interleaved segments, each started
  // from a direct O(m) sum, so that rounding drift stays short. Fewer segments when m is large
  // compared with the number of terms.
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

}  // namespace rwcalc::detail
