#pragma once
// The lag-1 autocorrelation behind the noise identification (internal; identify_noise in
// rwcalc/confidence.hpp is the public entry).
#include <cstddef>
#include <cstdint>

#include "rwcalc/series.hpp"

namespace rwcalc::detail {

/// r1 = Σ(z_k − z̄)(z_{k+1} − z̄) / Σ(z_k − z̄)² of z, the level-th difference (0 … 3) of the phase
/// decimated by m, p_k = x_{k·m} − x_0 (k < count): over every point up to 2^16, beyond that over 16
/// runs of 4096 consecutive points spread evenly over the record (pairs within a run; a noise type
/// needs no more). For counts from exact integer sums, rounded
/// once at the end, while those fit 128 bits (every |z| < 2^34, fewer than 2^28 points); beyond
/// that, and for floating phase, from floating sums. 0 when z has fewer than two points or is
/// constant.
double lag1_autocorrelation(const PhaseSeries& x, std::int64_t m, std::size_t count, int level);

}  // namespace rwcalc::detail
