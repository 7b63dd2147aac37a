#pragma once
/// @file signal.hpp
/// What the detectors read: the angle decimated to about 10 Hz, its block rates and mid-τ AV, a
/// model's deterministic terms, least-squares and spectral helpers, ensemble quantiles.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <vector>

#include "rwcalc/series.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

inline constexpr double kPi = 3.14159265358979323846;

/// The angle decimated to about 10 Hz: θ_j = x(jD) − x(0), ″ (gyro phase units).
struct Decimated {
  double tau_d = 0.1;         ///< decimated period, s
  std::vector<double> theta;  ///< θ_0 = 0 … θ_L
  [[nodiscard]] double duration() const { return theta.size() > 1 ? tau_d * double(theta.size() - 1) : 0.0; }
};
std::size_t decimation(double rate_hz);  ///< D: a power of two, 10 Hz ≤ rate/D < 20 Hz; 1 below 20 Hz
Decimated decimate(const PhaseSeries& x);
/// Mean rates over blocks of `per_block` decimated periods (about `seconds`: per_block_for), °/h.
std::vector<double> block_rates(const Decimated& d, std::size_t per_block);
std::size_t per_block_for(const Decimated& d, double seconds);
/// The mid-τ grid: 10 cluster sizes per decade from 1 s to T/3, and the AV there, (°/h)².
std::vector<std::size_t> mid_tau_grid(const Decimated& d);
std::vector<double> decimated_avar(const Decimated& d, const std::vector<std::size_t>& grid);

/// Angle (″) at time t of a model's deterministic terms (sinusoids, steps, warm-ups), from t = 0;
/// subtract_deterministic removes them from a decimated angle whose θ_0 is at t0.
double deterministic_angle(const NoiseModel& m, double t);
void subtract_deterministic(Decimated& d, const NoiseModel& m, double t0 = 0);

/// (1 − α) quantile of a maximum-type statistic from ensemble values (Gumbel fit by moments),
/// never below the largest ensemble value.
double gumbel_threshold(const std::vector<double>& values, double alpha);
/// The same quantile with its Monte-Carlo standard error (method-of-moments Gumbel quantile,
/// Var = σ²/K·(1 + 1.1396k + 1.1k²), k its frequency factor); the ensemble maximum is a floor only
/// when K < 1/α (beyond, the maximum lies above the quantile and would only add scatter).
struct GumbelQuantile {
  double value = 0, sigma = 0;
};
GumbelQuantile gumbel_quantile(const std::vector<double>& values, double alpha);
double quantile(std::vector<double> v, double p);
double median_of(std::vector<double>& v);  ///< the upper median; reorders v
/// White-noise σ from first differences (block means of counts make most differences 0, so not
/// their median).
double diff_sigma(const std::vector<double>& y);

void remove_trend(std::vector<double>& y);  ///< less mean and least-squares line
/// RSS of y ~ level + trend + extra columns; coefficients and (XᵀX)⁻¹ on request.
double ls_rss(const std::vector<double>& y, const std::vector<std::vector<double>>& extra,
              Eigen::VectorXd* coef = nullptr, Eigen::MatrixXd* inv = nullptr);
/// Weighted least squares of y on columns: χ², coefficients and (XᵀWX)⁺.
struct WlsOut {
  double chi2 = 0;
  Eigen::VectorXd coef;
  Eigen::MatrixXd inv;
};
WlsOut wls(const std::vector<double>& y, const std::vector<double>& w, const std::vector<std::vector<double>>& cols);

/// The attenuation sinc(πf·tb) of a line of frequency f by means over blocks of tb.
inline double block_attenuation(double f, double tb) {
  const double x = kPi * f * tb;
  return x > 1e-9 ? std::sin(x) / x : 1.0;
}
/// The response H = (1 − φ)/(1 − φe^{−iωτ0}) at f of the output-chain low-pass y_k = φy_{k−1} +
/// (1 − φ)r_k, φ = e^{−τ0/tf}.
inline std::complex<double> lowpass_response(double f, double tau0, double tf) {
  const double phi = std::exp(-tau0 / tf);
  return (1.0 - phi) / (1.0 - phi * std::polar(1.0, -2.0 * kPi * f * tau0));
}

/// A periodogram's local level window at bin k: one value per true bin (`pad` padded bins) over
/// ±24 true bins, the main lobe (±3) left out; within P[1 … P.size() − 1], shifted inwards at the
/// upper end when `keep_size`.
void level_window(const std::vector<double>& P, std::size_t k, double pad, bool keep_size, std::vector<double>& v);

/// A periodogram's largest ratio to its local level over bins [k_lo, k_hi]: the level of each
/// group of 4 true bins is the median of `window(first bin)` over `divisor`. A group whose median
/// cannot be below the bound that beats the best ratio so far is skipped.
struct Peak {
  double ratio = 0, level = 0;
  std::size_t k = 0;
};
template <class Window>
Peak peak_over_level(const std::vector<double>& P, std::size_t k_lo, std::size_t k_hi, double pad, Window& window,
                     double divisor) {
  Peak best;
  best.k = k_lo;
  const std::size_t stride = std::max<std::size_t>(1, static_cast<std::size_t>(pad));
  const std::size_t group = 4 * stride;
  for (std::size_t k0 = k_lo; k0 <= k_hi; k0 += group) {
    const std::size_t k1 = std::min(k_hi, k0 + group - 1);
    std::vector<double>& v = window(k0);
    if (best.ratio > 0) {
      double g = 0;
      for (std::size_t k = k0; k <= k1; ++k) g = P[k] > g ? P[k] : g;
      const double bound = g * divisor / best.ratio * (1.0 + 1e-9);
      std::size_t below = 0;
      for (const double x : v) below += x < bound;
      if (below <= v.size() / 2) continue;  // the median is at least the bound
    }
    const double lev = median_of(v) / divisor;
    if (lev <= 0) continue;
    for (std::size_t k = k0; k <= k1; ++k) {
      const double r = P[k] / lev;
      if (r > best.ratio) best = {r, lev, k};
    }
  }
  return best;
}

/// `iters` golden-section steps towards a minimum of f in [lo, hi]; the final interval's midpoint.
template <class F>
double golden_min(const F& f, double lo, double hi, int iters) {
  for (int it = 0; it < iters; ++it) {
    const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    if (f(m1) < f(m2))
      hi = m2;
    else
      lo = m1;
  }
  return 0.5 * (lo + hi);
}

/// A line's frequency near f0: the best of f0 + i·step (|i| ≤ half_steps, 0 < f < f_max) by the
/// explained sum of squares of fit_at(f, a, b), then `iters` golden-section steps in ±step.
template <class Fit>
double refine_frequency(Fit& fit_at, double f0, double step, int half_steps, int iters, double f_max) {
  double fbest = f0, ebest = -1;
  for (int i = -half_steps; i <= half_steps; ++i) {
    const double f = f0 + static_cast<double>(i) * step;
    if (f <= 0 || f >= f_max) continue;
    double a, b;
    const double ex = fit_at(f, a, b);
    if (ex > ebest) {
      ebest = ex;
      fbest = f;
    }
  }
  const auto loss = [&](double f) {
    double a, b;
    return -fit_at(f, a, b);
  };
  return golden_min(loss, fbest - step, fbest + step, iters);
}

}  // namespace rwcalc::diag
