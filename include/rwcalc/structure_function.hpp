#pragma once
#ifndef RWCALC_USES_NUMERICS
#error \
    "rwcalc/structure_function.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file structure_function.hpp
/// D(u) = E[(θ(s + u) − θ(s))²] of the angle under the five IEEE 952 terms, u in s. A variance of a
/// linear statistic Σa_i θ(t_i) with Σa_i = 0 is −½ Σ a_i a_j D(t_i − t_j), so the parts of D that
/// do not grow with u or grow as u² (the flicker's low-frequency cut-off) cancel and are left out.
#include <array>

namespace rwcalc {

/// D(u) for c = {Q², N², B², K², R²} (s-based units): 2Q² + N²u − (B²/π)u² ln u − K²u³/6 − R²u⁴/12
/// for u > 0; 0 for u ≤ 0.
double structure_function(const std::array<double, 5>& c, double u);
/// D(u) of each term at unit coefficient.
std::array<double, 5> term_structure_functions(double u);

}  // namespace rwcalc
