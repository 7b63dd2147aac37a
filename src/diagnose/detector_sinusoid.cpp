// The sinusoid detector: a periodogram line search on the 0.5-s block rates of the record without
// its mean-shape candidate (a step left in spreads over the low frequencies); a least-squares fit.
#include <unsupported/Eigen/FFT>

#include <cmath>
#include <algorithm>
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

/// The slow band, in cycles per record: from a period of T/2.8 (3 cycles with room for the
/// frequency's error) to where the ±24-bin level window of the whole-band search is whole.
constexpr double kSlowCyclesLo = 2.8, kSlowCyclesHi = 12.0;

/// The level of the Hann periodogram near a slow line, as c0 + c1/m at true bin m: white and
/// flicker rate noise, fitted to the true bins 3–80 but the line's main lobe (|m − c| ≤ 3 for a
/// line at c cycles per record; the bins below 3 are depressed by the detrending and the window)
/// by least squares weighted by the model's own level (three passes, the later ones dropping bins
/// above 6 times the fit: another line). Bins 3–20 carry most of what is known of the flicker
/// there. Tried first: a power law fitted to the cut-off ±24-bin window (its extrapolation to 3
/// bins scattered the null thresholds over 55–538), and the same fit on bins 6–80 only (c1 from 0
/// to 1566 between records of the same model).
struct SlowLevel {
  double c0 = 0, c1 = 0;
  [[nodiscard]] double at(double m) const { return c0 + c1 / m; }
};
SlowLevel slow_level(const std::vector<double>& P, double pad, double c) {
  SlowLevel L;
  std::vector<double> m, p;
  for (int b = 3; b <= 80; ++b) {
    const auto k = static_cast<std::size_t>(std::lround(b * pad));
    if (k >= P.size()) break;
    if (std::abs(b - c) <= 3.0) continue;
    m.push_back(b);
    p.push_back(P[k]);
  }
  if (m.size() < 10) return L;
  std::vector<double> sorted = p;
  L.c0 = median_of(sorted) / std::log(2.0);
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<double> y, w;
    std::vector<std::vector<double>> cols(2);
    for (std::size_t i = 0; i < m.size(); ++i) {
      const double lev = L.at(m[i]);
      if (pass > 0 && p[i] > 6.0 * lev) continue;
      y.push_back(p[i]);
      w.push_back(1.0 / (lev * lev));
      cols[0].push_back(1.0);
      cols[1].push_back(1.0 / m[i]);
    }
    const WlsOut o = wls(y, w, cols);
    const SlowLevel next{std::max(0.0, o.coef(0)), std::max(0.0, o.coef(1))};
    if (!(next.at(80.0) > 0)) break;
    L = next;
  }
  return L;
}

/// The block-mean columns of a mean-shape candidate (a step or a transient) on blocks of tb.
std::vector<std::vector<double>> candidate_columns(const NoiseModel* c, std::size_t n, double tb) {
  std::vector<std::vector<double>> cols;
  if (!c) return cols;
  for (const auto& st : c->bias_steps) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i)
      v[i] = std::clamp((static_cast<double>(i + 1) * tb - st.t_s) / tb, 0.0, 1.0);
    cols.push_back(std::move(v));
  }
  for (const auto& w : c->warmups) {
    std::vector<double> v(n);
    const double f = w.tc_s / tb * -std::expm1(-tb / w.tc_s);
    for (std::size_t i = 0; i < n; ++i) v[i] = std::exp(-static_cast<double>(i) * tb / w.tc_s) * f;
    cols.push_back(std::move(v));
  }
  return cols;
}

/// The slow band's line search: at 3–12 cycles per record a Hann window spreads a line over 4 of
/// the few bins there and lets the steep flicker of the lowest bins leak in, so the line is fitted
/// by least squares with level, trend and the record's mean-shape candidate (fitted jointly: the
/// candidate's removal beforehand would take a share of a line of a few cycles) on the 10-s block
/// rates of the record as measured, on a grid of T/4. The explained sum of squares E(f) over its
/// expectation S(f)/tb under noise of one-sided PSD S (slow_level) is exponential of mean 1.
struct SlowPeak {
  double ratio = 0, f_hz = 0, S = 0;
};
struct SlowFit {
  std::vector<double> y;
  double tb = 0, T = 0;
  Eigen::MatrixXd Q;   ///< orthonormal basis of level, trend and the candidate's columns
  Eigen::VectorXd r0;  ///< y less its projection on them
  Eigen::VectorXd c, s;
  SlowFit(const Decimated& raw, const NoiseModel* candidate) {
    const std::size_t pb = per_block_for(raw, 10.0);
    y = block_rates(raw, pb);
    tb = static_cast<double>(pb) * raw.tau_d;
    T = tb * static_cast<double>(y.size());
    const auto n = static_cast<Eigen::Index>(y.size());
    const auto extra = candidate_columns(candidate, y.size(), tb);
    Eigen::MatrixXd X(n, static_cast<Eigen::Index>(2 + extra.size()));
    for (Eigen::Index i = 0; i < n; ++i) {
      X(i, 0) = 1.0;
      X(i, 1) = static_cast<double>(i) / static_cast<double>(n);
      for (std::size_t k = 0; k < extra.size(); ++k)
        X(i, static_cast<Eigen::Index>(2 + k)) = extra[k][static_cast<std::size_t>(i)];
    }
    Q = Eigen::HouseholderQR<Eigen::MatrixXd>(X).householderQ() * Eigen::MatrixXd::Identity(n, X.cols());
    const Eigen::Map<const Eigen::VectorXd> Y(y.data(), n);
    r0 = Y - Q * (Q.transpose() * Y);
    c.resize(n);
    s.resize(n);
  }
  /// Explained sum of squares at f beyond level, trend and candidate; the line's coefficients
  /// a (cos) and b (sin) of the joint least squares (Frisch–Waugh: from the projected columns).
  double at(double f, double& a, double& b) {
    const Eigen::Index n = r0.size();
    // cos and sin at (i + ½)·tb by rotation (the ensembles call this for every record; the
    // rounding error grows as n·ε, 10⁻¹³ here).
    const std::complex<double> step = std::polar(1.0, 2.0 * kPi * f * tb);
    std::complex<double> z = std::polar(1.0, kPi * f * tb);
    for (Eigen::Index i = 0; i < n; ++i, z *= step) {
      c(i) = z.real();
      s(i) = z.imag();
    }
    c -= Q * (Q.transpose() * c);
    s -= Q * (Q.transpose() * s);
    Eigen::Matrix2d G;
    G << c.squaredNorm(), c.dot(s), c.dot(s), s.squaredNorm();
    const Eigen::Vector2d g(c.dot(r0), s.dot(r0));
    const Eigen::Vector2d ab = G.ldlt().solve(g);
    a = ab(0);
    b = ab(1);
    return ab.dot(g);
  }
};
SlowPeak slow_line_search(SlowFit& fit, const std::vector<double>& P, double pad, double w2, double tb_hann) {
  SlowPeak best;
  if (fit.y.size() < 40) return best;
  // The level fit depends on c only through the bins left out: one fit per set of them.
  double left_out_lo = -1, left_out_hi = -1;
  SlowLevel level;
  for (double c = kSlowCyclesLo; c <= kSlowCyclesHi; c += 0.25) {
    if (std::ceil(c - 3.0) != left_out_lo || std::floor(c + 3.0) != left_out_hi) {
      level = slow_level(P, pad, c);
      left_out_lo = std::ceil(c - 3.0);
      left_out_hi = std::floor(c + 3.0);
    }
    const double f = c / fit.T;
    double a, b;
    const double E = fit.at(f, a, b);
    // The Hann bins are of the 0.5-s record: its true bin m is at m/T as well.
    const double S = 2.0 * tb_hann * level.at(c) / w2;  // one-sided, (°/h)²/Hz
    const double r = S > 0 ? E * fit.tb / S : 0.0;
    if (r > best.ratio) best = {r, f, S};
  }
  return best;
}

/// A slow line's frequency (refined when `refine`), amplitude and phase by the least squares of
/// slow_line_search; σ as in sinusoid_detect with the local PSD S.
SinusoidEstimate slow_estimate(SlowFit& fit, const SlowPeak& p, bool refine, SinusoidEstimate e) {
  const double T = fit.T;
  auto fit_at = [&](double f, double& a, double& b) { return fit.at(f, a, b); };
  const double f =
      refine ? refine_frequency(fit_at, p.f_hz, 1.0 / (20.0 * T), 10, 30, std::numeric_limits<double>::infinity())
             : p.f_hz;
  double a = 0, b = 0;
  fit.at(f, a, b);
  const double att = block_attenuation(f, fit.tb);
  e.f_hz = f;
  e.amp = std::hypot(a, b) / att;
  e.phase = std::atan2(-b, a);
  e.amp_sigma = std::sqrt(p.S / T) / att;
  e.f_sigma = std::sqrt(6.0 * p.S / (e.amp * e.amp * T * T * T)) / (2.0 * kPi);
  return e;
}

class SinusoidDetector final : public RecordDetector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::Sinusoid; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    const NoiseModel c = r.step && r.warmup ? own_candidates(*r.step, *r.warmup) : own_candidates(r.dec);
    return sinusoid_detect(r.clean, 0.0, false, &r.dec, &c).statistic;
  }
  /// A line of fewer cycles in the block than its search starts at cannot show there by itself:
  /// the whole record's line is carried into the block, its amplitude and phase fitted there (the
  /// prediction of the other block then tests them).
  [[nodiscard]] bool shows_in(const Trial& t) const override {
    const double hint = t.stretch.sin_hint_hz;
    if (hint > 0 && hint * t.data.dec.duration() < kSlowCyclesLo + 1.0) return true;
    return RecordDetector::shows_in(t);
  }
  void estimate(const Stretch& s, Extension& x) const override {
    const NoiseModel c = own_candidates(s.dec);
    const auto est = sinusoid_detect(s.clean, s.sin_hint_hz, true, &s.dec, &c);
    x.det.sinusoids.push_back({est.f_hz, est.amp, est.phase});
    x.findings.push_back({Effect::Sinusoid,
                          {{"frequency_hz", est.f_hz}, {"amplitude_deg_per_h", est.amp}, {"phase_rad", est.phase}},
                          {{"frequency_hz", est.f_sigma}, {"amplitude_deg_per_h", est.amp_sigma}},
                          {}});
  }
};

}  // namespace

SinusoidEstimate sinusoid_detect(const Decimated& d, double f_hint, bool estimate, const Decimated* raw,
                                 const NoiseModel* candidate) {
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
  Peak peak = peak_over_level(P, k_lo, k_hi, pad, window, std::log(2.0));
  // Both bands' ratios are exponential of mean 1 under the local noise: each less the log of the
  // number of frequencies it searched, the larger is the statistic (a Bonferroni −ln p).
  e.statistic = peak.ratio - std::log(std::max(1.0, static_cast<double>(k_hi - k_lo) / pad));
  SlowPeak slow;
  SlowFit fit(raw ? *raw : d, raw ? candidate : nullptr);
  if (f_hint > 0 && f_hint * T < kSlowCyclesHi + 3.0) {  // a slow line: its frequency is the hint
    slow = {0, f_hint, 2.0 * tb * slow_level(P, pad, f_hint * T).at(f_hint * T) / w2};
  } else if (f_hint <= 0) {
    slow = slow_line_search(fit, P, pad, w2, tb);
    const double s_slow = slow.ratio - std::log(kSlowCyclesHi - kSlowCyclesLo);
    if (s_slow > e.statistic)
      e.statistic = s_slow;
    else
      slow.f_hz = 0;
  }
  if (!estimate) return e;
  if (slow.f_hz > 0) return slow_estimate(fit, slow, f_hint <= 0, e);
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
