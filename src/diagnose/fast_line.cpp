// The periodogram line search (fast_line.hpp).
#include "fast_line.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include <boost/math/special_functions/beta.hpp>

#include "signal.hpp"

namespace rwcalc::diag {

namespace {

/// P(ratio > u) for one bin: a mean of K exponentials over a level that is a mean of K·W, an
/// F(2K, 2KW) ratio; (1 + u/W)^{−W} for K = 1.
double bin_tail(double u, double K) {
  const double W = kLevelBins;
  return boost::math::ibeta(K * W, K, W / (W + u));
}

/// The least-squares line a·cos 2πft + b·sin 2πft in y[0 … n) (sample k the mean over
/// [t0 + k·dt, t0 + (k+1)·dt), t0 from the record's start) and its explained sum of squares (the
/// 2×2 normal equations, the phase stepped by rotation).
double line_fit(const double* y, std::size_t n, double dt, double t0, double f, double& a, double& b) {
  const std::complex<double> step = std::polar(1.0, 2.0 * kPi * f * dt);
  std::complex<double> e = std::polar(1.0, 2.0 * kPi * f * (t0 + 0.5 * dt));
  double cc = 0, ss = 0, cs = 0, yc = 0, ys = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double c = e.real(), s = e.imag(), v = y[k];
    cc += c * c, ss += s * s, cs += c * s, yc += v * c, ys += v * s;
    e *= step;
  }
  const double det = cc * ss - cs * cs;
  if (!(det > 0)) return a = b = 0, 0.0;
  a = (ss * yc - cs * ys) / det;
  b = (cc * ys - cs * yc) / det;
  return a * yc + b * ys;
}

double line_fit(const std::vector<double>& y, double dt, double f, double& a, double& b) {
  return line_fit(y.data(), y.size(), dt, 0.0, f, a, b);
}

}  // namespace

FastLine fast_line_search(std::vector<double> y, double dt, double f_min, double f_max, double alpha) {
  FastLine r;
  const std::size_t n = y.size();
  double mean = 0;
  for (const double v : y) mean += v / static_cast<double>(n);
  for (double& v : y) v -= mean;
  // Segments of at most kSegment samples (the memory stays bounded), their periodograms averaged.
  const std::size_t len = std::min(n, kSegment), segs = n / len;
  std::size_t nfft = 4;
  while (nfft < 2 * len) nfft <<= 1;
  const double pad = static_cast<double>(nfft) / static_cast<double>(len), df = 1.0 / (static_cast<double>(nfft) * dt);
  const auto stride = static_cast<std::size_t>(std::lround(2 * pad));  // every second true bin
  const std::size_t reach = (kLevelBins / 2 + 1) * stride, half = nfft / 2;
  std::size_t k_lo = std::max<std::size_t>(static_cast<std::size_t>(std::ceil(f_min / df)), 2 * stride);
  const std::size_t k_hi = std::min(static_cast<std::size_t>(f_max / df), half - 2 * stride);
  if (k_lo >= k_hi || (2 * static_cast<std::size_t>(kLevelBins) + 2) * stride >= half) return r;
  const std::vector<double> P = hann_periodogram(y, len, nfft);
  // C[k] = P[k] + C[k − stride]: the sum of P[a], P[a + stride], …, P[b] in O(1).
  std::vector<double> C(P);
  for (std::size_t k = stride; k < C.size(); ++k) C[k] += C[k - stride];
  const auto run = [&](std::size_t a, std::size_t b) { return C[b] - (a >= stride ? C[a - stride] : 0.0); };
  const std::size_t W = kLevelBins / 2;
  double best = 0, best_level = 0;
  std::size_t kbest = k_lo;
  for (std::size_t k = k_lo; k <= k_hi; ++k) {
    // W values on each side, 2 … W + 1 strides away; near an end, 2W on the other side.
    double s;
    if (k < reach)
      s = run(k + 2 * stride, k + (2 * W + 1) * stride);
    else if (k + reach > half)
      s = run(k - (2 * W + 1) * stride, k - 2 * stride);
    else
      s = run(k - (W + 1) * stride, k - 2 * stride) + run(k + 2 * stride, k + (W + 1) * stride);
    const double level = s / static_cast<double>(kLevelBins);
    if (level > 0 && P[k] / level > best) best = P[k] / level, best_level = level, kbest = k;
  }
  const double bins = static_cast<double>(k_hi - k_lo + 1);
  r.statistic = best;
  const double K = static_cast<double>(segs);
  r.p = std::min(1.0, bins * bin_tail(best, K));
  double lo = 0, hi = 1e4;
  for (int it = 0; it < 100; ++it) (bins * bin_tail(0.5 * (lo + hi), K) > alpha ? lo : hi) = 0.5 * (lo + hi);
  r.threshold = hi;
  r.test = fmt::format(
      "largest Hann periodogram ordinate of the rate samples ({:.4g}–{:.4g} Hz, mean of {} segments) over the "
      "mean of {} others 4–{} bins away; null law: F(2K, 2KW) per bin, Bonferroni over {:.0f} bins",
      f_min, f_max, segs, kLevelBins, kLevelBins + 2, bins);
  // The frequency refined by least squares between the neighbouring bins.
  double a = 0, b = 0;
  const auto fit = [&](double f, double& ca, double& cb) { return line_fit(y, dt, f, ca, cb); };
  r.f_hz = refine_frequency(fit, static_cast<double>(kbest) * df, df, 1, 30, 0.5 / dt);
  const double ess = fit(r.f_hz, a, b);
  r.amp = std::hypot(a, b) / block_attenuation(r.f_hz, dt);  // a sample is the mean over dt
  r.phase = std::atan2(-b, a);
  // Standard errors of a line in noise of the local level (per-sample variance σ² at f).
  const double nn = static_cast<double>(n);
  r.amp_sigma = std::sqrt(2.0 * best_level / nn);
  r.level = best_level;
  r.lr = best_level > 0 ? ess / best_level : 0.0;
  r.f_sigma = r.amp > 0 ? std::sqrt(24.0 * best_level / (r.amp * r.amp * nn * nn * nn)) / (2.0 * kPi * dt) : 0.0;
  return r;
}

double fast_line_holdout(const std::vector<double>& y, double dt, const FastLine& l) {
  const std::size_t n = y.size() / 2;
  if (n < 16 || !(l.level > 0)) return 0.0;
  // Each half less its own mean (a nuisance), and its first sample's time.
  std::vector<double> half[2] = {{y.begin(), y.begin() + static_cast<std::ptrdiff_t>(n)},
                                 {y.begin() + static_cast<std::ptrdiff_t>(n), y.end()}};
  const double t0[2] = {0.0, static_cast<double>(n) * dt};
  for (auto& h : half) {
    double mean = 0;
    for (const double v : h) mean += v / static_cast<double>(h.size());
    for (double& v : h) v -= mean;
  }
  double gain = 0;
  for (int train = 0; train < 2; ++train) {
    const auto& fit_y = half[train];
    auto fit = [&](double f, double& ca, double& cb) {
      return line_fit(fit_y.data(), fit_y.size(), dt, t0[train], f, ca, cb);
    };
    // Within the half's resolution of the record's frequency: the half's own estimate.
    const double step = 0.5 / (static_cast<double>(fit_y.size()) * dt);
    const double f = refine_frequency(fit, l.f_hz, step, 1, 30, 0.5 / dt);
    double a = 0, b = 0;
    fit(f, a, b);
    const auto& test = half[1 - train];
    std::vector<double> rest(test);
    const std::complex<double> rot = std::polar(1.0, 2.0 * kPi * f * dt);
    std::complex<double> e = std::polar(1.0, 2.0 * kPi * f * (t0[1 - train] + 0.5 * dt));
    for (double& v : rest) {
      v -= a * e.real() + b * e.imag();
      e *= rot;
    }
    double ca = 0, cb = 0;
    const double before = line_fit(test.data(), test.size(), dt, t0[1 - train], f, ca, cb);
    const double after = line_fit(rest.data(), rest.size(), dt, t0[1 - train], f, ca, cb);
    gain += (before - after) / l.level;
  }
  return gain;
}

}  // namespace rwcalc::diag
