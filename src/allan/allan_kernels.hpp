#pragma once
// Inner loops of the Allan-variance estimators (internal to the library).
//
// Each kernel takes one cluster size m and returns the sum of the squared differences; the caller
// applies the normalisation. The count kernels work in modular uint64 → int64 arithmetic, so the
// result does not depend on the counter's offset (or on its wrapping round).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "rwcalc/exact_sums.hpp"

namespace rwcalc::detail {

/// Σ_{i<n} (C[k+2m] − 2C[k+m] + C[k])², k = i·stride (1: overlapping; m: non-overlapping), exactly.
u128 second_diff_sumsq(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride);

/// The same on floating phase (rounded sums).
double second_diff_sumsq(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride);

/// Σ_{i<n} (C[k+3m] − 3C[k+2m] + 3C[k+m] − C[k])², k = i·stride (Hadamard), exactly; and on
/// floating phase.
u128 third_diff_sumsq(const std::int64_t* c, std::int64_t n, std::int64_t m, std::int64_t stride);
double third_diff_sumsq(const double* x, std::int64_t n, std::int64_t m, std::int64_t stride);

/// The overlapping sums second_diff_sumsq(c, points − 2m, m, 1) of every m of ms in one blocked
/// sweep: each block of terms is taken for every m while it is in the core's cache, and stretches
/// of the record run in parallel; a block whose terms are small is summed in 16-bit lanes
/// (narrow_counts.hpp). Exact, so bit for bit the per-m sums.
std::vector<u128> second_diff_sumsq_sweep(const std::int64_t* c, std::size_t points, std::span<const std::int64_t> ms);

/// The floating overlapping sums second_diff_sumsq(x, points − 2m, m, 1) of every m of ms in one
/// blocked sweep (each block of the record taken for every m while it is in cache, the m shared out
/// among the cores): the same terms in the same lanes and order, so bit for bit the per-m sums.
std::vector<double> second_diff_sumsq_sweep(const double* x, std::size_t points, std::span<const std::int64_t> ms);

/// Modular prefix sums of the counts: P[0] = 0, P[k+1] = P[k] + C[k] (points + 1 entries).
std::vector<std::uint64_t> count_prefix_sums(const std::int64_t* c, std::size_t points);

/// Modified AVAR numerator Σ_{j<n} S_j², S_j = Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} + x_i),
/// n = N − 3m + 1. From the counts' prefix sums, where S_j = P[j+3m] − 3P[j+2m] + 3P[j+m] − P[j]
/// is an exact integer; its squares are summed in double.
double modified_sumsq(const std::uint64_t* prefix, std::int64_t n, std::int64_t m);
/// The same on floating phase.
double modified_sumsq(const double* x, std::int64_t n, std::int64_t m);

}  // namespace rwcalc::detail
