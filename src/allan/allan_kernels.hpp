#pragma once
// Inner loops of the Allan-variance estimators (internal to the library).
//
// Each kernel takes one cluster size m and returns the sum of the squared differences; the
// caller applies the normalisation. Integer kernels (cumulative pulse counts) work in modular
// uint64 → int64 arithmetic, so the result does not depend on the counter's offset.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "rwcalc/series.hpp"

namespace rwcalc {
class Crew;
}

namespace rwcalc::detail {

__extension__ typedef unsigned __int128 u128;  // exact sums of squared int64 differences
__extension__ typedef __int128 i128;

/// Σ_{k=0}^{n−1} (C[k+2m] − 2C[k+m] + C[k])², exactly, over terms spaced `stride` apart
/// (1: overlapping; m: non-overlapping). n = number of terms.
u128 second_diff_sumsq_counts(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride);

/// Same on floating phase.
double second_diff_sumsq_values(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride);

/// Modified AVAR numerator Σ_j S_j² with S_j = Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} + x_i),
/// j = 0 … n−1, n = N − 3m + 1. Integer version takes the modular prefix sums P[k] = Σ_{i<k} C[i]
/// (N + 1 entries), in which S_j = P[j+3m] − 3P[j+2m] + 3P[j+m] − P[j] exactly.
double modified_sumsq_counts(const std::uint64_t* prefix, std::int64_t n, std::int64_t m);
double modified_sumsq_values(const double* x, std::int64_t n, std::int64_t m);

/// Modular prefix sums of the counts: P[0] = 0, P[k+1] = P[k] + C[k].
std::vector<std::uint64_t> count_prefix_sums(const std::vector<std::int64_t>& c);

/// Cumulative counts prepared once for many cluster sizes. When every C_k − C_0 fits in ±2^30
/// (any real gyro record: 2^30 pulses of 0.92″ are 762 revolutions) the counts are kept as
/// int32 offsets from C_0, which halves the memory traffic and lets the loops convert to double
/// exactly with one instruction; the squares are still summed exactly (blocks checked against
/// 2^21, redone in 128 bits when larger). Otherwise the int64 path is used. Offsets from C_0 are
/// formed modulo 2^64, so any counter offset gives the same numbers.
/// Allocator that leaves new elements uninitialised (every element is written right after).
template <class T>
struct UninitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitAllocator<U>;
  };
  UninitAllocator() = default;
  template <class U>
  UninitAllocator(const UninitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
};

struct PreparedCounts {
  PreparedCounts() = default;
  PreparedCounts(PreparedCounts&&) noexcept = default;
  PreparedCounts& operator=(PreparedCounts&&) noexcept = default;
  PreparedCounts(const PreparedCounts&) = delete;  // `view` may point into rel32
  PreparedCounts& operator=(const PreparedCounts&) = delete;
  const std::vector<std::int64_t>* raw = nullptr;  ///< the 64-bit counts, when the series holds them so
  std::vector<std::int32_t, UninitAllocator<std::int32_t>> rel32;  ///< C_k − C_0 made from `raw`, when small enough
  /// The int32 view C_k − C_0 the kernels read: rel32's data, or a narrow series' own counts32
  /// (C_0 = 0 there); nullptr when the offsets do not fit.
  const std::int32_t* view = nullptr;
  std::size_t points = 0;  ///< C_0 … C_{points−1}
  bool small29 = false;                 ///< every |C_k − C_0| < 2^29: second differences fit int32
  bool small24 = false;                 ///< every |C_k − C_0| < 2^24: every |d| < 2^26, no per-block check
  std::vector<double> prefix_f64;       ///< Σ_{i<k} (C_i − C_0), exact integers (MVAR), when small enough
  std::vector<std::uint64_t> prefix_u64;  ///< modular prefix sums of C (MVAR) otherwise
};
/// With a crew, the offsets pass is shared out in chunks to the calling thread and the crew's
/// lenders (`threads` is then not used for it); the same result.
PreparedCounts prepare_counts(const std::vector<std::int64_t>& c, bool need_prefix, unsigned threads = 1,
                              Crew* crew = nullptr);
/// The same for a series' exact counts: those held in 32 bits (PhaseSeries::counts32) are viewed
/// where they are, with no copy; the range flags come from one pass over them.
PreparedCounts prepare_counts(const PhaseSeries& x, bool need_prefix, unsigned threads = 1, Crew* crew = nullptr);
/// Counts prepared for second-difference sums only (second_diff_sumsq and its sweep, nothing that
/// reads the offsets themselves): as prepare_counts(x, false) when the offsets fit the int32 view;
/// otherwise the view holds C_k − C_0 − k·s, the offsets from a line of a whole number s of
/// pulses per sample (the rounded mean), when those fit. A line of whole pulses has second
/// differences of exactly 0, so every sum is the counts' own; a record whose offsets are wide only
/// because of its mean rate (a fine pulse, a fast rate) gets the narrow kernels.
PreparedCounts prepare_second_differences(const PhaseSeries& x);
u128 second_diff_sumsq(const PreparedCounts& c, std::int64_t n, std::int64_t m, std::int64_t stride);
double modified_sumsq(const PreparedCounts& c, std::int64_t n, std::int64_t m);

/// Overlapping sums Σ_{k<N−2m} (C[k+2m] − 2C[k+m] + C[k])² for the cluster sizes ms[first],
/// ms[first + step], … (ascending), all in one sweep over the data: each block of 4096 terms is
/// taken for every m while it is in the core's cache, instead of streaming the whole int32 view once
/// per m. Exact, so out[i] equals second_diff_sumsq(c, N − 2m, m, 1) bit for bit. For an int32
/// view with every |C_k − C_0| < 2^24 on AVX2 machines, and for 64-bit counts that have no view
/// (offsets of 2^30 or more: the blocks of 1024 terms of second_diff_sumsq_counts); returns false
/// (and writes nothing) for any other view.
bool second_diff_sumsq_sweep(const PreparedCounts& c, std::size_t points, const std::int64_t* ms,
                             std::size_t count, std::size_t first, std::size_t step, u128* out);

/// The same sums for every τ of ms[0 … count) with the data cut into stretches that the calling
/// thread and the crew's lenders take as they are free (each stretch's sums kept apart, then
/// added: exact, so the same bits). False (nothing written) where the sweep does not apply.
bool second_diff_sumsq_sweep_shared(const PreparedCounts& c, std::size_t points, const std::int64_t* ms,
                                    std::size_t count, Crew& crew, u128* out);

}  // namespace rwcalc::detail
