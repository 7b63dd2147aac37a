#pragma once
// A GL-2D-like pulse record from a generator written independently of rwcalc's simulator and fit: the
// rate's flicker (B) and random walk (K) are Gaussian Fourier coefficients shaped by their spectra and
// transformed back (frequency-domain synthesis), the white rate (N) is drawn per sample, and the pulses
// are counted by its own counter, ⌊θ/q + φ⌋, with one random phase (a plain counter) or a fresh one per
// sample (dither of up to a pulse: the GL-2D's randomised read-out). The records test the fit, the term
// choice, the direct N and the class probabilities against data that share no code with them.
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <cstdint>
#include <random>
#include <vector>

#include "rwcalc/noise_model.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/verdict.hpp"
#include "test_fit_sim.hpp"

namespace rwcalc::test {

struct IndependentTruth {
  double n = 0;  ///< white rate (ARW), °/√h
  double b = 0;  ///< flicker rate, °/h
  double k = 0;  ///< rate random walk, °/h/√h
};

struct IndependentSettings {
  double seconds = 1800.0;
  double rate_hz = 400.0;
  bool dither = false;     ///< a fresh read-out phase per sample (else one phase: a plain counter)
  double q_arcsec = 0.92;  ///< pulse weight (the GL-2D's)
  std::size_t flicker_step =
      1;  ///< samples per flicker value (the flicker's AV below it is far under the white terms')
};

/// `count` rate values (″/s) at step `step_s` with two-sided PSD psd(f) ((″/s)²/Hz): Gaussian Fourier
/// coefficients of variance L·psd(f)/step on a circle of L ≥ `circle`·count points, the first `count`
/// kept. The circle's lowest frequency 1/(L·step) leaves out the spectrum below it: for flicker with
/// L ≥ 4 count, the AV at τ = T/4 is within 1.3 % of its floor; for a random walk (1/f²) the AV is
/// short by about 3τ/(2L·step), 0.6 % at τ = T/4 with L ≥ 64 count.
template <class Psd>
std::vector<double> shaped_noise(std::size_t count, double step_s, std::size_t circle, Psd psd, Normal& g) {
  std::size_t len = 1;
  while (len < circle * count) len <<= 1;
  std::vector<std::complex<double>> spec(len, 0.0);
  const double ld = static_cast<double>(len);
  for (std::size_t j = 1; j <= len / 2; ++j) {
    const double s = psd(static_cast<double>(j) / (ld * step_s));
    if (j == len / 2) {
      spec[j] = std::sqrt(ld * s / step_s) * g();
    } else {
      const double sd = std::sqrt(ld * s / step_s / 2.0);
      spec[j] = {sd * g(), sd * g()};
      spec[len - j] = std::conj(spec[j]);
    }
  }
  Eigen::FFT<double> fft;
  std::vector<double> x;
  fft.inv(x, spec);
  x.resize(count);
  return x;
}

/// The record: Earth rate at 55.75°, white rate, flicker (IEEE 952 two-sided PSD B²/(2πf), AV
/// (2 ln2/π)B²) at `flicker_step` samples, random walk (PSD K″²/(2πf)², K″ = K/60 (″/s)/√s, AV K″²τ/3)
/// at one value per second (its AV below a second is far under the other terms').
inline Recording independent_record(const IndependentTruth& t, const IndependentSettings& s, std::uint64_t seed) {
  Normal g(seed);
  std::mt19937_64 u(seed ^ 0x9e3779b97f4a7c15ULL);
  auto uniform = [&] { return (static_cast<double>(u() >> 11) + 0.5) * 0x1.0p-53; };
  const double tau0 = 1.0 / s.rate_hz;
  const auto count = static_cast<std::size_t>(std::llround(s.seconds * s.rate_hz));
  const std::size_t fstep = std::max<std::size_t>(1, s.flicker_step);
  const std::vector<double> flicker = shaped_noise((count + fstep - 1) / fstep, tau0 * static_cast<double>(fstep), 4,
                                                   [&](double f) { return t.b * t.b / (2.0 * M_PI * f); }, g);
  const auto kstep = static_cast<std::size_t>(std::max(1.0, std::round(s.rate_hz)));
  std::vector<double> walk;
  if (t.k > 0) {
    const double kk = t.k / 60.0;
    walk = shaped_noise((count + kstep - 1) / kstep, tau0 * static_cast<double>(kstep), 64,
                        [&](double f) { return kk * kk / (4.0 * M_PI * M_PI * f * f); }, g);
  }
  const double arw = 60.0 * t.n * std::sqrt(tau0);  // ″ per sample
  const double earth = earth_rate_at(55.75);
  const double phase = uniform();
  Recording rec;
  rec.source = "independent";
  rec.rate_hz = s.rate_hz;
  rec.phase.tau0_s = tau0;
  rec.phase.arcsec_per_count = s.q_arcsec;
  rec.phase.counts.resize(count + 1);
  auto counted = [&](double angle) {
    return static_cast<std::int64_t>(std::floor(angle / s.q_arcsec + (s.dither ? uniform() : phase)));
  };
  const std::int64_t c0 = counted(0.0);
  rec.phase.counts[0] = 0;
  double theta = 0;  // ″
  for (std::size_t k = 0; k < count; ++k) {
    const double rate = earth + flicker[k / fstep] + (walk.empty() ? 0.0 : walk[k / kstep]);
    theta += rate * tau0 + arw * g();
    rec.phase.counts[k + 1] = counted(theta) - c0;
  }
  rec.samples = count;
  return rec;
}

}  // namespace rwcalc::test
