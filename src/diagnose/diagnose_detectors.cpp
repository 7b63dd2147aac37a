// The diagnosis detectors: periodogram line search (sinusoid), local two-window change point
// (bias step), exponential on the early block means (warm-up), and the mid-τ Allan-variance shape
// fits (Gauss–Markov bump, low-pass deficit). Each returns its statistic and, by least squares
// on the same data, the effect's parameters.
#include <unsupported/Eigen/FFT>

#include <Eigen/Dense>
#include <boost/math/special_functions/gamma.hpp>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <array>

#include "rwcalc/diagnose_detectors.hpp"

#include "allan/fft.hpp"

namespace rwcalc::diag {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCorrShrink = 0.2;  ///< weight of the identity in the mid-τ correlation matrix

/// The median of v's values (the upper one of an even count); reorders v.
double median_of(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// White-noise σ of a series from its first differences (rms / √2). Not the median absolute
/// difference: block means of pulse counts are quantized, and most differences can be 0.
double diff_sigma(const std::vector<double>& y) {
  if (y.size() < 3) return 0.0;
  double s = 0;
  for (std::size_t i = 0; i + 1 < y.size(); ++i) s += (y[i + 1] - y[i]) * (y[i + 1] - y[i]);
  return std::sqrt(s / static_cast<double>(y.size() - 1) / 2.0);
}

std::size_t per_block_for(const Decimated& d, double seconds) {
  return std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(seconds / d.tau_d)));
}

}  // namespace

std::size_t decimation(double rate_hz) {
  if (rate_hz < 20.0) return 1;
  return static_cast<std::size_t>(std::floor(rate_hz / 10.0));
}

Decimated decimate(const PhaseSeries& x, std::size_t first, std::size_t last) {
  Decimated d;
  if (last == 0 || last >= x.points()) last = x.points() - 1;
  const std::size_t D = decimation(1.0 / x.tau0_s);
  d.tau_d = static_cast<double>(D) * x.tau0_s;
  const std::size_t n = (last - first) / D;
  d.theta.resize(n + 1);
  for (std::size_t j = 0; j <= n; ++j) d.theta[j] = x.diff(first + j * D, first);
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

std::vector<std::size_t> mid_tau_grid(const Decimated& d) {
  // 10 per decade from 1 s to a third of the record.
  std::vector<std::size_t> g;
  const double T = d.duration();
  for (int i = 0;; ++i) {
    const double tau = std::pow(10.0, i / 10.0);
    if (tau > T / 3.0) break;
    const auto m = static_cast<std::size_t>(std::max(1L, std::lround(tau / d.tau_d)));
    if (g.empty() || m > g.back()) g.push_back(m);
  }
  return g;
}

std::vector<double> decimated_avar(const Decimated& d, const std::vector<std::size_t>& grid) {
  std::vector<double> v(grid.size(), 0.0);
  const std::size_t P = d.theta.size();
  const double* th = d.theta.data();
  for (std::size_t g = 0; g < grid.size(); ++g) {
    const std::size_t m = grid[g];
    if (P <= 2 * m) break;
    const std::size_t terms = P - 2 * m;
    double s = 0;
    for (std::size_t k = 0; k < terms; ++k) {
      const double e = th[k + 2 * m] - 2.0 * th[k + m] + th[k];
      s += e * e;
    }
    const double tau = static_cast<double>(m) * d.tau_d;
    v[g] = s / (2.0 * tau * tau * static_cast<double>(terms));
  }
  return v;
}

// ---- sinusoid --------------------------------------------------------------------------------

namespace {

/// A periodogram's largest ratio to its local level over bins [k_lo, k_hi] (the first bin of the
/// largest), the level taken afresh every 4 true bins (pad padded bins each) for the group of bins
/// up to the next: the median of the values `window(k)` fills in for the group's first bin k, over
/// `divisor`. Ratio 0 when no level is positive.
///
/// The median (a selection, most of the search's time) is taken only for a group that can beat
/// the best ratio so far: its largest bin g can give g/level > best only if the median M is below
/// g·divisor/best, i.e. if more than half the window lies below that bound — a count, branch-free.
/// A group is skipped only when M is at least the bound times (1 + 1e-9), so that its rounded
/// ratios cannot exceed the best: the result is the one every group's median gives.
struct Peak {
  double ratio = 0, level = 0;
  std::size_t k = 0;
};
template <class Window>
Peak peak_over_level(const std::vector<double>& P, std::size_t k_lo, std::size_t k_hi, double pad, Window& window,
                     double divisor) {
  Peak best;
  best.k = k_lo;
  const std::size_t stride = std::max<std::size_t>(1, static_cast<std::size_t>(pad));
  const std::size_t group = 4 * stride;
  for (std::size_t k0 = k_lo; k0 <= k_hi; k0 += group) {
    const std::size_t k1 = std::min(k_hi, k0 + group - 1);
    std::vector<double>& v = window(k0);
    if (best.ratio > 0) {
      double g = 0;
      for (std::size_t k = k0; k <= k1; ++k) g = P[k] > g ? P[k] : g;
      const double bound = g * divisor / best.ratio * (1.0 + 1e-9);
      std::size_t below = 0;
      for (const double x : v) below += x < bound;
      if (below <= v.size() / 2) continue;  // the median is at least the bound
    }
    const double lev = median_of(v) / divisor;
    if (lev <= 0) continue;
    for (std::size_t k = k0; k <= k1; ++k) {
      const double r = P[k] / lev;
      if (r > best.ratio) best = {r, lev, k};
    }
  }
  return best;
}

/// The frequency of a line near f0: the best of f0 + i·step (|i| ≤ half_steps, 0 < f < f_max) by
/// the explained sum of squares of fit_at(f, a, b), then `iters` golden-section steps in ±step.
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
  double lo = fbest - step, hi = fbest + step;
  for (int it = 0; it < iters; ++it) {
    const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    double a, b;
    if (fit_at(m1, a, b) > fit_at(m2, a, b))
      hi = m2;
    else
      lo = m1;
  }
  return 0.5 * (lo + hi);
}

/// y less its mean and its least-squares linear trend over the sample index.
void remove_trend(std::vector<double>& y) {
  const std::size_t n = y.size();
  double sy = 0, sty = 0, stt = 0;
  const double m = 0.5 * static_cast<double>(n - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) - m;
    sy += y[i];
    sty += t * y[i];
    stt += t * t;
  }
  const double a = sy / static_cast<double>(n), b = sty / stt;
  for (std::size_t i = 0; i < n; ++i) y[i] -= a + b * (static_cast<double>(i) - m);
}

/// The FFT of y under a Hann window (at the sample centres), zero-padded to the first power of two
/// of at least 2n (`nfft`; only the first half with `half_spectrum`), and the window's Σw².
std::vector<std::complex<double>> hann_spectrum(const std::vector<double>& y, bool half_spectrum, std::size_t& nfft,
                                                double& w2) {
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
  return spec;
}

/// Least-squares a·cos(2πft) + b·sin(2πft) through y_i at t_i = (i + ½)·tb: (a, b), and the
/// explained sum of squares as the result.
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

}  // namespace

SinusoidEstimate sinusoid_detect(const Decimated& d, double f_hint, bool estimate) {
  SinusoidEstimate e;
  const std::size_t pb = per_block_for(d, 0.5);
  std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 64) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double T = tb * static_cast<double>(n);
  // Remove the level and the linear trend.
  remove_trend(y);
  std::size_t nfft = 0;
  double w2 = 0;
  const std::vector<std::complex<double>> spec = hann_spectrum(y, false, nfft, w2);
  const std::size_t half = nfft / 2;
  std::vector<double> P(half + 1);
  for (std::size_t k = 0; k <= half; ++k) P[k] = std::norm(spec[k]);
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
  const auto gap = static_cast<std::size_t>(std::ceil(3.0 * pad));
  // Local level: the median of the periodogram over ±24 true bins around k (one value per true
  // bin, the main lobe left out), / ln 2 (the median of an exponential variable).
  std::vector<double> v;  // the level's scratch, reused
  v.reserve(64);
  auto window = [&](std::size_t k) -> std::vector<double>& {
    const auto W = static_cast<std::size_t>(24.0 * pad);
    const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(pad)));
    v.clear();
    const std::size_t a = k > W ? k - W : 1, b = std::min(half, k + W);
    for (std::size_t j = a; j <= b; j += stepb) {
      if (j + gap >= k && j <= k + gap) continue;
      v.push_back(P[j]);
    }
    return v;
  };
  const Peak peak = peak_over_level(P, k_lo, k_hi, pad, window, std::log(2.0));
  const double best = peak.ratio, best_level = peak.level;
  const std::size_t kbest = peak.k;
  e.statistic = best;
  if (!estimate) return e;
  // Least-squares sinusoid on the (untapered, detrended) block rates around the peak.
  auto fit_at = [&](double f, double& a, double& b) { return sinusoid_ls(y, tb, f, a, b); };
  const double f0 = static_cast<double>(kbest) * df;
  const double fbest = refine_frequency(fit_at, f0, 1.0 / (20.0 * T), 30, 30, std::numeric_limits<double>::infinity());
  double a = 0, b = 0;
  fit_at(fbest, a, b);
  // Block averaging attenuates the rate amplitude by sinc(π f tb); the block mean sits at its centre.
  const double x = kPi * fbest * tb;
  const double att = x > 1e-9 ? std::sin(x) / x : 1.0;
  e.f_hz = fbest;
  e.amp = std::hypot(a, b) / att;
  e.phase = std::atan2(-b, a);
  // One-sided PSD of the noise at the line (Hann-windowed periodogram scaled to (°/h)²/Hz).
  const double S = 2.0 * tb * best_level / w2;
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
  // The noise PSD at f: the Hann periodogram's median over ±24 true bins (main lobe left out).
  std::size_t nfft = 0;
  double w2 = 0;
  const std::vector<std::complex<double>> spec = hann_spectrum(y, true, nfft, w2);
  const std::size_t half = nfft / 2;
  const double df = 1.0 / (static_cast<double>(nfft) * tb);
  const double pad = static_cast<double>(nfft) / static_cast<double>(n);
  const auto k = static_cast<std::size_t>(std::lround(f / df));
  const auto W = static_cast<std::size_t>(24.0 * pad), gap = static_cast<std::size_t>(std::ceil(3.0 * pad));
  const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(pad)));
  std::vector<double> v;
  for (std::size_t j = k > W ? k - W : 1; j <= std::min(half, k + W) && j < spec.size(); j += stepb) {
    if (j + gap >= k && j <= k + gap) continue;
    v.push_back(std::norm(spec[j]));
  }
  if (v.empty()) return c;
  const double S = 2.0 * tb * (median_of(v) / std::log(2.0)) / w2;  // one-sided, (°/h)²/Hz
  c.sigma = std::sqrt(S / T);
  return c;
}

// ---- high-frequency line on the raw samples ---------------------------------------------------

namespace {

/// Mean periodogram of consecutive Hann-windowed segments of `len` samples (one of the whole
/// series when len ≥ y.size()), each zero-padded to `nfft`; P[0 … nfft/2]. The segments do not
/// overlap: a coherent line then gains no more from the mean of K segments than from the whole
/// record's periodogram, and K·P/level is Gamma(K) under the null.
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

/// −ln of the upper tail of a mean of K unit exponential variables at r (K·r ~ Gamma(K)), with the
/// leading asymptotic term where the tail underflows.
double neg_log_tail(double K, double r) {
  const double x = K * r;
  const double q = boost::math::gamma_q(K, x);
  if (q > 1e-280) return -std::log(q);
  return x - (K - 1.0) * std::log(x) + std::lgamma(K);
}

}  // namespace

LineEstimate line_detect(const PhaseSeries& x, double f_min, double f_hint, bool estimate) {
  LineEstimate e;
  if (x.points() < 130) return e;
  const std::size_t n = x.points() - 1;
  const double t0 = x.tau0_s;
  const double T = t0 * static_cast<double>(n);
  // Per-sample rates (″/s = °/h), level and linear trend removed.
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = x.diff(i + 1, i) / t0;
  remove_trend(y);
  // Resolutions: the whole record (a coherent line), and Welch means of segments of 16384, 4096
  // and 1024 samples (at least 8 segments) for a line broadened by a wandering frequency or phase.
  std::vector<std::size_t> lens{n};
  if (f_hint <= 0)
    for (std::size_t len : {std::size_t{16384}, std::size_t{4096}, std::size_t{1024}})
      if (8 * len <= n) lens.push_back(len);
  struct Best {
    double score = -std::numeric_limits<double>::infinity(), ratio = 0, level = 0, K = 1, w2 = 0, df = 0, pad = 2;
    std::size_t k = 0, len = 0, nfft = 0;
    std::vector<double> P;
  } best;
  std::vector<double> full_P;  // the whole record's periodogram
  double full_df = 0;
  for (const std::size_t len : lens) {
    std::size_t nfft = 1;
    while (nfft < 2 * len) nfft <<= 1;
    const std::size_t half = nfft / 2;
    const double seg_T = t0 * static_cast<double>(len);
    const double df = 1.0 / (static_cast<double>(nfft) * t0);
    const double pad = static_cast<double>(nfft) / static_cast<double>(len);
    auto kf = [&](double f) { return static_cast<std::size_t>(std::lround(f / df)); };
    // A Welch level starts 50 of its bins up: below, the spectrum's curvature (1/f flicker) within
    // the ±24-bin window would bias the level by more than the mean's scatter.
    const double f_start = len == n ? std::max(f_min, 4.0 / T) : std::max(f_min, 50.0 / seg_T);
    std::size_t k_lo = std::max<std::size_t>(kf(f_start), 1);
    std::size_t k_hi = half - 1;
    if (f_hint > 0) {
      k_lo = std::max(k_lo, kf(std::max(f_hint - 3.0 / T, 0.0)));
      k_hi = std::min(k_hi, kf(f_hint + 3.0 / T));
    }
    if (k_lo >= k_hi) continue;
    std::size_t segs = 0;
    double w2 = 0;
    std::vector<double> P = mean_periodogram(y, len, nfft, segs, w2);
    const double K = static_cast<double>(segs);
    // Median of a mean of K unit exponentials (ln 2 for K = 1).
    const double med = K == 1 ? std::log(2.0) : boost::math::gamma_p_inv(K, 0.5) / K;
    const auto gap = static_cast<std::size_t>(std::ceil(3.0 * pad));
    const auto W = static_cast<std::size_t>(24.0 * pad);
    const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(pad)));
    std::vector<double> v;
    v.reserve(64);
    // Local level: the median of one value per true bin over ±24 true bins (main lobe left out);
    // at the ends of the spectrum the window is shifted inwards so that it keeps its size.
    auto window = [&](std::size_t k) -> std::vector<double>& {
      std::size_t a = k > W ? k - W : 1, b = k + W;
      if (b > half) {
        a = a > b - half ? a - (b - half) : 1;
        b = half;
      }
      v.clear();
      for (std::size_t j = a; j <= b; j += stepb) {
        if (j + gap >= k && j <= k + gap) continue;
        v.push_back(P[j]);
      }
      return v;
    };
    const Peak peak = peak_over_level(P, k_lo, k_hi, pad, window, med);
    const double rbest = peak.ratio, lbest = peak.level;
    const std::size_t kbest = peak.k;
    if (!(rbest > 0)) continue;
    // Comparable across resolutions: −ln of the peak's tail probability less ln of the number of
    // true bins searched (the expected null maximum is then about the same at every resolution).
    const double bins = std::max(1.0, static_cast<double>(k_hi - k_lo) / pad);
    const double score = neg_log_tail(K, rbest) - std::log(bins);
    if (len == n && estimate) {
      full_P = P;
      full_df = df;
    }
    if (score > best.score) {
      best.score = score;
      best.ratio = rbest;
      best.level = lbest;
      best.K = K;
      best.w2 = w2;
      best.df = df;
      best.pad = pad;
      best.k = kbest;
      best.len = len;
      best.nfft = nfft;
      best.P = std::move(P);
    }
  }
  if (best.len == 0) return e;
  e.statistic = best.score;
  e.resolution_hz = 1.0 / (static_cast<double>(best.len) * t0);
  e.coherent = best.len == n;
  if (!estimate) return e;
  double f0 = static_cast<double>(best.k) * best.df;
  if (!e.coherent) {
    // A broadened line: its power is the periodogram's excess over the level around the band
    // (the median of the bins 48–96 true bins away on both sides), summed over the contiguous
    // bins above that level; frequency and width from the excess's centroid and spread. The
    // phase of a wandering line is not defined: 0.
    const auto inner = static_cast<std::size_t>(48 * best.pad), outer = static_cast<std::size_t>(96 * best.pad);
    const std::size_t half = best.P.size() - 1;
    std::vector<double> ring;
    const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(best.pad)));
    for (std::size_t d = inner; d <= outer; d += stepb) {
      if (best.k > d + 1) ring.push_back(best.P[best.k - d]);
      if (best.k + d <= half) ring.push_back(best.P[best.k + d]);
    }
    const double med = boost::math::gamma_p_inv(best.K, 0.5) / best.K;
    const double base = ring.empty() ? best.level : median_of(ring) / med;
    std::size_t a = best.k, b = best.k;
    while (a > 1 && best.k - a < inner && best.P[a - 1] > base) --a;
    while (b + 1 <= half && b - best.k < inner && best.P[b + 1] > base) ++b;
    // One-sided PSD per periodogram unit, (°/h)²/Hz; bins best.df apart.
    const double scale = 2.0 * t0 / best.w2;
    double pw = 0, fm = 0, var = 0;
    for (std::size_t k = a; k <= b; ++k) {
      const double ex = (best.P[k] - base) * scale * best.df;
      pw += ex;
      fm += ex * static_cast<double>(k) * best.df;
      var += std::pow(best.P[k] * scale * best.df, 2) / best.K / best.pad;
    }
    if (!(pw > 0)) return e;
    fm /= pw;
    // A strong phase-stable line can win at a Welch resolution too (its sidelobes raise the local
    // level of every resolution alike, and the mean of K segments then counts it K times): it is
    // coherent when the whole record's highest bin in the band holds at least half the excess
    // power (a Hann peak of height P carries the power 2P/(Σw)²).
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
      e.resolution_hz = 1.0 / T;
      f0 = static_cast<double>(kk) * full_df;
      // The noise level at the line from the whole record's periodogram (±48 … ±96 true bins).
      std::vector<double> lv;
      for (std::size_t d = 96; d <= 192; d += 2) {
        if (kk > d + 1) lv.push_back(full_P[kk - d]);
        if (kk + d < full_P.size()) lv.push_back(full_P[kk + d]);
      }
      best.level = median_of(lv) / std::log(2.0);
      best.w2 = 0.375 * static_cast<double>(n);
    }
    if (!e.coherent) {
      double s2 = 0;
      for (std::size_t k = a; k <= b; ++k) {
        const double f = static_cast<double>(k) * best.df;
        s2 += (best.P[k] - base) * scale * best.df * (f - fm) * (f - fm);
      }
      e.width_hz = std::sqrt(std::max(0.0, s2 / pw));
      const double xs = kPi * fm * t0;
      const double att = xs > 1e-9 ? std::sin(xs) / xs : 1.0;
      const double amp_s = std::sqrt(2.0 * pw);  // amplitude of the per-sample rate
      e.f_hz = fm;
      e.amp = amp_s / att;
      e.phase = 0;
      e.amp_sigma = std::sqrt(var) / amp_s / att;
      e.f_sigma = std::max(e.width_hz * std::sqrt(var) / pw, e.resolution_hz / std::sqrt(12.0));
      return e;
    }
  }
  // A coherent line: least-squares sinusoid on the detrended samples (at their centres), cos/sin
  // by rotation, re-seeded every 4096 samples.
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
  const double xs = kPi * fbest * t0;
  const double att = xs > 1e-9 ? std::sin(xs) / xs : 1.0;
  e.f_hz = fbest;
  e.amp = std::hypot(a, b) / att;
  e.phase = std::atan2(-b, a);
  const double S = 2.0 * t0 * best.level / best.w2;  // one-sided PSD of the noise at the line, (°/h)²/Hz
  e.amp_sigma = std::sqrt(S / T) / att;
  e.f_sigma = e.amp > 0 ? std::sqrt(6.0 * S / (e.amp * att * e.amp * att * T * T * T)) / (2.0 * kPi) : 0.0;
  return e;
}

// ---- bias step -------------------------------------------------------------------------------

namespace {

/// RSS of y ~ level + trend + Σ extra columns, by least squares; returns RSS and the coefficients.
double ls_rss(const std::vector<double>& y, const std::vector<std::vector<double>>& extra, Eigen::VectorXd* coef = nullptr,
              Eigen::MatrixXd* inv = nullptr) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const auto p = static_cast<Eigen::Index>(2 + extra.size());
  Eigen::MatrixXd X(n, p);
  Eigen::VectorXd Y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    X(i, 0) = 1.0;
    X(i, 1) = (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) / static_cast<double>(n);
    for (std::size_t c = 0; c < extra.size(); ++c) X(i, static_cast<Eigen::Index>(2 + c)) = extra[c][static_cast<std::size_t>(i)];
    Y(i) = y[static_cast<std::size_t>(i)];
  }
  const Eigen::MatrixXd XtX = X.transpose() * X;
  const Eigen::VectorXd b = XtX.ldlt().solve(X.transpose() * Y);
  if (coef) *coef = b;
  if (inv) *inv = XtX.inverse();
  return (Y - X * b).squaredNorm();
}

}  // namespace

StepEstimate step_detect(const Decimated& d) {
  StepEstimate e;
  const std::size_t pb = per_block_for(d, 10.0);
  const std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 40) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double sig = std::max(diff_sigma(y), 1e-12);
  std::vector<double> cs(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) cs[i + 1] = cs[i] + y[i];
  // Likelihood ratio of one change of the mean at block k against none (white noise of the
  // level σ̂ seen in the block-to-block differences): n/(k(n−k))·(S_k − k·ȳ)²/σ̂², maximised over k.
  double best = 0;
  std::size_t ibest = n / 2;
  const double ybar = cs[n] / static_cast<double>(n);
  for (std::size_t k = 3; k + 3 <= n; ++k) {
    const double dk = static_cast<double>(k), dn = static_cast<double>(n);
    const double u = cs[k] - dk * ybar;
    const double lr = dn / (dk * (dn - dk)) * u * u / (sig * sig);
    if (lr > best) {
      best = lr;
      ibest = k;
    }
  }
  const std::size_t wbest = std::min<std::size_t>({ibest, n - ibest, 180});
  e.statistic = best;
  // Refine the time on 1-s block means: the split minimising the two-level RSS in the window.
  const std::size_t pb1 = per_block_for(d, 1.0);
  const std::vector<double> y1 = block_rates(d, pb1);
  const double t1 = static_cast<double>(pb1) * d.tau_d;
  const std::size_t n1 = y1.size();
  std::vector<double> c1(n1 + 1, 0.0), c2(n1 + 1, 0.0);
  for (std::size_t i = 0; i < n1; ++i) {
    c1[i + 1] = c1[i] + y1[i];
    c2[i + 1] = c2[i] + y1[i] * y1[i];
  }
  const auto center = static_cast<std::size_t>(static_cast<double>(ibest) * tb / t1);
  const std::size_t W = std::max<std::size_t>(10, static_cast<std::size_t>(static_cast<double>(wbest) * tb / t1));
  const std::size_t search = static_cast<std::size_t>(2.0 * tb / t1) + 2;
  double rss_best = std::numeric_limits<double>::infinity();
  std::size_t split = center;
  auto seg_rss = [&](std::size_t a, std::size_t b) {
    const double s = c1[b] - c1[a], s2 = c2[b] - c2[a];
    return s2 - s * s / double(b - a);
  };
  std::vector<std::pair<std::size_t, double>> profile;
  for (std::size_t s = center > search ? center - search : 1; s <= std::min(n1 - 1, center + search); ++s) {
    const std::size_t a = s > W ? s - W : 0, b = std::min(n1, s + W);
    if (s - a < 2 || b - s < 2) continue;
    const double r = seg_rss(a, s) + seg_rss(s, b);
    profile.emplace_back(s, r);
    if (r < rss_best) {
      rss_best = r;
      split = s;
    }
  }
  const double ts = static_cast<double>(split) * t1;
  e.t_s = ts;
  // Size: the difference of the means over up to 30 min on each side.
  const auto Ws = static_cast<std::size_t>(std::min<double>(1800.0 / t1, static_cast<double>(n1)));
  const std::size_t a = split > Ws ? split - Ws : 0, b = std::min(n1, split + Ws);
  const double m1 = (c1[split] - c1[a]) / double(split - a), m2 = (c1[b] - c1[split]) / double(b - split);
  e.size = m2 - m1;
  const double sig1 = diff_sigma(y1);
  e.size_sigma = sig * std::sqrt(tb / (double(split - a) * t1) + tb / (double(b - split) * t1));
  // Time uncertainty: the range of splits whose RSS is within σ₁² (Δχ² = 1) of the best.
  double lo = ts, hi = ts;
  for (const auto& [s, r] : profile)
    if (r - rss_best <= sig1 * sig1) {
      lo = std::min(lo, static_cast<double>(s) * t1);
      hi = std::max(hi, static_cast<double>(s) * t1);
    }
  e.t_sigma = std::max(0.5 * (hi - lo), t1);
  // RSS of level + trend + step on the 10-s block means (for the comparison with a warm-up).
  std::vector<double> stepcol(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t0 = static_cast<double>(i) * tb, t2 = t0 + tb;
    stepcol[i] = std::clamp((t2 - ts) / tb, 0.0, 1.0);
  }
  e.rss = ls_rss(y, {stepcol});
  return e;
}

// ---- warm-up ---------------------------------------------------------------------------------

WarmupEstimate warmup_detect(const Decimated& d) {
  WarmupEstimate e;
  const std::size_t pb = per_block_for(d, 10.0);
  const std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 40) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double T = tb * static_cast<double>(n);
  const double sig = std::max(diff_sigma(y), 1e-12);
  const double rss0 = ls_rss(y, {});
  auto column = [&](double tc) {
    std::vector<double> c(n);
    const double f = tc / tb * -std::expm1(-tb / tc);  // block mean of exp(−t/tc) over [0, tb]
    for (std::size_t i = 0; i < n; ++i) c[i] = std::exp(-static_cast<double>(i) * tb / tc) * f;
    return c;
  };
  auto rss_at = [&](double tc) { return ls_rss(y, {column(tc)}); };
  const double lt_lo = std::log(2.0 * tb), lt_hi = std::log(T / 3.0);
  const int G = 40;
  double best = std::numeric_limits<double>::infinity(), lbest = lt_lo;
  std::vector<std::pair<double, double>> prof;
  for (int g = 0; g <= G; ++g) {
    const double lt = lt_lo + (lt_hi - lt_lo) * g / G;
    const double r = rss_at(std::exp(lt));
    prof.emplace_back(lt, r);
    if (r < best) {
      best = r;
      lbest = lt;
    }
  }
  const double step = (lt_hi - lt_lo) / G;
  double lo = lbest - step, hi = lbest + step;
  for (int it = 0; it < 25; ++it) {
    const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
    if (rss_at(std::exp(m1)) < rss_at(std::exp(m2)))
      hi = m2;
    else
      lo = m1;
  }
  lbest = 0.5 * (lo + hi);
  Eigen::VectorXd coef;
  Eigen::MatrixXd inv;
  e.tc = std::exp(lbest);
  e.rss = ls_rss(y, {column(e.tc)}, &coef, &inv);
  e.amp = coef(2);
  e.amp_sigma = sig * std::sqrt(inv(2, 2));
  // F-type statistic: the residual variance, not the white level, normalises the drop, so that
  // wander the base fit took up into K or R does not hide the transient.
  e.statistic = std::max(0.0, (rss0 - e.rss) / (e.rss / static_cast<double>(n - 4)));
  // Time-constant range: Δ RSS/σ̂² ≤ 1 on a fine profile around the optimum.
  double tl = e.tc, th = e.tc;
  for (int g = -40; g <= 40; ++g) {
    const double lt = lbest + g * 0.025;
    if (lt < lt_lo - 1 || lt > lt_hi + 1) continue;
    if ((rss_at(std::exp(lt)) - e.rss) / (sig * sig) <= 1.0) {
      tl = std::min(tl, std::exp(lt));
      th = std::max(th, std::exp(lt));
    }
  }
  e.tc_sigma = std::max(0.5 * (th - tl), 0.0);
  return e;
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

void subtract_deterministic(Decimated& d, const NoiseModel& m, double t0) {
  if (m.sinusoids.empty() && m.bias_steps.empty() && m.warmups.empty()) return;
  const double a0 = deterministic_angle(m, t0);
  for (std::size_t j = 0; j < d.theta.size(); ++j)
    d.theta[j] -= deterministic_angle(m, t0 + static_cast<double>(j) * d.tau_d) - a0;
}

namespace {

NoiseModel mean_shape_candidate(const Decimated& d) {
  NoiseModel c;
  const auto st = step_detect(d);
  const auto w = warmup_detect(d);
  if (st.rss <= w.rss)
    c.bias_steps.push_back({st.t_s, st.size});
  else
    c.warmups.push_back({w.amp, w.tc});
  return c;
}

}  // namespace

Decimated without_mean_shape(const Decimated& d) {
  Decimated c = d;
  subtract_deterministic(c, mean_shape_candidate(d));
  return c;
}

NoiseModel own_candidates(const Decimated& d) { return mean_shape_candidate(d); }

Decimated without_own_candidates(const Decimated& d) {
  Decimated c = d;
  subtract_deterministic(c, own_candidates(d));
  return c;
}

// ---- mid-τ shapes ----------------------------------------------------------------------------

double shape_avar(Shape s, double tau, double time) {
  const double x = tau / time;
  // (T/(2τ))(3 − 4e^{−x} + e^{−2x}), with a series for small x.
  double h;
  if (x < 1e-3)
    h = 1.0 - x * x / 3.0;
  else
    h = (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x);
  if (s == Shape::GaussMarkov) {
    // σ² = 1: AVAR = (2T/τ)[1 − h]
    return 2.0 / x * (1.0 - h);
  }
  // Low-pass of a unit white rate: the AV removed is (1/τ)·h.
  return -h / tau;
}

namespace {

struct WlsOut {
  double chi2 = 0;
  Eigen::VectorXd coef;
  Eigen::MatrixXd inv;
};

WlsOut wls(const std::vector<double>& y, const std::vector<double>& w, const std::vector<std::vector<double>>& cols) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const auto p = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd X(n, p);
  Eigen::VectorXd Y(n), W(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index c = 0; c < p; ++c) X(i, c) = cols[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)];
    Y(i) = y[static_cast<std::size_t>(i)];
    W(i) = w[static_cast<std::size_t>(i)];
  }
  const Eigen::MatrixXd XtW = X.transpose() * W.asDiagonal();
  const Eigen::MatrixXd A = XtW * X;
  WlsOut o;
  o.inv = A.completeOrthogonalDecomposition().pseudoInverse();
  o.coef = o.inv * (XtW * Y);
  const Eigen::VectorXd r = Y - X * o.coef;
  o.chi2 = (r.array().square() * W.array()).sum();
  return o;
}

}  // namespace

namespace {

/// The measured-minus-reference mid-τ AV, its weights (1/ensemble variance) and the Q, N, B, K
/// basis columns (normalised; `colscale` holds the factors).
struct MidTauProblem {
  std::vector<double> y, w, tau;
  std::vector<std::size_t> index;  ///< grid index of each point
  std::vector<std::vector<double>> cols{4};
  std::array<double, 4> colscale{1, 1, 1, 1};
};

MidTauProblem mid_tau_problem(const std::vector<double>& v, const MidTauReference& ref) {
  MidTauProblem p;
  for (std::size_t i = 0; i < ref.tau.size() && i < v.size(); ++i) {
    if (!(ref.var[i] > 0) || !(v[i] > 0)) continue;
    const double t = ref.tau[i];
    p.index.push_back(i);
    p.y.push_back(v[i] - ref.mean[i]);
    p.w.push_back(1.0 / ref.var[i]);
    p.tau.push_back(t);
    p.cols[0].push_back(3.0 / (t * t));
    p.cols[1].push_back(1.0 / t);
    p.cols[2].push_back(2.0 * std::log(2.0) / kPi);
    p.cols[3].push_back(t / 3.0);
  }
  for (std::size_t c = 0; c < 4; ++c) {
    double m = 0;
    for (double x : p.cols[c]) m = std::max(m, std::abs(x));
    p.colscale[c] = m > 0 ? m : 1.0;
    for (double& x : p.cols[c]) x /= p.colscale[c];
  }
  return p;
}

/// The problem decorrelated with the reference's correlation matrix: with C = D^½ R D^½ (D the
/// variances) = L·Lᵀ, y and every column are replaced by L⁻¹y, L⁻¹x and the weights by 1, so that
/// least squares minimise the generalised χ². Without a correlation matrix: unchanged.
struct Whitener {
  Eigen::MatrixXd L;
  bool on = false;
  std::vector<double> apply(const std::vector<double>& x) const {
    if (!on) return x;
    Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    Eigen::VectorXd u = L.triangularView<Eigen::Lower>().solve(v);
    return std::vector<double>(u.data(), u.data() + u.size());
  }
};

Whitener whiten(MidTauProblem& p, const MidTauReference& ref) {
  Whitener wh;
  const std::size_t g = ref.grid.size();
  const std::size_t n = p.y.size();
  if (ref.cov.size() != g * g || n < 2) return wh;
  // Correlations shrunk toward the identity: the runs are fewer than the grid points.
  const double shrink = kCorrShrink;
  Eigen::MatrixXd C(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const std::size_t ia = p.index[a], ib = p.index[b];
      const double d = std::sqrt(ref.var[ia] * ref.var[ib]);
      double rho = a == b ? 1.0 : (d > 0 ? std::clamp(ref.cov[ia * g + ib] / d, -1.0, 1.0) * (1.0 - shrink) : 0.0);
      C(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = rho / std::sqrt(p.w[a] * p.w[b]);
    }
  Eigen::LLT<Eigen::MatrixXd> llt(C);
  if (llt.info() != Eigen::Success) return wh;
  wh.L = llt.matrixL();
  wh.on = true;
  p.y = wh.apply(p.y);
  for (auto& c : p.cols) c = wh.apply(c);
  std::fill(p.w.begin(), p.w.end(), 1.0);
  return wh;
}

}  // namespace

namespace {

/// Weighted least squares of the mid-τ problem with the corrections of N², B², K² constrained so
/// that the corrected coefficients c_base + Δc stay ≥ 0 (active set: a correction that would make
/// its coefficient negative is held at −c_base and the rest re-fitted). `shape` (optional) is a
/// further, unconstrained column. Q² is free (the read-out is simulated, not fitted).
struct ConstrainedFit {
  double chi2 = 0;
  std::array<double, 4> dc{0, 0, 0, 0};
  double a = 0, a_var = 0;  ///< shape coefficient (column as given) and its variance
  double dn_var = 0;        ///< variance of ΔN² when N is free, fit scale²
};

ConstrainedFit constrained_fit(const MidTauProblem& p, const std::array<double, 4>& c_base,
                               const std::vector<double>* shape, std::array<bool, 4> free = {true, true, true, true}) {
  ConstrainedFit f;
  std::array<bool, 4> fixed{false, false, false, false};
  for (int iter = 0; iter < 4; ++iter) {
    std::vector<double> y = p.y;
    std::vector<std::vector<double>> cols;
    std::vector<std::size_t> idx;
    for (std::size_t t = 0; t < 4; ++t) {
      if (!free[t]) continue;  // held at the reference's value: no correction
      if (fixed[t]) {
        for (std::size_t i = 0; i < y.size(); ++i) y[i] += c_base[t] * p.cols[t][i] * p.colscale[t];
      } else {
        cols.push_back(p.cols[t]);
        idx.push_back(t);
      }
    }
    if (shape) cols.push_back(*shape);
    const WlsOut o = wls(y, p.w, cols);
    f.chi2 = o.chi2;
    for (std::size_t t = 0; t < 4; ++t) f.dc[t] = fixed[t] && free[t] ? -c_base[t] : 0.0;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      f.dc[idx[k]] = o.coef(static_cast<Eigen::Index>(k)) / p.colscale[idx[k]];
      if (idx[k] == 1) f.dn_var = o.inv(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)) /
                                  (p.colscale[1] * p.colscale[1]);
    }
    if (shape) {
      const auto last = static_cast<Eigen::Index>(idx.size());
      f.a = o.coef(last);
      f.a_var = o.inv(last, last);
    }
    // The most negative constrained coefficient, if any, goes to its bound.
    std::size_t worst = 4;
    double worst_v = 0;
    for (std::size_t t = 1; t < 4; ++t) {
      if (fixed[t] || !free[t]) continue;
      const double total = c_base[t] + f.dc[t];
      const double rel = total / std::max(std::abs(c_base[t]) + std::abs(f.dc[t]), 1e-300);
      if (total < 0 && rel < worst_v) {
        worst_v = rel;
        worst = t;
      }
    }
    if (worst == 4) break;
    fixed[worst] = true;
  }
  return f;
}

}  // namespace

std::array<double, 4> power_law_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                            const std::array<double, 4>& c_base) {
  std::array<double, 4> dc{0, 0, 0, 0};
  const MidTauProblem p = mid_tau_problem(v, ref);
  if (p.y.size() < 6) return dc;
  return constrained_fit(p, c_base, nullptr).dc;
}

std::array<double, 4> calibration_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                              const std::array<double, 4>& c_base, double tau_max, bool n_free) {
  std::array<double, 4> dc{0, 0, 0, 0};
  std::vector<double> w = v;
  for (std::size_t i = 0; i < w.size() && i < ref.tau.size(); ++i)
    if (ref.tau[i] > tau_max) w[i] = 0.0;  // left out of the problem
  const MidTauProblem p = mid_tau_problem(w, ref);
  if (p.y.size() < 6) return dc;
  return constrained_fit(p, c_base, nullptr, {true, n_free, true, false}).dc;
}

ShapeEstimate shape_detect(const std::vector<double>& v, const MidTauReference& ref,
                           const std::array<double, 4>& c_base, double fixed_time) {
  ShapeEstimate e;
  const MidTauProblem p0 = mid_tau_problem(v, ref);
  if (p0.y.size() < 8) return e;
  MidTauProblem p = p0;
  const Whitener wh = whiten(p, ref);
  const double c_n_base = c_base[1];
  using Fit = ConstrainedFit;
  auto fit = [&](const std::vector<double>* shape) { return constrained_fit(p, c_base, shape); };
  const Fit null = fit(nullptr);
  // Correlation times from 3× the shortest τ (a bump peaking at the grid's first points is white
  // rate noise there: not identifiable) to half the longest; a given one (fixed_time > 0) alone.
  const double lt_lo = std::log(3.0 * p.tau.front()), lt_hi = std::log(p.tau.back() / 2.0);
  const int G = fixed_time > 0 ? 0 : 48;
  double best_chi2 = null.chi2;
  std::vector<std::pair<double, double>> prof;
  Fit best;
  bool have = false;
  for (int g = 0; g <= G; ++g) {
    const double T = G > 0 ? std::exp(lt_lo + (lt_hi - lt_lo) * g / G) : fixed_time;
    std::vector<double> col(p.tau.size());
    double m = 0;
    for (std::size_t i = 0; i < p.tau.size(); ++i) {
      col[i] = shape_avar(Shape::GaussMarkov, p.tau[i], T);
      m = std::max(m, std::abs(col[i]));
    }
    if (!(m > 0)) continue;
    for (double& x : col) x /= m;
    col = wh.apply(col);
    Fit f = fit(&col);
    double chi2 = f.a > 0 ? f.chi2 : null.chi2;  // the bump only adds variance
    prof.emplace_back(T, chi2);
    if (chi2 < best_chi2) {
      best_chi2 = chi2;
      best = f;
      e.time = T;
      e.scale = f.a / m;
      e.scale_sigma = std::sqrt(std::max(0.0, f.a_var)) / m;
      have = true;
    }
  }
  e.statistic = std::max(0.0, null.chi2 - best_chi2);
  e.dc = null.dc;
  if (!have) return e;
  e.dc = best.dc;
  for (std::size_t i = 0; i < p0.tau.size(); ++i) {
    double net = e.scale * shape_avar(Shape::GaussMarkov, p0.tau[i], e.time);
    for (std::size_t t = 0; t < 4; ++t) net += best.dc[t] * p0.cols[t][i] * p0.colscale[t];
    e.excess = std::max(e.excess, net * std::sqrt(p0.w[i]));
  }
  {
    const double tp = 1.8926 * e.time;
    std::size_t k = 0;
    for (std::size_t i = 1; i < p0.tau.size(); ++i)
      if (std::abs(std::log(p0.tau[i] / tp)) < std::abs(std::log(p0.tau[k] / tp))) k = i;
    const double m = ref.mean[p0.index[k]];
    e.peak_ratio = m > 0 ? e.scale * shape_avar(Shape::GaussMarkov, tp, e.time) / m : 0.0;
  }
  e.white_rest = std::max(0.0, c_n_base + best.dc[1]);
  e.white_rest_sigma = std::sqrt(std::max(0.0, best.dn_var));
  e.time_low = e.time_high = e.time;
  for (const auto& [T, c] : prof)
    if (c - best_chi2 <= 1.0) {
      e.time_low = std::min(e.time_low, T);
      e.time_high = std::max(e.time_high, T);
    }
  return e;
}

MidTauReference leave_one_out(const MidTauReference& ref, const std::vector<double>& v, std::size_t runs) {
  MidTauReference r = ref;
  if (runs < 3) return r;
  const double K = static_cast<double>(runs);
  for (std::size_t i = 0; i < r.mean.size() && i < v.size(); ++i) {
    const double m = (K * ref.mean[i] - v[i]) / (K - 1);
    // Sum of squares about the old mean, without v.
    const double ss = ref.var[i] * (K - 1) - (v[i] - ref.mean[i]) * (v[i] - m);
    r.mean[i] = m;
    r.var[i] = std::max(ss / (K - 2), 1e-300);
  }
  // Covariance without the run: S' = S − K/(K − 1)·(v − m)(v − m)ᵀ.
  const std::size_t g = ref.mean.size();
  if (ref.cov.size() == g * g && v.size() >= g) {
    for (std::size_t i = 0; i < g; ++i)
      for (std::size_t j = 0; j < g; ++j) {
        const double s = ref.cov[i * g + j] * (K - 1) - K / (K - 1) * (v[i] - ref.mean[i]) * (v[j] - ref.mean[j]);
        r.cov[i * g + j] = s / (K - 2);
      }
  } else {
    r.cov.clear();
  }
  return r;
}

// ---- output-chain low-pass ---------------------------------------------------------------------

double output_lowpass_angle_avar(std::size_t m, double tau0, double tf) {
  const double tau = static_cast<double>(m) * tau0;
  if (!(tf > 0)) return 3.0 / (tau * tau);
  const double x = tau0 / tf;
  const double one_m_phi = -std::expm1(-x);
  const double phi_m = std::exp(-static_cast<double>(m) * x);
  const double v = one_m_phi / (2.0 - one_m_phi);  // (1 − φ)/(1 + φ)
  return v * (3.0 - 4.0 * phi_m + phi_m * phi_m) / (tau * tau);
}

double output_lowpass_rate_avar(std::size_t m, double tau0, double tf) {
  const double md = static_cast<double>(m);
  if (!(tf > 0)) return 1.0 / (md * tau0);
  // Rate samples of variance 1/τ0 through the AR(1) filter: variance V, autocorrelation φ^k.
  // AV = (Var of an m-sum − Cov of adjacent m-sums)/m².
  const double x = tau0 / tf;
  const double a = -std::expm1(-x);                 // 1 − φ
  const double phi = 1.0 - a;
  const double b = -std::expm1(-md * x);            // 1 − φ^m
  const double V = (1.0 / tau0) * a / (2.0 - a);
  const double var_sum = V * (md + 2.0 * phi * (md * a - b) / (a * a));
  const double cov = V * phi * b * b / (a * a);
  return (var_sum - cov) / (md * md);
}

namespace {

/// Non-negative weighted least squares of y on up to three columns (all subsets; small p).
struct NnFit {
  double chi2 = std::numeric_limits<double>::infinity();
  std::array<double, 3> c{0, 0, 0};
};

NnFit nn_fit3(const std::vector<double>& y, const std::vector<double>& w, const std::array<std::vector<double>, 3>& cols) {
  NnFit best;
  for (int mask = 1; mask < 8; ++mask) {
    std::vector<std::vector<double>> cs;
    std::vector<int> idx;
    for (int c = 0; c < 3; ++c)
      if (mask & (1 << c)) {
        cs.push_back(cols[static_cast<std::size_t>(c)]);
        idx.push_back(c);
      }
    const WlsOut o = wls(y, w, cs);
    bool ok = true;
    for (Eigen::Index k = 0; k < o.coef.size(); ++k) ok = ok && o.coef(k) >= 0 && std::isfinite(o.coef(k));
    if (!ok || !(o.chi2 < best.chi2)) continue;
    best.chi2 = o.chi2;
    best.c = {0, 0, 0};
    for (std::size_t k = 0; k < idx.size(); ++k) best.c[static_cast<std::size_t>(idx[k])] = o.coef(static_cast<Eigen::Index>(k));
  }
  if (!std::isfinite(best.chi2)) {
    best.chi2 = 0;
    for (std::size_t i = 0; i < y.size(); ++i) best.chi2 += w[i] * y[i] * y[i];
  }
  return best;
}

}  // namespace

OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration) {
  OutputLowpassEstimate e;
  const double tau_cut = std::min(20.0, duration / 100.0);
  std::vector<std::size_t> mm;
  std::vector<double> y, w;
  for (std::size_t i = 0; i < m.size() && i < v.size() && i < edf.size(); ++i) {
    const double tau = static_cast<double>(m[i]) * tau0;
    if (tau > tau_cut || !(v[i] > 0) || !(edf[i] > 0)) continue;
    mm.push_back(static_cast<std::size_t>(m[i]));
    y.push_back(v[i]);
    w.push_back(edf[i] / (2.0 * v[i] * v[i]));
  }
  e.points = static_cast<double>(y.size());
  if (y.size() < 5) return e;
  // Columns scaled to unit maximum for the conditioning of the normal equations.
  auto fit_at = [&](double tf, std::array<double, 2>* scale) {
    std::array<std::vector<double>, 3> cols;
    for (auto& c : cols) c.resize(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) {
      cols[0][i] = output_lowpass_angle_avar(mm[i], tau0, tf);
      cols[1][i] = output_lowpass_rate_avar(mm[i], tau0, tf);
      cols[2][i] = 1.0;
    }
    std::array<double, 3> sc{1, 1, 1};
    for (std::size_t c = 0; c < 2; ++c) {
      sc[c] = *std::max_element(cols[c].begin(), cols[c].end());
      for (double& x : cols[c]) x /= sc[c];
    }
    NnFit f = nn_fit3(y, w, cols);
    if (scale) *scale = {f.c[0] / sc[0], f.c[1] / sc[1]};
    return f.chi2;
  };
  const double chi0 = fit_at(0.0, nullptr);
  const double lo = std::log(tau0 / 4.0), hi = std::log(std::max(tau_cut / 4.0, tau0));
  const int G = 80;
  std::vector<std::pair<double, double>> prof;
  double best = chi0;
  // χ² at tf; the best so far (tf and the white scales of its fit) kept in e.
  const auto consider = [&](double tf) {
    std::array<double, 2> sc{0, 0};
    const double c = fit_at(tf, &sc);
    if (c < best) {
      best = c;
      e.tf = tf;
      e.white_angle2 = sc[0];
      e.white_rate = sc[1];
    }
    return c;
  };
  for (int g = 0; g <= G; ++g) {
    const double tf = std::exp(lo + (hi - lo) * g / G);
    prof.emplace_back(tf, consider(tf));
  }
  e.statistic = std::max(0.0, chi0 - best);
  if (!(e.tf > 0)) return e;
  // Golden-section refinement of tf in log between the grid neighbours.
  {
    double a = std::log(e.tf) - (hi - lo) / G, b = std::log(e.tf) + (hi - lo) / G;
    const double gr = (std::sqrt(5.0) - 1.0) / 2.0;
    double c1 = b - gr * (b - a), c2 = a + gr * (b - a);
    double f1 = fit_at(std::exp(c1), nullptr), f2 = fit_at(std::exp(c2), nullptr);
    for (int it = 0; it < 30; ++it) {
      if (f1 < f2) {
        b = c2; c2 = c1; f2 = f1; c1 = b - gr * (b - a); f1 = fit_at(std::exp(c1), nullptr);
      } else {
        a = c1; c1 = c2; f1 = f2; c2 = a + gr * (b - a); f2 = fit_at(std::exp(c2), nullptr);
      }
    }
    consider(std::exp(0.5 * (a + b)));
    e.statistic = std::max(0.0, chi0 - best);
  }
  e.chi2 = best;
  // Δχ² range, widened by the misfit per degree of freedom when the shape does not fit exactly.
  const double dof = std::max(1.0, e.points - 4.0);
  const double delta = std::max(1.0, best / dof);
  e.tf_low = e.tf_high = e.tf;
  // Curvature of χ² in ln tf at the optimum (steps of 2 %), else the grid profile.
  const double h = 0.02;
  const double fp = fit_at(e.tf * std::exp(h), nullptr), fm = fit_at(e.tf * std::exp(-h), nullptr);
  const double curv = (fp - 2.0 * best + fm) / (h * h);
  if (curv > 0) {
    const double su = std::sqrt(2.0 * delta / curv);
    e.tf_low = e.tf * std::exp(-su);
    e.tf_high = e.tf * std::exp(su);
  } else {
    for (const auto& [tf, c] : prof)
      if (c - best <= delta) {
        e.tf_low = std::min(e.tf_low, tf);
        e.tf_high = std::max(e.tf_high, tf);
      }
  }
  return e;
}

// ---- calibration ------------------------------------------------------------------------------

double quantile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  if (i + 1 >= v.size()) return v.back();
  return v[i] * (1 - f) + v[i + 1] * f;
}

double gumbel_threshold(const std::vector<double>& values, double alpha) {
  if (values.empty()) return std::numeric_limits<double>::infinity();
  double mean = 0, mx = values.front();
  for (double x : values) {
    mean += x;
    mx = std::max(mx, x);
  }
  mean /= static_cast<double>(values.size());
  double var = 0;
  for (double x : values) var += (x - mean) * (x - mean);
  var /= std::max<double>(1.0, static_cast<double>(values.size()) - 1.0);
  const double beta = std::sqrt(var) * std::sqrt(6.0) / kPi;
  const double u = mean - 0.5772156649 * beta;
  const double q = u - beta * std::log(-std::log(1.0 - alpha));
  return std::max(q, mx);
}

}  // namespace rwcalc::diag
