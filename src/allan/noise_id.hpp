#pragma once
// Noise identification reading the prepared int32 view of exact counts in place (internal).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {
class Crew;
}

namespace rwcalc::detail {

/// identify_noise() with, for exact counts, the offsets C_k − C_0 as int32 (PreparedCounts::rel32;
/// nullptr to read the counts themselves); small24: every |C_k − C_0| < 2^24 (PreparedCounts::small24).
/// On the view, the lag-1 autocorrelations come from exact integer sums (AVX2 when small24), so
/// they differ from the floating sums on the counts by those sums' rounding only. No allocation on
/// the ACF path.
/// start: nullptr, or the r1 of the first two difference levels of the ACF method at this m from
/// lag1_start_pass() (the same bits as computed here).
int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain,
                   const std::int32_t* rel32, bool small24, const double* start = nullptr);

/// The r1 pairs that identify_noise's ACF method takes first (levels 0 and 1 for phase, 1 and 2
/// for frequency domain) for every small m of ms (m ≤ 256) in one pass over the int32 view: each
/// block of the view is read once for all of them while it is in the core's cache, the record
/// split in halves on two threads (exact sums: the split changes no bit). Returns 2·n_ms values
/// (NaN where the pass did not compute: large m, B1 region), or nothing where the pass does not
/// apply (no AVX2, no view, not small24).
/// With a crew, the view is cut into stretches that the calling thread and the crew's lenders
/// take as they are free (`threads` is then not used); the same bits.
std::vector<double> lag1_start_pass(const PhaseSeries& x, const std::int64_t* ms, std::size_t n_ms,
                                    NoiseIdDomain domain, const std::int32_t* rel32, bool small24, unsigned threads,
                                    Crew* crew = nullptr);

/// The lag-1 autocorrelation r1 of the level-th difference (0 … 3) of p(k) = rel32[k·stride],
/// k < count, from exact integer sums, into r[0]; with pair (level < 3), also that of level + 1 into r[1]
/// (else r[1] = 0).
/// vector: the AVX2 kernel where the CPU has it (requires every |p| < 2^24), else one term at a
/// time. Both give the same bits.
void lag1_exact(const std::int32_t* rel32, std::size_t stride, std::size_t count, int level, bool vector, bool pair,
                double r[2]);

}  // namespace rwcalc::detail
