#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/normal_quantile.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file normal_quantile.hpp
/// The standard normal quantile that two-sided 95 % intervals use, and the log-normal interval
/// built from it.

#include <cmath>

namespace rwcalc {

/// Φ⁻¹(0.975): a 95 % interval is the estimate ± kZ95 standard errors.
inline constexpr double kZ95 = 1.959963984540054;

/// A 95 % interval of a positive quantity whose logarithm is taken as normal with standard deviation
/// σ/value (the delta method): value·exp(∓kZ95·σ/value); [0, 0] for a value that is not positive.
struct LogNormalInterval {
  double low = 0, high = 0;
};
inline LogNormalInterval lognormal_interval95(double value, double sigma) {
  if (!(value > 0)) return {};
  const double s = sigma / value;
  return {value * std::exp(-kZ95 * s), value * std::exp(kZ95 * s)};
}

}  // namespace rwcalc
