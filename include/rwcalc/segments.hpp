#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/segments.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
// A record split at the gaps of its time column (`--gaps segments`): each segment's phase, and the
// Allan variance pooled over the segments so that no difference spans a gap.
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

/// Phase points first … last (inclusive) of `x`, its sample period, kind, pulse weight and rate
/// offset kept; only those points are copied.
PhaseSeries phase_slice(const PhaseSeries& x, std::size_t first, std::size_t last);

/// Each segment's phase series (one series, the record's, when it has no gap). A segment of n samples
/// holds n + 1 phase points when the phase starts from 0 before the first sample (rate, increment and
/// pulse input), n otherwise.
std::vector<PhaseSeries> segment_phases(const Recording& rec);

/// The longest segment's phase (the record's own when it has no gap).
PhaseSeries longest_segment(const Recording& rec);

/// The chosen variance of every segment, pooled at each τ: the sums of squares over the terms of
/// all segments divided by the number of terms (the terms of a segment too short for that τ are
/// none), EDF the sum of the segments' (independent stretches), bounds from it; α of the longest
/// segment that has the τ. The record's own result when it has no gap.
AllanResult allan_of_record(const Recording& rec, const AllanOptions& options);

}  // namespace rwcalc
