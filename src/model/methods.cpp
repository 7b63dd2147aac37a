// The paper's cross-checks: direct N from angle variances, spread of 100-s mean rates.
#include "rwcalc/methods.hpp"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numbers>

namespace rwcalc {

namespace {

constexpr double kZ95 = 1.959963984540054;

struct LineFit {
  double a = 0;
  double b = 0;
  bool ok = false;
};

/// Sample variance (divisor n − 1) of `v`, n ≥ 2.
double sample_variance(const std::vector<double>& v) {
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return ss / static_cast<double>(v.size() - 1);
}

/// Weighted regression s²(t) = a + b t with model-based weights (n − 1)/(a + b t)², iterated.
LineFit fit_line(const std::vector<DirectPoint>& pts) {
  LineFit f;
  std::vector<double> w(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    w[i] = static_cast<double>(pts[i].intervals - 1) / (pts[i].var_arcsec2 * pts[i].var_arcsec2 + 1e-300);
  for (int it = 0; it < 4; ++it) {
    double s0 = 0, s1 = 0, s2 = 0, sy = 0, sty = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double t = pts[i].t_s;
      s0 += w[i];
      s1 += w[i] * t;
      s2 += w[i] * t * t;
      sy += w[i] * pts[i].var_arcsec2;
      sty += w[i] * t * pts[i].var_arcsec2;
    }
    const double det = s0 * s2 - s1 * s1;
    if (!(det > 0)) return f;
    f.b = (s0 * sty - s1 * sy) / det;
    f.a = (sy - f.b * s1) / s0;
    f.ok = std::isfinite(f.a) && std::isfinite(f.b);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double m = f.a + f.b * pts[i].t_s;
      const double v = m > 0 ? m : pts[i].var_arcsec2;
      w[i] = static_cast<double>(pts[i].intervals - 1) / (v * v + 1e-300);
    }
  }
  return f;
}

/// Direct-method points on x[begin … end] (phase indices) for cluster sizes ms.
std::vector<DirectPoint> direct_points(const PhaseSeries& x, std::size_t begin, std::size_t end,
                                       const std::vector<std::size_t>& ms) {
  std::vector<DirectPoint> pts;
  const std::size_t len = end - begin;  // number of sample intervals
  for (std::size_t m : ms) {
    const std::size_t k = len / m;
    if (k < 10) continue;
    // The variance about the mean increment (Earth rate + bias).
    std::vector<double> d(k);
    for (std::size_t j = 0; j < k; ++j) d[j] = x.diff(begin + (j + 1) * m, begin + j * m);
    pts.push_back({static_cast<double>(m) * x.tau0_s, k, sample_variance(d)});
  }
  return pts;
}

void lognormal_bounds(MethodEstimate& e) {
  if (e.value > 0 && e.sigma > 0) {
    const double s = e.sigma / e.value;
    e.low = e.value * std::exp(-kZ95 * s);
    e.high = e.value * std::exp(kZ95 * s);
  } else {
    e.low = e.high = e.value;
  }
}

}  // namespace

DirectNResult direct_n(const PhaseSeries& x, const MethodOptions& o) {
  DirectNResult r;
  const std::size_t n = x.points() > 0 ? x.points() - 1 : 0;
  const double t_total = static_cast<double>(n) * x.tau0_s;
  const double t_max = std::min(o.direct_t_max_s, t_total / 50.0);
  const double t_min = std::max(o.direct_t_min_s, x.tau0_s);
  if (n < 20 || !(t_max > t_min)) return r;
  std::vector<std::size_t> ms;
  for (int i = 0; i < o.direct_points; ++i) {
    const double t = t_min * std::pow(t_max / t_min, o.direct_points > 1 ? double(i) / (o.direct_points - 1) : 0.0);
    // t ≤ t_max ≤ the record's length / 50: m fits the sample count.
    const auto m = static_cast<std::size_t>(std::max(1.0, std::round(std::min(t / x.tau0_s, static_cast<double>(n)))));
    if (ms.empty() || m != ms.back()) ms.push_back(m);
  }
  r.points = direct_points(x, 0, n, ms);
  if (r.points.size() < 3) return r;
  const LineFit full = fit_line(r.points);
  if (!full.ok) return r;
  r.intercept_arcsec2 = full.a;
  r.slope_arcsec2_per_s = full.b;

  // Standard error of the slope from contiguous segments (each analysed like the whole record,
  // with the same interval lengths; a segment keeps those with ≥ 10 intervals).
  std::vector<double> slopes;
  const int kseg = std::max(2, o.direct_segments);
  for (int s = 0; s < kseg; ++s) {
    const std::size_t b = n * static_cast<std::size_t>(s) / static_cast<std::size_t>(kseg);
    const std::size_t e = n * static_cast<std::size_t>(s + 1) / static_cast<std::size_t>(kseg);
    const auto pts = direct_points(x, b, e, ms);
    if (pts.size() < 3) continue;
    const LineFit f = fit_line(pts);
    if (f.ok) slopes.push_back(f.b);
  }
  r.segments_used = static_cast<int>(slopes.size());
  if (slopes.size() < 3) return r;
  const double se_b = std::sqrt(sample_variance(slopes) / static_cast<double>(slopes.size()));
  const double tq =
      boost::math::quantile(boost::math::students_t_distribution<double>(static_cast<double>(slopes.size() - 1)),
                            0.975);

  // b = N² in ″²/s = (°/h)²·s; N[°/√h] = √b / 60.
  auto& e = r.N;
  e.valid = true;
  if (full.b > 0) {
    e.value = std::sqrt(full.b) / 60.0;
    e.sigma = se_b / (2.0 * std::sqrt(full.b)) / 60.0;
    // Bounds of b by Student t, mapped through √ (b's low end may reach 0).
    const double lo = full.b - tq * se_b;
    const double hi = full.b + tq * se_b;
    e.low = lo > 0 ? std::sqrt(lo) / 60.0 : 0.0;
    e.high = std::sqrt(hi) / 60.0;
    e.resolved = lo > 0;
    if (!e.resolved) e.value = e.high;
  } else {
    e.resolved = false;
    const double hi = full.b + tq * se_b;
    e.high = hi > 0 ? std::sqrt(hi) / 60.0 : 0.0;
    e.value = e.high;
    e.sigma = e.high / (2.0 * kZ95);
  }
  return r;
}

BlockSpreadResult block_spread(const PhaseSeries& x, double block_s) {
  BlockSpreadResult r;
  const std::size_t n = x.points() > 0 ? x.points() - 1 : 0;
  // Samples per block, compared as a double before the conversion: a block longer than the
  // record (or NaN) has no whole block, and its count would not fit an integer.
  const double per_block = std::max(1.0, std::round(block_s / x.tau0_s));
  if (!(per_block <= static_cast<double>(n))) {
    r.block_s = std::isfinite(block_s) ? block_s : 0.0;
    return r;
  }
  const auto m = static_cast<std::size_t>(per_block);
  r.block_s = static_cast<double>(m) * x.tau0_s;
  const std::size_t k = n / m;
  r.blocks = k;
  if (k < 3) return r;
  std::vector<double> y(k);
  for (std::size_t j = 0; j < k; ++j) y[j] = x.diff((j + 1) * m, j * m) / r.block_s;
  auto& e = r.spread;
  e.valid = true;
  e.value = std::sqrt(sample_variance(y));
  e.sigma = e.value / std::sqrt(2.0 * static_cast<double>(k - 1));
  lognormal_bounds(e);
  return r;
}

double expected_block_variance(const Eigen::Matrix<double, kTermCount, 1>& c, double tau, std::size_t blocks) {
  if (blocks < 2) return 0;
  // Generalized structure function of the angle, ″², for each term (fit-scale c):
  //   Q: 2c (u > 0)   N: c·u   B: −(c/π)·u²·ln u   K: −c·u³/6   R: −c·u⁴/12
  auto s = [&](double u) {
    if (u <= 0) return 0.0;
    return 2.0 * c[0] + c[1] * u - c[2] / std::numbers::pi * u * u * std::log(u) - c[3] * u * u * u / 6.0 -
           c[4] * u * u * u * u / 12.0;
  };
  const auto mm = static_cast<double>(blocks);
  double sum = 0;
  for (std::size_t l = 1; l < blocks; ++l) {
    const double dl = static_cast<double>(l);
    const double d = (2.0 * s(tau) - s((dl + 1) * tau) - s((dl - 1) * tau) + 2.0 * s(dl * tau)) / (2.0 * tau * tau);
    sum += (mm - dl) * d;
  }
  return 2.0 * sum / (mm * (mm - 1.0));
}

void attach_expectation(BlockSpreadResult& r, const FitResult& fit) {
  if (!r.spread.valid) return;
  const double v = expected_block_variance(fit.c, r.block_s, r.blocks);
  if (!(v > 0)) return;
  r.expected = std::sqrt(v);
  // Linear in c: gradient by unit vectors.
  Eigen::Matrix<double, kTermCount, 1> h;
  for (int i = 0; i < kTermCount; ++i) {
    Eigen::Matrix<double, kTermCount, 1> e = Eigen::Matrix<double, kTermCount, 1>::Zero();
    e[i] = 1.0;
    h[i] = expected_block_variance(e, r.block_s, r.blocks);
  }
  const double var_v = h.dot(fit.cov_c * h);
  r.expected_sigma = var_v > 0 ? std::sqrt(var_v) / (2.0 * r.expected) : 0.0;
}

double discrepancy_sigma(double a, double sa, double b, double sb) {
  const double s = std::sqrt(sa * sa + sb * sb);
  return s > 0 ? (a - b) / s : 0.0;
}

}  // namespace rwcalc
