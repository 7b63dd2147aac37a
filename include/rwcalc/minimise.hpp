#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/minimise.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file minimise.hpp
/// Bounded minimisation in one variable at a fixed cost (the functions searched are likelihood
/// scans, expensive, with one minimum in the bracket given).

namespace rwcalc {

/// `iters` golden-section steps (one evaluation each, two to start; the bracket shrinks by 0.618 a
/// step) towards a minimum of f in [lo, hi]: the better of the last two points.
template <class F>
double golden_min(const F& f, double lo, double hi, int iters) {
  const double g = 0.3819660112501051;  // (3 − √5)/2
  double x1 = lo + g * (hi - lo), x2 = hi - g * (hi - lo), f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < iters; ++i) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = lo + g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = hi - g * (hi - lo), f2 = f(x2);
    }
  }
  return f1 < f2 ? x1 : x2;
}

template <class F>
double golden_max(const F& f, double lo, double hi, int iters) {  ///< the same towards a maximum
  return golden_min([&f](double x) { return -f(x); }, lo, hi, iters);
}

}  // namespace rwcalc
