#pragma once
#ifndef RWCALC_USES_ALLAN
#error "rwcalc/narrow_counts.hpp belongs to the allan layer, which this layer may not use (docs/architecture.md)"
#endif
// Exact sums of small differences of counts in 16-bit lanes (internal to the library).
//
// A difference of counts Σ w_j·C[k + j·lag] is exact modulo 2^16 from the counts' low 16 bits, so it
// is the true difference wherever that is known to lie within ±2^15. The extremes of the counts
// (less a whole-number trend, which no second difference sees) over groups of kGroup points bound
// every difference over a block of terms; where the bound also keeps the block's sum of squares below
// 2^32, the block is summed from the low bits: eight terms to a 128-bit register on any x86-64, where
// the 64-bit products of the general kernels take one multiply each. A block beyond the bound is
// left to the caller's 64-bit sums. The result is the exact integer either way.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "rwcalc/exact_sums.hpp"

namespace rwcalc::detail {

class NarrowCounts {
 public:
  /// Terms per block at most (a block's bound is taken over kGroup-point groups around it).
  static constexpr std::size_t kMaxTerms = 1024;

  NarrowCounts(const std::int64_t* c, std::size_t points);

  /// Σ_{k0 ≤ k < k0+len} (C[k+2m] − 2C[k+m] + C[k])², when the bound allows (len ≤ kMaxTerms).
  [[nodiscard]] std::optional<std::uint64_t> second_diff_sumsq(std::size_t k0, std::size_t len, std::size_t m) const;

  /// Σe and Σe² of e_k = C[k+t] − C[k] − shift, k0 ≤ k < k0+len, when the bound allows (len ≤
  /// kMaxTerms); false otherwise.
  bool increment_sums(std::size_t k0, std::size_t len, std::size_t t, std::int64_t shift, std::int64_t& s1,
                      std::uint64_t& s2) const;

 private:
  static constexpr std::size_t kGroup = 256;
  struct Range {
    i128 lo, hi;
  };
  /// The extremes of x' over the groups that cover [from, from + len).
  [[nodiscard]] Range range(std::size_t from, std::size_t len) const;

  std::int64_t slope_ = 0;                // a: x'_k = C_k − C_0 − a·k (modulo 2^64)
  std::unique_ptr<std::uint16_t[]> low_;  // x'_k modulo 2^16 (written once: not zeroed first)
  std::vector<std::int64_t> min_, max_;   // of x' over each group of kGroup points
};

}  // namespace rwcalc::detail
