#pragma once
// Order statistics of non-negative values held in several arrays (internal).
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace rwcalc::detail {

/// The value of rank k (0-based: the element std::nth_element would put at k) among the values
/// of `sets` taken together, which must number more than k (and fewer than 2^32) and be
/// non-negative (not NaN). The values are not gathered: the bit patterns of non-negative doubles
/// order them as unsigned integers, so a radix select finds rank k 12 bits at a time — a
/// histogram of the values whose higher bits match those fixed so far picks the next 12 — until
/// the values left are equal (a quantised record's residuals, mostly zero, end there at once) or
/// few, which are then gathered and ordered. The same value as nth_element over the
/// concatenation, in a few passes over the values that nothing in a pass waits on (four
/// histograms in turn, so that runs of equal values do not queue on one counter): for the outlier
/// scale's 2e5 values 0.7–0.85 ms, where their concatenation (1.5 MB of fresh pages) and
/// nth_element took 0.9–1.7 ms and more.
inline double select_nonnegative(const std::vector<std::span<const double>>& sets, std::size_t k) {
  constexpr int kBits = 12;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  constexpr std::size_t kGather = 2048;  // values few enough to gather and order
  using Bits = std::uint64_t;
  auto bits = [](double v) { return std::bit_cast<Bits>(v); };
  std::vector<std::uint32_t> hist(4 * kBuckets);
  // The values still in the running: those whose bits under `pmask` are `want` (all at first).
  Bits pmask = 0, want = 0;
  int fixed = 0;  // the high bits of rank k's value found so far
  for (std::size_t count = SIZE_MAX; count > kGather && fixed < 64;) {
    const int width = std::min(kBits, 64 - fixed);
    const int shift = 64 - fixed - width;
    const Bits mask = (Bits{1} << width) - 1;
    std::fill(hist.begin(), hist.end(), 0);
    Bits lo = ~Bits{0}, hi = 0;
    std::size_t j = 0;
    for (const auto& set : sets)
      for (const double v : set) {  // branch-free: a value out of the running adds 0
        const Bits u = bits(v);
        const bool in = (u & pmask) == want;
        const Bits m = Bits{0} - Bits{in};  // all ones for a value in the running
        hist[(j++ & 3) * kBuckets + ((u >> shift) & mask)] += in;
        lo = std::min(lo, u | ~m);
        hi = std::max(hi, u & m);
      }
    if (lo == hi) return std::bit_cast<double>(lo);  // every value left is rank k's
    std::size_t below = 0, b = 0;
    for (;; ++b) {
      const std::size_t c = std::size_t{hist[b]} + hist[kBuckets + b] + hist[2 * kBuckets + b] + hist[3 * kBuckets + b];
      if (below + c > k) {
        count = c;
        break;
      }
      below += c;
    }
    k -= below;
    pmask |= mask << shift;
    want |= Bits{b} << shift;
    fixed += width;
  }
  std::vector<double> in;
  for (const auto& set : sets)
    for (const double v : set)
      if ((bits(v) & pmask) == want) in.push_back(v);
  const auto mid = in.begin() + static_cast<std::ptrdiff_t>(k);
  std::nth_element(in.begin(), mid, in.end());
  return *mid;
}

}  // namespace rwcalc::detail
