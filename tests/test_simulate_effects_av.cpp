// The deterministic effects of the simulator leave their exact signature in the Allan variance:
// a bias step, a warm-up transient and a first-order low-pass of a sinusoid. A tiny pulse weight
// makes the counting error negligible, so the comparison is against closed forms, not tolerances
// of a Monte-Carlo.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rwcalc/allan.hpp"
#include "rwcalc/simulate.hpp"

namespace {

using rwcalc::NoiseModel;
using rwcalc::SimulationSettings;

SimulationSettings fine_settings(double duration_s, double rate_hz) {
  SimulationSettings s;
  s.duration_s = duration_s;
  s.rate_hz = rate_hz;
  s.scale_arcsec = 1e-7;  // quantization error ≪ every effect below
  s.seed = 11;
  return s;
}

double oavar(const rwcalc::PhaseSeries& x, std::int64_t m) {
  return rwcalc::allan_variance(x, m, rwcalc::Estimator::Overlapping);
}

TEST(SimulatedEffectsAv, BiasStepGivesTheSingleStepFormula) {
  // A rate step Δ anywhere at least 2τ from both ends: AV(τ) = Δ²τ/(3(T − 2τ)) (noise-models §6.2),
  // which looks like rate random walk with K = Δ/√T. On the sample grid the second differences
  // around the step form a discrete triangle whose squares sum to m(2m² + 1)/3 rather than 2m³/3,
  // hence the exact factor (1 + 1/(2m²)).
  NoiseModel m;
  m.readout = rwcalc::ReadoutMode::Counting;
  m.bias_steps.push_back({1234.5, 0.05});
  const auto s = fine_settings(3600.0, 10.0);
  const auto x = rwcalc::simulate(m, s);
  const double T = s.duration_s;
  for (std::int64_t mm : {10, 100, 1000, 5000}) {
    const double tau = static_cast<double>(mm) / s.rate_hz;
    const double md = static_cast<double>(mm);
    const double expected = 0.05 * 0.05 * tau / (3.0 * (T - 2.0 * tau)) * (1.0 + 1.0 / (2.0 * md * md));
    EXPECT_NEAR(oavar(x, mm) / expected, 1.0, 1e-4) << "tau " << tau << " s";
  }
}

TEST(SimulatedEffectsAv, WarmupTransientMatchesTheAvOfItsExactAngle) {
  // The warm-up rate A·e^{−t/Tw} integrates to θ(t) = A·Tw·(1 − e^{−t/Tw}); the simulator's AV
  // must equal the AV of that angle sampled at t_k, and at τ ≪ Tw it must look like a rate ramp
  // of slope A/Tw at the start (AV rises as τ², ADEV slope +1).
  NoiseModel m;
  m.warmups.push_back({0.2, 300.0});
  const auto s = fine_settings(3600.0, 10.0);
  const auto x = rwcalc::simulate(m, s);
  rwcalc::PhaseSeries exact;
  exact.kind = rwcalc::PhaseKind::Gyro;
  exact.tau0_s = s.tau0_s();
  const auto n = x.points();
  exact.values.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * exact.tau0_s;
    exact.values[k] = 0.2 * 300.0 * (1.0 - std::exp(-t / 300.0));  // ″ (rate in °/h = ″/s)
  }
  for (std::int64_t mm : {10, 100, 1000, 5000}) EXPECT_NEAR(oavar(x, mm) / oavar(exact, mm), 1.0, 1e-3) << mm;
  const double r1 = oavar(x, 20), r2 = oavar(x, 40);
  EXPECT_NEAR(r2 / r1, 4.0, 0.2) << "AV of a slow transient grows as τ² at short τ";
}

TEST(SimulatedEffectsAv, LowpassAttenuatesASinusoidsAvByTheFilterGain) {
  // A first-order low-pass of time constant τf passes a sinusoid of frequency f with gain
  // 1/√(1 + (2πfτf)²); the sinusoid's AV (Ω0·sin²(πfτ)/(πfτ))² scales by the gain squared.
  const double f = 0.05, amp = 1.0, tf = 5.0;
  NoiseModel plain;
  plain.sinusoids.push_back({f, amp, 0.3});
  NoiseModel filtered = plain;
  filtered.lowpass_tc_s = tf;
  const auto s = fine_settings(4000.0, 20.0);
  const auto xp = rwcalc::simulate(plain, s);
  const auto xf = rwcalc::simulate(filtered, s);
  const double w = 2.0 * std::numbers::pi * f * tf;
  const double gain2 = 1.0 / (1.0 + w * w);
  // Steady state after ~10 τf; the start-up transient of the filter is short against the record.
  for (std::int64_t mm : {10, 74, 150}) {
    const double tau = static_cast<double>(mm) / s.rate_hz;
    const double x = std::numbers::pi * f * tau;
    const double analytic = std::pow(amp * std::sin(x) * std::sin(x) / x, 2.0);
    EXPECT_NEAR(oavar(xp, mm) / analytic, 1.0, 0.02) << "unfiltered, tau " << tau;
    EXPECT_NEAR(oavar(xf, mm) / oavar(xp, mm), gain2, 0.03 * gain2) << "filtered, tau " << tau;
  }
}

}  // namespace
