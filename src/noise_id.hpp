#pragma once
// Noise identification reading the prepared int32 view of exact counts in place (internal).
#include <cstdint>

#include "rwcalc/allan.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc::detail {

/// identify_noise() with, for exact counts, the offsets C_k − C_0 as int32 (PreparedCounts::rel32;
/// nullptr to read the counts themselves). Same result bit for bit; no allocation on the ACF path.
int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain,
                   const std::int32_t* rel32);

}  // namespace rwcalc::detail
