#pragma once
/// @file signal.hpp
/// What the detectors read: the angle decimated to about 10 Hz, its block-mean rates and mid-τ
/// Allan variance, the deterministic terms of a model, least-squares and spectral helpers, and
/// the ensemble quantiles that calibrate the thresholds (docs/diagnosis.md).
#include <Eigen/Dense>
#include <algorithm>
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

/// Decimation factor for a sample rate (rate/D ≈ 10 Hz; 1 below 20 Hz).
std::size_t decimation(double rate_hz);
Decimated decimate(const PhaseSeries& x);
/// Mean rates over blocks of `per_block` decimated periods, °/h.
std::vector<double> block_rates(const Decimated& d, std::size_t per_block);
/// Decimated periods in a block of about `seconds`.
std::size_t per_block_for(const Decimated& d, double seconds);
/// Dense τ grid of the mid-τ detectors (cluster sizes in decimated periods, 10 per decade).
std::vector<std::size_t> mid_tau_grid(const Decimated& d);
/// Overlapping AV of the decimated angle at those cluster sizes, (°/h)².
std::vector<double> decimated_avar(const Decimated& d, const std::vector<std::size_t>& grid);

/// Angle (″) at time t of the deterministic terms of a model (sinusoids, steps, warm-ups),
/// relative to t = 0.
double deterministic_angle(const NoiseModel& m, double t);
/// Subtract the deterministic terms of `m` from the decimated angle (t0: time of θ_0).
void subtract_deterministic(Decimated& d, const NoiseModel& m, double t0 = 0);

/// (1 − α) quantile of a maximum-type statistic from ensemble values (Gumbel fit by moments),
/// never below the largest ensemble value.
double gumbel_threshold(const std::vector<double>& values, double alpha);
double quantile(std::vector<double> v, double p);
/// The median of v's values (the upper one of an even count); reorders v.
double median_of(std::vector<double>& v);
/// White-noise σ of a series from its first differences (rms / √2): block means of pulse
/// counts are quantized, and most differences can be 0, so not the median absolute difference.
double diff_sigma(const std::vector<double>& y);

/// y less its mean and its least-squares linear trend over the sample index.
void remove_trend(std::vector<double>& y);
/// The FFT of y under a Hann window (at the sample centres), zero-padded to the first power of two
/// of at least 2n (`nfft`; only the first half with `half_spectrum`), and the window's Σw².
std::vector<std::complex<double>> hann_spectrum(const std::vector<double>& y, bool half_spectrum, std::size_t& nfft,
                                                double& w2);
/// Least-squares a·cos(2πft) + b·sin(2πft) through y_i at t_i = (i + ½)·tb: (a, b), and the
/// explained sum of squares as the result.
double sinusoid_ls(const std::vector<double>& y, double tb, double f, double& a, double& b);
/// RSS of y ~ level + trend + Σ extra columns by least squares; the coefficients and (XᵀX)⁻¹ on
/// request.
double ls_rss(const std::vector<double>& y, const std::vector<std::vector<double>>& extra,
              Eigen::VectorXd* coef = nullptr, Eigen::MatrixXd* inv = nullptr);

/// Weighted least squares of y on columns: χ², coefficients and (XᵀWX)⁺.
struct WlsOut {
  double chi2 = 0;
  Eigen::VectorXd coef;
  Eigen::MatrixXd inv;
};
WlsOut wls(const std::vector<double>& y, const std::vector<double>& w, const std::vector<std::vector<double>>& cols);

/// A periodogram's largest ratio to its local level over bins [k_lo, k_hi], the level taken
/// afresh every 4 true bins (`pad` padded bins each) for the group of bins up to the next: the
/// median of the values `window(k)` fills in for the group's first bin k, over `divisor`.
/// A group whose median cannot be below the bound that beats the best ratio so far (a count of
/// the window's values under it) is skipped: its ratios cannot win, so the result is the same.
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

/// The frequency of a line near f0: the best of f0 + i·step (|i| ≤ half_steps, 0 < f < f_max) by
/// the explained sum of squares of fit_at(f, a, b), then `iters` golden-section steps in ±step.
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
  double lo = fbest - step, hi = fbest + step;
  for (int it = 0; it < iters; ++it) {
    const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    double a, b;
    if (fit_at(m1, a, b) > fit_at(m2, a, b))
      hi = m2;
    else
      lo = m1;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rwcalc::diag
