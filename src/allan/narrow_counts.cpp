// Exact sums of small differences of counts in 16-bit lanes (narrow_counts.hpp).
#include "rwcalc/narrow_counts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rwcalc/parallel.hpp"

namespace rwcalc::detail {

namespace {

/// Groups per parallel_for item of the constructor (a fixed split: the result is the same anyway).
constexpr std::size_t kGroupsPerItem = 1024;

/// Whether every term bounded by |e| ≤ bound is exact from 16 bits and `len` squares of them sum
/// below 2^32.
bool narrow_enough(i128 bound, std::size_t len) {
  return bound < (i128{1} << 15) && bound * bound * static_cast<i128>(len) < (i128{1} << 32);
}

/// Σ (c − 2b + a)² over 16-bit residues, each term known to lie within ±2^15 and the sum below 2^32.
std::uint32_t narrow_second_diff_sumsq(const std::uint16_t* __restrict a, const std::uint16_t* __restrict b,
                                       const std::uint16_t* __restrict c, std::size_t len) {
  std::uint32_t s = 0;
  for (std::size_t i = 0; i < len; ++i) {
    const auto d = static_cast<std::int16_t>(static_cast<std::uint16_t>(c[i] - 2 * b[i] + a[i]));
    s += static_cast<std::uint32_t>(d * d);
  }
  return s;
}

/// Σe and Σe² of e = b − a + off over 16-bit residues, under the same conditions.
void narrow_increment_sums(const std::uint16_t* __restrict a, const std::uint16_t* __restrict b, std::uint16_t off,
                           std::size_t len, std::int32_t& s1, std::uint32_t& s2) {
  std::int32_t t1 = 0;
  std::uint32_t t2 = 0;
  for (std::size_t i = 0; i < len; ++i) {
    const auto e = static_cast<std::int16_t>(static_cast<std::uint16_t>(b[i] - a[i] + off));
    t1 += e;
    t2 += static_cast<std::uint32_t>(e * e);
  }
  s1 = t1;
  s2 = t2;
}

}  // namespace

NarrowCounts::NarrowCounts(const std::int64_t* c, std::size_t points)
    : low_(std::make_unique_for_overwrite<std::uint16_t[]>(points)),
      min_((points + kGroup - 1) / kGroup),
      max_(min_.size()) {
  if (points == 0) return;
  const auto c0 = static_cast<std::uint64_t>(c[0]);
  if (points > 1) {  // the mean step, whole: a trend of many counts per point would widen every bound
    const auto span = static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(c[points - 1]) - c0));
    const double slope = std::round(span / static_cast<double>(points - 1));
    slope_ = std::abs(slope) < 0x1p62 ? static_cast<std::int64_t>(slope) : 0;
  }
  const auto a = static_cast<std::uint64_t>(slope_);
  const std::size_t groups = min_.size(), items = (groups + kGroupsPerItem - 1) / kGroupsPerItem;
  std::uint16_t* low = low_.get();
  parallel_for(items, [&](std::size_t item) {
    for (std::size_t g = item * kGroupsPerItem; g < std::min(groups, (item + 1) * kGroupsPerItem); ++g) {
      const std::size_t begin = g * kGroup, end = std::min(points, begin + kGroup);
      std::uint64_t trend = c0 + a * begin;  // C_0 + a·k, modulo 2^64
      std::int64_t lo = std::numeric_limits<std::int64_t>::max(), hi = std::numeric_limits<std::int64_t>::min();
      for (std::size_t k = begin; k < end; ++k, trend += a) {
        const auto v = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[k]) - trend);
        low[k] = static_cast<std::uint16_t>(v);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      min_[g] = lo;
      max_[g] = hi;
    }
  });
}

NarrowCounts::Range NarrowCounts::range(std::size_t from, std::size_t len) const {
  const std::size_t g0 = from / kGroup, g1 = (from + len - 1) / kGroup;
  std::int64_t lo = min_[g0], hi = max_[g0];
  for (std::size_t g = g0 + 1; g <= g1; ++g) lo = std::min(lo, min_[g]), hi = std::max(hi, max_[g]);
  return {lo, hi};
}

std::optional<std::uint64_t> NarrowCounts::second_diff_sumsq(std::size_t k0, std::size_t len, std::size_t m) const {
  if (len == 0) return 0;
  // The trend a·k and C_0 drop out of every second difference.
  const Range r0 = range(k0, len), r1 = range(k0 + m, len), r2 = range(k0 + 2 * m, len);
  const i128 lo = r2.lo - 2 * r1.hi + r0.lo, hi = r2.hi - 2 * r1.lo + r0.hi;
  if (len > kMaxTerms || !narrow_enough(std::max(-lo, hi), len)) return std::nullopt;
  const std::uint16_t* p = low_.get() + k0;
  return narrow_second_diff_sumsq(p, p + m, p + 2 * m, len);
}

bool NarrowCounts::increment_sums(std::size_t k0, std::size_t len, std::size_t t, std::int64_t shift, std::int64_t& s1,
                                  std::uint64_t& s2) const {
  if (len == 0) {
    s1 = 0, s2 = 0;
    return true;
  }
  // C[k+t] − C[k] − shift = x'[k+t] − x'[k] + (a·t − shift).
  const i128 off = static_cast<i128>(slope_) * static_cast<i128>(t) - shift;
  const Range r0 = range(k0, len), r1 = range(k0 + t, len);
  const i128 lo = r1.lo - r0.hi + off, hi = r1.hi - r0.lo + off;
  if (len > kMaxTerms || !narrow_enough(std::max(-lo, hi), len)) return false;
  std::int32_t n1 = 0;
  std::uint32_t n2 = 0;
  const std::uint16_t* p = low_.get() + k0;
  narrow_increment_sums(p, p + t, static_cast<std::uint16_t>(static_cast<std::uint64_t>(off)), len, n1, n2);
  s1 = n1, s2 = n2;
  return true;
}

}  // namespace rwcalc::detail
