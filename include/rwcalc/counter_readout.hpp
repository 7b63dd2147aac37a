#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/counter_readout.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file counter_readout.hpp
/// The Allan variance of a plain pulse counter's read-out error (docs/analysis.md, "The counter
/// read-out"): the angle's fractional pulse, a sawtooth driven by the mean rate, smoothed by the
/// angle's own jitter. Rates in °/h (= ″/s), angles in ″, times in s.
#include <cstddef>
#include <cstdint>

namespace rwcalc {

/// What the counter's error depends on, all read from the record itself.
struct CounterReadout {
  double pulses_per_sample = 0;  ///< mean rate of the record, pulses per sample (any sign)
  double q_arcsec = 0;           ///< pulse weight q, ″
  double tau0_s = 0;             ///< sample period, s
  std::size_t points = 0;        ///< phase points of the record (for the jitter about the mean rate)
};

/// Fit-scale coefficients (fit.hpp) of the terms that jitter the angle about its mean-rate line:
/// white angle Q² (″²), white rate N″² (″²/s), flicker B² ((″/s)²).
struct AngleJitter {
  double q2 = 0, n2 = 0, b2 = 0;
};

/// Covariance of the counter's error (in pulses) at samples h apart: R(h) = E[f(frac(r·h + Z))]
/// with f(y) = (y² − y + 1/6)/2 and Z ~ N(0, s²) the angle's jitter over h samples in pulses
/// (s = 0: the exact sawtooth; large s: white, R → 0). R(0) = 1/12.
[[nodiscard]] double sawtooth_covariance(double fraction, double jitter_pulses);

/// Allan variance (°/h)² of the counter read-out error at cluster size m:
/// q²/(2τ²)·[6R(0) − 8R(m) + 2R(2m)], τ = m·τ0. Averages q²/(4τ²) (Q = q/√12) over the mean rate;
/// 0 where the mean rate advances a whole number of pulses per m samples and the angle is still.
[[nodiscard]] double counter_avar(const CounterReadout& counter, std::int64_t m, const AngleJitter& jitter);

/// Mean square of the read-out error's increments over h samples, 2q²·[R(0) − R(h)], ″²: its part
/// of the variance of the angle increments (the direct N method).
[[nodiscard]] double counter_increment_var(const CounterReadout& counter, std::int64_t h, const AngleJitter& jitter);

}  // namespace rwcalc
