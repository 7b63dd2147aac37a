// The Gamma deviance (deviance.hpp).
#include "rwcalc/deviance.hpp"

#include <algorithm>
#include <boost/math/special_functions/digamma.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <cmath>

namespace rwcalc {

double gamma_deviance(double observed, double model, double nu) {
  const double x = observed / model;
  return nu * (x - 1.0 - std::log(x));
}

double deviance_residual(double observed, double model, double nu) {
  if (!(observed > 0 && model > 0 && nu > 0)) return 0.0;
  // x − 1 − ln x rounds below 0 within ~1e-8 of x = 1.
  return std::copysign(std::sqrt(std::max(0.0, gamma_deviance(observed, model, nu))), observed / model - 1);
}

double gamma_deviance_mean(double nu) {
  if (nu > 1e3) return 1.0 + 1.0 / (3.0 * nu);  // the series: ψ and ln cancel to rounding
  return -nu * (boost::math::digamma(nu / 2.0) - std::log(nu / 2.0));
}

double chi_root_mean(double nu) {
  if (!(nu > 0)) return 1.0;
  if (nu > 1e8) return 1.0 - 1.0 / (4.0 * nu);
  // Γ(ν/2)/Γ(ν/2 + ½) as one ratio (Boost: accurate at large ν, and no global sign like lgamma's).
  return std::sqrt(2.0 / nu) / boost::math::tgamma_delta_ratio(nu / 2.0, 0.5);
}

double mean_unbiased_root(double v, double var_v) { return mean_unbiased_root(v, var_v, v); }

double mean_unbiased_root(double v, double var_v, double level) {
  if (!(v > 0)) return 0.0;
  const double nu = var_v > 0 && level > 0 ? 2.0 * level * level / var_v : 0.0;
  return nu >= kRootMinEdf ? std::sqrt(v) / chi_root_mean(nu) : std::sqrt(v);
}

}  // namespace rwcalc
