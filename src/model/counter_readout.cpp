// The Allan variance of a plain counter's read-out error. The count is C_k = ⌊θ_k/q + φ⌋: its error
// e_k = frac(θ_k/q + φ) is a deterministic function of the angle. With the phase φ uniform the error
// is uncorrelated with the angle's increments, so its AV adds to theirs; its covariance at lag h,
// from the Fourier series of the sawtooth, is Σ_n cos(2πn·x)·E[cos(2πn·Z)]/(2π²n²), x = r·h the
// mean-rate advance and Z the angle's jitter about it (Gaussian: the factor is exp(−2π²n²s²)).
#include "rwcalc/counter_readout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rwcalc/methods.hpp"

namespace rwcalc {

namespace {

constexpr double kPi = std::numbers::pi;

/// f(y) = (y² − y + 1/6)/2 on [0, 1): the sawtooth's covariance at no jitter (½ Bernoulli B₂).
double bernoulli_half(double y) { return 0.5 * (y * y - y + 1.0 / 6.0); }

/// E[f(u)·1{0 ≤ u < 1}] for u ~ N(mu, s²): partial moments of the normal over [0, 1).
double partial_f(double mu, double s) {
  const double a = (0.0 - mu) / s, b = (1.0 - mu) / s;
  const double pa = std::exp(-0.5 * a * a) / std::sqrt(2.0 * kPi), pb = std::exp(-0.5 * b * b) / std::sqrt(2.0 * kPi);
  const double m0 = 0.5 * (std::erfc(-b / std::numbers::sqrt2) - std::erfc(-a / std::numbers::sqrt2));
  const double m1 = mu * m0 + s * (pa - pb);
  const double m2 = (mu * mu + s * s) * m0 + s * ((0.0 + mu) * pa - (1.0 + mu) * pb);
  return 0.5 * (m2 - m1 + m0 / 6.0);
}

}  // namespace

double sawtooth_covariance(double fraction, double s) {
  const double x = fraction - std::floor(fraction);
  if (!(s > 0)) return bernoulli_half(x);
  if (s > 0.15) {  // the Fourier series converges in a few terms
    double r = 0;
    for (int n = 1; n < 64; ++n) {
      const double damp = std::exp(-2.0 * kPi * kPi * n * n * s * s);
      if (damp < 1e-18) break;
      r += std::cos(2.0 * kPi * n * x) * damp / (2.0 * kPi * kPi * n * n);
    }
    return r;
  }
  // Narrow jitter: the smoothed piecewise quadratic, exactly, over the whole pulses it reaches.
  double r = 0;
  const auto k0 = static_cast<long>(std::floor(x - 9.0 * s)), k1 = static_cast<long>(std::floor(x + 9.0 * s));
  for (long k = k0; k <= k1; ++k) r += partial_f(x - static_cast<double>(k), s);
  return r;
}

namespace {

/// R(h) of the record: the mean-rate advance and the jitter over h samples about the record's
/// mean-rate line (sample variance of the increments, mean removed; Gaussian terms), in pulses.
double error_covariance(const CounterReadout& c, std::int64_t h, const AngleJitter& j) {
  if (c.points / static_cast<std::size_t>(h) < 3) return 0.0;  // no two increments: taken as white
  const IncrementBasis g = increment_basis(static_cast<std::size_t>(h), c.points, c.tau0_s, false);
  const double var = (g.q * j.q2 + g.n * j.n2 + g.b * j.b2) / (c.q_arcsec * c.q_arcsec);
  const double advance = c.pulses_per_sample * static_cast<double>(h);
  return sawtooth_covariance(advance - std::floor(advance), std::sqrt(std::max(var, 0.0)));
}

}  // namespace

double counter_increment_var(const CounterReadout& c, std::int64_t h, const AngleJitter& j) {
  if (h <= 0 || !(c.q_arcsec > 0)) return 0.0;
  return 2.0 * c.q_arcsec * c.q_arcsec * (1.0 / 12.0 - error_covariance(c, h, j));
}

double counter_avar(const CounterReadout& c, std::int64_t m, const AngleJitter& j) {
  if (m <= 0 || !(c.q_arcsec > 0)) return 0.0;
  const double tau = static_cast<double>(m) * c.tau0_s;
  const double e = 6.0 / 12.0 - 8.0 * error_covariance(c, m, j) + 2.0 * error_covariance(c, 2 * m, j);
  return c.q_arcsec * c.q_arcsec / (2.0 * tau * tau) * std::max(e, 0.0);
}

}  // namespace rwcalc
