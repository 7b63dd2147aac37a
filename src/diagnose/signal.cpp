// The decimated angle, its block rates, deterministic terms and weighted least squares.
#include "signal.hpp"

#include <cmath>
#include <limits>

#include "rwcalc/fft.hpp"

namespace rwcalc::diag {

std::size_t per_block_for(const Decimated& d, double seconds) {
  return std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(seconds / d.tau_d)));
}

std::size_t decimation(double rate_hz) {
  // A power of two: the octave cluster sizes from D on are whole decimated periods, so the
  // ensembles' nulls can be simulated at the decimated step (ensemble.cpp).
  std::size_t D = 1;
  while (rate_hz >= 20.0 * static_cast<double>(D)) D *= 2;
  return D;
}

Decimated decimate(const PhaseSeries& x) {
  Decimated d;
  const std::size_t D = decimation(1.0 / x.tau0_s);
  d.tau_d = static_cast<double>(D) * x.tau0_s;
  d.theta.resize((x.points() - 1) / D + 1);
  for (std::size_t j = 0; j < d.theta.size(); ++j) d.theta[j] = x.diff(j * D, 0);
  return d;
}

std::vector<double> block_rates(const Decimated& d, std::size_t per_block) {
  const std::size_t L = d.theta.size() - 1;
  const std::size_t nb = L / per_block;
  std::vector<double> r(nb);
  const double T = static_cast<double>(per_block) * d.tau_d;
  for (std::size_t i = 0; i < nb; ++i) r[i] = (d.theta[(i + 1) * per_block] - d.theta[i * per_block]) / T;
  return r;
}

double deterministic_angle(const NoiseModel& m, double t) {
  double a = 0;
  for (const auto& s : m.sinusoids) {
    const double w = 2.0 * kPi * s.f_hz;
    a += s.amp_deg_per_h / w * (std::sin(w * t + s.phase_rad) - std::sin(s.phase_rad));
  }
  for (const auto& st : m.bias_steps) a += st.size_deg_per_h * std::max(0.0, t - st.t_s);
  for (const auto& w : m.warmups) a += w.amp_deg_per_h * w.tc_s * -std::expm1(-t / w.tc_s);
  return a;
}

std::vector<double> hann_periodogram(const std::vector<double>& y, std::size_t len, std::size_t nfft) {
  const std::size_t segs = len ? y.size() / len : 0;
  std::vector<double> P(nfft / 2 + 1, 0.0), w(len), buf(len);
  double w2 = 0;
  for (std::size_t i = 0; i < len; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * (static_cast<double>(i) + 0.5) / static_cast<double>(len));
    w2 += w[i] * w[i];
  }
  if (segs == 0) return P;
  detail::RealPowerSpectrum spectrum(nfft);
  for (std::size_t sg = 0; sg < segs; ++sg) {
    for (std::size_t i = 0; i < len; ++i) buf[i] = w[i] * y[sg * len + i];
    spectrum.add(buf.data(), len, P.data());
  }
  for (double& p : P) p /= w2 * static_cast<double>(segs);
  return P;
}

}  // namespace rwcalc::diag
