#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/sample_variance.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file sample_variance.hpp
/// The unbiased sample variance that the noise identification's B1 ratio and the paper's
/// cross-checks read.

#include <span>

namespace rwcalc {

/// Σ(v − v̄)² / (n − 1) of `v`, n ≥ 2 (two passes: the mean first, so a large common level costs
/// no digits).
double sample_variance(std::span<const double> v);

}  // namespace rwcalc
