#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/normal_quantile.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file normal_quantile.hpp
/// The standard normal quantile that two-sided 95 % intervals use.

namespace rwcalc {

/// Φ⁻¹(0.975): a 95 % interval is the estimate ± kZ95 standard errors.
inline constexpr double kZ95 = 1.959963984540054;

}  // namespace rwcalc
