// The high-frequency line detector: a line search on the rate samples of floating data from 0.25 Hz
// to Nyquist, for a coherent line and (at Welch resolutions) one broadened by a wandering phase.
#include <boost/math/special_functions/gamma.hpp>

#include <cmath>
#include <complex>
#include <limits>

#include "allan/fft.hpp"
#include "diagnose/detector.hpp"

namespace rwcalc::diag {

namespace {

/// Mean periodogram P[0 … nfft/2] of consecutive Hann-windowed segments of `len` samples. They do
/// not overlap: a coherent line then gains no more from the mean than from the whole record's
/// periodogram, and K·P/level is Gamma(K) under the null.
std::vector<double> mean_periodogram(const std::vector<double>& y, std::size_t len, std::size_t nfft, std::size_t& segs,
                                     double& w2) {
  const std::size_t n = y.size();
  len = std::min(len, n);
  const std::size_t hop = len;
  std::vector<double> P(nfft / 2 + 1, 0.0), win(len), buf(len);
  w2 = 0;
  for (std::size_t i = 0; i < len; ++i) {
    win[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * (static_cast<double>(i) + 0.5) / static_cast<double>(len));
    w2 += win[i] * win[i];
  }
  detail::RealPowerSpectrum spectrum(nfft);
  segs = 0;
  for (std::size_t s = 0; s + len <= n; s += hop) {
    for (std::size_t i = 0; i < len; ++i) buf[i] = win[i] * y[s + i];
    spectrum.add(buf.data(), len, P.data());
    ++segs;
  }
  for (double& p : P) p /= static_cast<double>(std::max<std::size_t>(segs, 1));
  return P;
}

/// −ln of the upper tail of a mean of K unit exponentials at r, asymptotic where it underflows.
double neg_log_tail(double K, double r) {
  const double x = K * r;
  const double q = boost::math::gamma_q(K, x);
  if (q > 1e-280) return -std::log(q);
  return x - (K - 1.0) * std::log(x) + std::lgamma(K);
}

/// The best peak of the periodogram at one resolution (segments of `len` samples).
struct Resolution {
  double score = -std::numeric_limits<double>::infinity(), ratio = 0, level = 0, K = 1, w2 = 0, df = 0, pad = 2;
  std::size_t k = 0, len = 0;
  std::vector<double> P;
};

/// The score (−ln tail probability less ln of the bins searched) has one null maximum at all resolutions.
Resolution search(const std::vector<double>& y, std::size_t len, double t0, double f_min, double f_hint) {
  const std::size_t n = y.size();
  const double T = t0 * static_cast<double>(n);
  Resolution r;
  std::size_t nfft = 1;
  while (nfft < 2 * len) nfft <<= 1;
  const std::size_t half = nfft / 2;
  r.df = 1.0 / (static_cast<double>(nfft) * t0);
  r.pad = static_cast<double>(nfft) / static_cast<double>(len);
  auto kf = [&](double f) { return static_cast<std::size_t>(std::lround(f / r.df)); };
  // A Welch level starts 50 of its bins up: below, the spectrum's curvature (1/f flicker) within
  // the ±24-bin window would bias the level by more than the mean's scatter.
  const double f_start = len == n ? std::max(f_min, 4.0 / T) : std::max(f_min, 50.0 / (t0 * static_cast<double>(len)));
  std::size_t k_lo = std::max<std::size_t>(kf(f_start), 1);
  std::size_t k_hi = half - 1;
  if (f_hint > 0) {
    k_lo = std::max(k_lo, kf(std::max(f_hint - 3.0 / T, 0.0)));
    k_hi = std::min(k_hi, kf(f_hint + 3.0 / T));
  }
  if (k_lo >= k_hi) return r;
  std::size_t segs = 0;
  r.P = mean_periodogram(y, len, nfft, segs, r.w2);
  r.K = static_cast<double>(segs);
  const double med =
      r.K == 1 ? std::log(2.0) : boost::math::gamma_p_inv(r.K, 0.5) / r.K;  // of a mean of K exponentials
  std::vector<double> v;
  auto window = [&](std::size_t k) -> std::vector<double>& {
    level_window(r.P, k, r.pad, true, v);  // at the spectrum's end shifted inwards, keeping its size
    return v;
  };
  const Peak peak = peak_over_level(r.P, k_lo, k_hi, r.pad, window, med);
  if (!(peak.ratio > 0)) return r;
  r.ratio = peak.ratio;
  r.level = peak.level;
  r.k = peak.k;
  r.len = len;
  r.score = neg_log_tail(r.K, peak.ratio) - std::log(std::max(1.0, static_cast<double>(k_hi - k_lo) / r.pad));
  return r;
}

/// P at k ± d, d = inner, inner + step, … ≤ outer, within P[2 …].
std::vector<double> ring_values(const std::vector<double>& P, std::size_t k, std::size_t inner, std::size_t outer,
                                std::size_t step) {
  std::vector<double> v;
  for (std::size_t d = inner; d <= outer; d += step) {
    if (k > d + 1) v.push_back(P[k - d]);
    if (k + d < P.size()) v.push_back(P[k + d]);
  }
  return v;
}

/// A line that won at a Welch resolution: its power is the excess over the level 48–96 true bins
/// away, summed over the contiguous bins above it; frequency and width from its centroid and
/// spread, phase 0. A strong coherent line can win there too: when the whole record's highest bin
/// in the band holds half the excess power (a Hann peak P carries 2P/(Σw)²), f0 and the level
/// come from the whole record and false is returned.
bool broad_line(LineEstimate& e, Resolution& best, const std::vector<double>& full_P, double full_df, std::size_t n,
                double t0, double& f0) {
  const auto inner = static_cast<std::size_t>(48 * best.pad), outer = static_cast<std::size_t>(96 * best.pad);
  const std::size_t half = best.P.size() - 1;
  const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(best.pad)));
  std::vector<double> ring = ring_values(best.P, best.k, inner, outer, stepb);
  const double med = boost::math::gamma_p_inv(best.K, 0.5) / best.K;
  const double base = ring.empty() ? best.level : median_of(ring) / med;
  std::size_t a = best.k, b = best.k;
  while (a > 1 && best.k - a < inner && best.P[a - 1] > base) --a;
  while (b + 1 <= half && b - best.k < inner && best.P[b + 1] > base) ++b;
  const double scale = 2.0 * t0 / best.w2;  // one-sided PSD per periodogram unit, (°/h)²/Hz
  double pw = 0, fm = 0, var = 0;
  for (std::size_t k = a; k <= b; ++k) {
    const double ex = (best.P[k] - base) * scale * best.df;
    pw += ex;
    fm += ex * static_cast<double>(k) * best.df;
    var += std::pow(best.P[k] * scale * best.df, 2) / best.K / best.pad;
  }
  if (!(pw > 0)) return true;
  fm /= pw;
  double pk = 0;
  std::size_t kk = 0;
  for (std::size_t k = static_cast<std::size_t>(static_cast<double>(a) * best.df / full_df);
       full_df > 0 && k < full_P.size() && static_cast<double>(k) * full_df <= static_cast<double>(b) * best.df; ++k)
    if (full_P[k] > pk) {
      pk = full_P[k];
      kk = k;
    }
  const double sum_w = 0.5 * static_cast<double>(n);
  if (2.0 * pk / (sum_w * sum_w) >= 0.5 * pw) {
    e.coherent = true;
    e.resolution_hz = 1.0 / (t0 * static_cast<double>(n));
    f0 = static_cast<double>(kk) * full_df;
    std::vector<double> lv = ring_values(full_P, kk, 96, 192, 2);  // the level at ±48 … ±96 true bins
    best.level = median_of(lv) / std::log(2.0);
    best.w2 = 0.375 * static_cast<double>(n);
    return false;
  }
  double s2 = 0;
  for (std::size_t k = a; k <= b; ++k) {
    const double f = static_cast<double>(k) * best.df;
    s2 += (best.P[k] - base) * scale * best.df * (f - fm) * (f - fm);
  }
  e.width_hz = std::sqrt(std::max(0.0, s2 / pw));
  const double att = block_attenuation(fm, t0);
  const double amp_s = std::sqrt(2.0 * pw);  // amplitude of the per-sample rate
  e.f_hz = fm;
  e.amp = amp_s / att;
  e.phase = 0;
  e.amp_sigma = std::sqrt(var) / amp_s / att;
  e.f_sigma = std::max(e.width_hz * std::sqrt(var) / pw, e.resolution_hz / std::sqrt(12.0));
  return true;
}

/// A coherent line: least-squares sinusoid on the detrended samples; σ from the level at the line.
void coherent_line(LineEstimate& e, const std::vector<double>& y, double t0, double f0, double level, double w2) {
  const std::size_t n = y.size();
  const double T = t0 * static_cast<double>(n);
  auto fit_at = [&](double f, double& a, double& b) {
    double cc = 0, cs = 0, ss = 0, ry = 0, sy = 0;
    const double w = 2.0 * kPi * f;
    const std::complex<double> rot = std::polar(1.0, w * t0);
    std::complex<double> z;
    for (std::size_t i = 0; i < n; ++i) {
      if (i % 4096 == 0) z = std::polar(1.0, w * (static_cast<double>(i) + 0.5) * t0);
      const double c = z.real(), s = z.imag();
      cc += c * c;
      cs += c * s;
      ss += s * s;
      ry += c * y[i];
      sy += s * y[i];
      z *= rot;
    }
    Eigen::Matrix2d A;
    A << cc, cs, cs, ss;
    const Eigen::Vector2d r(ry, sy);
    const Eigen::Vector2d sol = A.ldlt().solve(r);
    a = sol(0);
    b = sol(1);
    return sol.dot(r);
  };
  const double fbest = refine_frequency(fit_at, f0, 1.0 / (16.0 * T), 12, 20, 0.5 / t0);
  double a = 0, b = 0;
  fit_at(fbest, a, b);
  const double att = block_attenuation(fbest, t0);
  e.f_hz = fbest;
  e.amp = std::hypot(a, b) / att;
  e.phase = std::atan2(-b, a);
  const double S = 2.0 * t0 * level / w2;  // one-sided PSD of the noise at the line, (°/h)²/Hz
  e.amp_sigma = std::sqrt(S / T) / att;
  e.f_sigma = e.amp > 0 ? std::sqrt(6.0 * S / (e.amp * att * e.amp * att * T * T * T)) / (2.0 * kPi) : 0.0;
}

class LineDetector final : public RecordDetector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::Line; }
  [[nodiscard]] bool full_rate() const override { return true; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    return line_detect(r.series, kHighLineMinHz, 0.0, false).statistic;
  }
  /// A broadened line cannot be subtracted from the data: it enters the model only, as a sinusoid
  /// of its power at its centroid (the Allan variance sees the power, not the phase).
  void estimate(const Stretch& s, Extension& x) const override {
    const auto est = line_detect(s.rec->phase, kHighLineMinHz, s.line_hint_hz);
    (est.coherent ? x.det.sinusoids : x.broad).push_back({est.f_hz, est.amp, est.phase});
    Finding f{Effect::Line,
              {{"frequency_hz", est.f_hz}, {"amplitude_deg_per_h", est.amp}, {"phase_rad", est.phase}},
              {{"frequency_hz", est.f_sigma}, {"amplitude_deg_per_h", est.amp_sigma}},
              {{"coherent", est.coherent}, {"resolution_hz", est.resolution_hz}}};
    if (!est.coherent) f.evidence["width_hz"] = est.width_hz;
    x.findings.push_back(std::move(f));
  }
};

}  // namespace

LineEstimate line_detect(const PhaseSeries& x, double f_min, double f_hint, bool estimate) {
  LineEstimate e;
  if (x.points() < 130) return e;
  const std::size_t n = x.points() - 1;
  const double t0 = x.tau0_s;
  std::vector<double> y(n);  // per-sample rates (″/s = °/h), level and linear trend removed
  for (std::size_t i = 0; i < n; ++i) y[i] = x.diff(i + 1, i) / t0;
  remove_trend(y);
  // The whole record (a coherent line), and Welch means (≥ 8 segments) for a broadened one.
  std::vector<std::size_t> lens{n};
  if (f_hint <= 0)
    for (std::size_t len : {std::size_t{16384}, std::size_t{4096}, std::size_t{1024}})
      if (8 * len <= n) lens.push_back(len);
  Resolution best;
  std::vector<double> full_P;  // the whole record's periodogram
  double full_df = 0;
  for (const std::size_t len : lens) {
    Resolution r = search(y, len, t0, f_min, f_hint);
    if (r.len == 0) continue;
    if (len == n && estimate) {
      full_P = r.P;
      full_df = r.df;
    }
    if (r.score > best.score) best = std::move(r);
  }
  if (best.len == 0) return e;
  e.statistic = best.score;
  e.resolution_hz = 1.0 / (static_cast<double>(best.len) * t0);
  e.coherent = best.len == n;
  if (!estimate) return e;
  double f0 = static_cast<double>(best.k) * best.df;
  if (!e.coherent && broad_line(e, best, full_P, full_df, n, t0, f0)) return e;
  coherent_line(e, y, t0, f0, best.level, best.w2);
  return e;
}

std::unique_ptr<RecordDetector> line_detector() { return std::make_unique<LineDetector>(); }

}  // namespace rwcalc::diag
