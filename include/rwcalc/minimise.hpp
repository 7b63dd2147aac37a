#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/minimise.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file minimise.hpp
/// Minimisers of likelihood scans: bounded in one variable at a fixed cost (expensive functions
/// with one minimum in the bracket given), and Nelder–Mead's simplex in a few variables.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "rwcalc/termination.hpp"

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

/// Where a simplex search stopped and how.
struct SimplexMinimum {
  std::vector<double> x;    ///< the best vertex
  Termination termination;  ///< converged: the vertices' values agree within ftol; iterations: evaluations
};

/// Nelder–Mead minimisation of f over R^d from x0, the first simplex x0 + step·e_i, at most
/// `max_evals` evaluations of f, converged when the simplex's worst and best values differ by < ftol.
template <class F>
SimplexMinimum nelder_mead(const F& f, const std::vector<double>& x0, double step, int max_evals, double ftol) {
  const std::size_t d = x0.size();
  std::vector<std::vector<double>> s(d + 1, x0);
  std::vector<double> fv(d + 1);
  for (std::size_t i = 0; i < d; ++i) s[i + 1][i] += step;
  for (std::size_t i = 0; i <= d; ++i) fv[i] = f(s[i]);
  int evals = static_cast<int>(d + 1);
  bool converged = false;
  std::vector<std::size_t> idx(d + 1);
  while (evals < max_evals) {
    for (std::size_t i = 0; i <= d; ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return fv[a] < fv[b]; });
    const std::size_t best = idx[0], worst = idx[d], second = idx[d - 1];
    if (std::abs(fv[worst] - fv[best]) < ftol) {
      converged = true;
      break;
    }
    std::vector<double> c(d, 0.0);
    for (std::size_t i = 0; i <= d; ++i)
      if (i != worst)
        for (std::size_t j = 0; j < d; ++j) c[j] += s[i][j] / static_cast<double>(d);
    auto along = [&](double t) {
      std::vector<double> x(d);
      for (std::size_t j = 0; j < d; ++j) x[j] = c[j] + t * (s[worst][j] - c[j]);
      return x;
    };
    auto xr = along(-1.0);
    const double fr = f(xr);
    ++evals;
    if (fr < fv[best]) {
      auto xe = along(-2.0);
      const double fe = f(xe);
      ++evals;
      if (fe < fr)
        s[worst] = xe, fv[worst] = fe;
      else
        s[worst] = xr, fv[worst] = fr;
    } else if (fr < fv[second]) {
      s[worst] = xr, fv[worst] = fr;
    } else {
      auto xc = along(fr < fv[worst] ? -0.5 : 0.5);
      const double fc = f(xc);
      ++evals;
      if (fc < std::min(fr, fv[worst])) {
        s[worst] = xc, fv[worst] = fc;
      } else {  // shrink towards the best
        for (std::size_t i = 0; i <= d; ++i) {
          if (i == best) continue;
          for (std::size_t j = 0; j < d; ++j) s[i][j] = s[best][j] + 0.5 * (s[i][j] - s[best][j]);
          fv[i] = f(s[i]);
          ++evals;
        }
      }
    }
  }
  const auto it = std::min_element(fv.begin(), fv.end());
  SimplexMinimum m{s[static_cast<std::size_t>(it - fv.begin())], {}};
  m.termination.status = converged ? TerminationStatus::Converged : TerminationStatus::IterationLimit;
  m.termination.iterations = evals;
  return m;
}

}  // namespace rwcalc
