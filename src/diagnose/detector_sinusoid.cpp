// The sinusoid detector: a periodogram line search on the 0.5-s block rates of the record without
// its mean-shape candidate (a step left in spreads over the low frequencies); a least-squares fit.
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <limits>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

namespace {

/// Periodogram |FFT|² of y under a Hann window, zero-padded to the first power of two ≥ 2n
/// (`nfft`), bins 0 … nfft/2 (`half_spectrum`: by the half-spectrum transform); `w2` = Σw².
std::vector<double> hann_periodogram(const std::vector<double>& y, bool half_spectrum, std::size_t& nfft, double& w2) {
  const std::size_t n = y.size();
  nfft = 1;
  while (nfft < 2 * n) nfft <<= 1;
  std::vector<double> buf(nfft, 0.0);
  w2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double h = 0.5 - 0.5 * std::cos(2.0 * kPi * (static_cast<double>(i) + 0.5) / static_cast<double>(n));
    buf[i] = h * y[i];
    w2 += h * h;
  }
  Eigen::FFT<double> fft;
  if (half_spectrum) fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<std::complex<double>> spec;
  fft.fwd(spec, buf);
  std::vector<double> P(nfft / 2 + 1);
  for (std::size_t k = 0; k < P.size(); ++k) P[k] = std::norm(spec[k]);
  return P;
}

/// Least-squares a·cos(2πft) + b·sin(2πft) through y_i at (i + ½)·tb; the explained sum of squares.
double sinusoid_ls(const std::vector<double>& y, double tb, double f, double& a, double& b) {
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d r = Eigen::Vector2d::Zero();
  const double w = 2.0 * kPi * f;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double t = (static_cast<double>(i) + 0.5) * tb;
    const double c = std::cos(w * t), s = std::sin(w * t);
    A(0, 0) += c * c;
    A(0, 1) += c * s;
    A(1, 1) += s * s;
    r(0) += c * y[i];
    r(1) += s * y[i];
  }
  A(1, 0) = A(0, 1);
  const Eigen::Vector2d x = A.ldlt().solve(r);
  a = x(0);
  b = x(1);
  return x.dot(r);
}

class SinusoidDetector final : public RecordDetector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::Sinusoid; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    return sinusoid_detect(r.clean, 0.0, false).statistic;
  }
  void estimate(const Stretch& s, Extension& x) const override {
    const auto est = sinusoid_detect(s.clean, s.sin_hint_hz);
    x.det.sinusoids.push_back({est.f_hz, est.amp, est.phase});
    x.findings.push_back({Effect::Sinusoid,
                          {{"frequency_hz", est.f_hz}, {"amplitude_deg_per_h", est.amp}, {"phase_rad", est.phase}},
                          {{"frequency_hz", est.f_sigma}, {"amplitude_deg_per_h", est.amp_sigma}},
                          {}});
  }
};

}  // namespace

SinusoidEstimate sinusoid_detect(const Decimated& d, double f_hint, bool estimate) {
  SinusoidEstimate e;
  const std::size_t pb = per_block_for(d, 0.5);
  std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 64) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double T = tb * static_cast<double>(n);
  remove_trend(y);
  std::size_t nfft = 0;
  double w2 = 0;
  const std::vector<double> P = hann_periodogram(y, false, nfft, w2);
  const std::size_t half = nfft / 2;
  const double df = 1.0 / (static_cast<double>(nfft) * tb);
  const double pad = static_cast<double>(nfft) / static_cast<double>(n);  // padded bins per true bin
  auto kf = [&](double f) { return static_cast<std::size_t>(std::lround(f / df)); };
  std::size_t k_lo = std::max<std::size_t>(kf(4.0 / T), 1);
  std::size_t k_hi = std::min(kf(std::min(0.25, 0.4 / tb)), half - 1);
  if (f_hint > 0) {
    k_lo = std::max<std::size_t>(1, kf(std::max(f_hint - 3.0 / T, 0.0)));
    k_hi = std::min(half - 1, kf(f_hint + 3.0 / T));
  }
  if (k_lo >= k_hi) return e;
  std::vector<double> v;
  auto window = [&](std::size_t k) -> std::vector<double>& {
    level_window(P, k, pad, false, v);
    return v;
  };
  // The level: the window's median over ln 2 (the median of an exponential variable).
  const Peak peak = peak_over_level(P, k_lo, k_hi, pad, window, std::log(2.0));
  e.statistic = peak.ratio;
  if (!estimate) return e;
  // Least-squares sinusoid on the (untapered, detrended) block rates around the peak.
  auto fit_at = [&](double f, double& a, double& b) { return sinusoid_ls(y, tb, f, a, b); };
  const double f0 = static_cast<double>(peak.k) * df;
  const double fbest = refine_frequency(fit_at, f0, 1.0 / (20.0 * T), 30, 30, std::numeric_limits<double>::infinity());
  double a = 0, b = 0;
  fit_at(fbest, a, b);
  const double att = block_attenuation(fbest, tb);  // the block mean sits at its centre
  e.f_hz = fbest;
  e.amp = std::hypot(a, b) / att;
  e.phase = std::atan2(-b, a);
  // One-sided PSD of the noise at the line (Hann-windowed periodogram scaled to (°/h)²/Hz).
  const double S = 2.0 * tb * peak.level / w2;
  e.amp_sigma = std::sqrt(S / T) / att;
  e.f_sigma = std::sqrt(6.0 * S / (e.amp * e.amp * T * T * T)) / (2.0 * kPi);
  return e;
}

LineCoefficients line_coefficients(std::vector<double> y, double tb, double f) {
  LineCoefficients c;
  const std::size_t n = y.size();
  if (n < 64 || !(tb > 0) || !(f > 0)) return c;
  const double T = tb * static_cast<double>(n);
  remove_trend(y);  // level and linear trend
  (void)sinusoid_ls(y, tb, f, c.a, c.b);
  // The noise PSD at f: the Hann periodogram's local level there.
  std::size_t nfft = 0;
  double w2 = 0;
  const std::vector<double> P = hann_periodogram(y, true, nfft, w2);
  const double df = 1.0 / (static_cast<double>(nfft) * tb);
  const double pad = static_cast<double>(nfft) / static_cast<double>(n);
  std::vector<double> v;
  level_window(P, static_cast<std::size_t>(std::lround(f / df)), pad, false, v);
  if (v.empty()) return c;
  const double S = 2.0 * tb * (median_of(v) / std::log(2.0)) / w2;  // one-sided, (°/h)²/Hz
  c.sigma = std::sqrt(S / T);
  return c;
}

std::unique_ptr<RecordDetector> sinusoid_detector() { return std::make_unique<SinusoidDetector>(); }

}  // namespace rwcalc::diag
