#pragma once
// Overlapping AVAR sums for every cluster size at once (internal; used by compute_allan for the
// `all` grid on long records).
//
// With T = P − 2m terms, S(m) = Σ_{k<T} (x_{k+2m} − 2x_{k+m} + x_k)² expands into prefix sums of x²
// and three cross sums: the lag-2m autocorrelation A(2m) and twice the lag-m autocorrelation A(m)
// less m head and m tail products. A(L) for every L is one FFT; the head products H(m) =
// Σ_{j<m} x_j x_{j+m} for every m come from dyadic squares of the (j, m) triangle, each one FFT
// correlation (O(N log² N) in all); the tail products are the head products of the reversed series.
// This is floating-point, not exact: the caller uses it above a cluster size where S(m) is large
// compared with the rounding (docs/performance.md states the measured departure).
#include <cstdint>
#include <vector>

namespace rwcalc::detail {

/// S(m) for m = 0 … max_m (S(0) = 0 and S(m) = 0 where m leaves no term) from the phase x_0 … x_{P−1}
/// in any units.
std::vector<double> all_oavar_sumsq_fft(std::vector<double> x, std::int64_t max_m);

}  // namespace rwcalc::detail
