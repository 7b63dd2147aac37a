// The structure function of the five-term angle (structure_function.hpp).
#include "rwcalc/structure_function.hpp"

#include <cmath>
#include <numbers>

namespace rwcalc {

namespace {

/// D(u) given ln u, nested in u so that the terms left out (c = 0) add exact zeros.
double structure_at(const std::array<double, 5>& c, double u, double log_u) {
  return 2.0 * c[0] + u * (c[1] - u * (c[2] / std::numbers::pi * log_u + c[3] * u / 6.0 + c[4] * u * u / 12.0));
}

}  // namespace

double structure_function(const std::array<double, 5>& c, double u) {
  return u > 0 ? structure_at(c, u, std::log(u)) : 0.0;
}

std::array<double, 5> term_structure_functions(double u) {
  std::array<double, 5> d{};
  if (!(u > 0)) return d;
  const double log_u = std::log(u);  // once for the five terms
  for (std::size_t i = 0; i < d.size(); ++i) {
    std::array<double, 5> unit{};
    unit[i] = 1.0;
    d[i] = structure_at(unit, u, log_u);
  }
  return d;
}

}  // namespace rwcalc
