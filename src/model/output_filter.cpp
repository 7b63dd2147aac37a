// Allan variances of white angle and white rate noise seen through a first-order output filter
// (the sensor's own low-pass): the analysis finds the filter's roll-off with them, the diagnosis
// names it.
#include "rwcalc/output_filter.hpp"

#include <cmath>

namespace rwcalc {

double output_lowpass_angle_avar(std::size_t m, double tau0, double tf) {
  const double tau = static_cast<double>(m) * tau0;
  if (!(tf > 0)) return 3.0 / (tau * tau);
  const double x = tau0 / tf;
  const double one_m_phi = -std::expm1(-x);
  const double phi_m = std::exp(-static_cast<double>(m) * x);
  const double v = one_m_phi / (2.0 - one_m_phi);  // (1 − φ)/(1 + φ)
  return v * (3.0 - 4.0 * phi_m + phi_m * phi_m) / (tau * tau);
}

double output_lowpass_rate_avar(std::size_t m, double tau0, double tf) {
  const double md = static_cast<double>(m);
  if (!(tf > 0)) return 1.0 / (md * tau0);
  // AR(1)-filtered rate samples of variance 1/τ0: AV = (Var of an m-sum − Cov of adjacent ones)/m².
  const double x = tau0 / tf;
  const double a = -std::expm1(-x);  // 1 − φ
  const double phi = 1.0 - a;
  const double b = -std::expm1(-md * x);  // 1 − φ^m
  const double V = (1.0 / tau0) * a / (2.0 - a);
  const double var_sum = V * (md + 2.0 * phi * (md * a - b) / (a * a));
  const double cov = V * phi * b * b / (a * a);
  return (var_sum - cov) / (md * md);
}

}  // namespace rwcalc
