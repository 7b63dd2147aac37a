#pragma once
// A small, exact-in-distribution gyro generator for the fit/analysis tests: white angle noise Q
// (″ rms per sample), angle random walk N (°/√h), Kasdin–Walter flicker rate B (°/h, Q_d = B²,
// FFT convolution over the whole record so the 1/f band reaches the record length), and a
// constant rate. Phase in ″ (1 ″/s = 1 °/h). Independent of the project's simulator on purpose:
// the fit is tested against a generator that shares no code with it.
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <cstdint>
#include <random>
#include <vector>

#include "rwcalc/series.hpp"

namespace rwcalc::test {

struct SimTruth {
  double Q = 0.0;       // ″
  double N = 0.0;       // °/√h
  double B = 0.0;       // °/h
  double rate = 12.43;  // °/h
};

/// Box–Muller normal on mt19937_64 (reproducible across standard libraries).
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double operator()() {
    if (has_) {
      has_ = false;
      return spare_;
    }
    double u1 = 0;
    do u1 = (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53;
    while (u1 <= 0);
    const double u2 = (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 rng_;
  double spare_ = 0;
  bool has_ = false;
};

/// Flicker rate samples (°/h) of length n with one-sided PSD ≈ B²/(π f): Kasdin–Walter filter
/// h_k = h_{k−1}(k − ½)/k applied to white noise of variance B² by FFT convolution.
inline std::vector<double> flicker_rate(std::size_t n, double b, Normal& g) {
  std::size_t len = 1;
  while (len < 2 * n) len <<= 1;
  std::vector<double> h(len, 0.0), w(len, 0.0);
  h[0] = 1.0;
  for (std::size_t k = 1; k < n; ++k) h[k] = h[k - 1] * (static_cast<double>(k) - 0.5) / static_cast<double>(k);
  for (std::size_t k = 0; k < n; ++k) w[k] = b * g();
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> hf, wf;
  fft.fwd(hf, h);
  fft.fwd(wf, w);
  for (std::size_t k = 0; k < hf.size(); ++k) hf[k] *= wf[k];
  std::vector<double> y;
  fft.inv(y, hf);
  y.resize(n);
  return y;
}

/// A phase series (″) of `seconds` at `rate_hz`.
inline PhaseSeries simulate_gyro(const SimTruth& t, double seconds, double rate_hz, std::uint64_t seed) {
  Normal g(seed);
  PhaseSeries x;
  x.tau0_s = 1.0 / rate_hz;
  const auto n = static_cast<std::size_t>(std::llround(seconds * rate_hz));
  std::vector<double> fl;
  if (t.B > 0) fl = flicker_rate(n, t.B, g);
  x.values.resize(n + 1);
  const double arw = 60.0 * t.N * std::sqrt(x.tau0_s);
  double th = 0;
  x.values[0] = t.Q > 0 ? t.Q * g() : 0.0;
  for (std::size_t k = 1; k <= n; ++k) {
    th += t.rate * x.tau0_s + arw * g() + (t.B > 0 ? fl[k - 1] * x.tau0_s : 0.0);
    x.values[k] = th + (t.Q > 0 ? t.Q * g() : 0.0);
  }
  return x;
}

}  // namespace rwcalc::test
