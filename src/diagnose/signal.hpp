#pragma once
/// @file signal.hpp
/// What the diagnosis reads: the angle decimated to about 10 Hz and its block rates, a model's
/// deterministic terms, the refinement of a line's frequency.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "rwcalc/minimise.hpp"
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
/// The Hann-windowed periodogram of y averaged over its ⌊n/len⌋ segments of `len` samples, each
/// zero-padded to `nfft` (a power of two, at least len and 4): P[k], k = 0 … nfft/2, scaled so that
/// E P = σ² for white noise of variance σ². Removing y's mean is the caller's.
std::vector<double> hann_periodogram(const std::vector<double>& y, std::size_t len, std::size_t nfft);
/// Mean rates over blocks of `per_block` decimated periods (about `seconds`: per_block_for), °/h.
std::vector<double> block_rates(const Decimated& d, std::size_t per_block);
std::size_t per_block_for(const Decimated& d, double seconds);

/// Angle (″) at time t of a model's deterministic terms (sinusoids, steps, warm-ups), from t = 0.
double deterministic_angle(const NoiseModel& m, double t);

/// The attenuation sinc(πf·tb) of a line of frequency f by means over blocks of tb.
inline double block_attenuation(double f, double tb) {
  const double x = kPi * f * tb;
  return x > 1e-9 ? std::sin(x) / x : 1.0;
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
