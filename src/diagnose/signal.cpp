// The decimated angle, its block rates and mid-τ AV, deterministic terms, least-squares and
// spectral helpers, and the ensemble quantiles.
#include "diagnose/signal.hpp"

#include <cmath>
#include <limits>

namespace rwcalc::diag {

double median_of(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double diff_sigma(const std::vector<double>& y) {
  if (y.size() < 3) return 0.0;
  double s = 0;
  for (std::size_t i = 0; i + 1 < y.size(); ++i) s += (y[i + 1] - y[i]) * (y[i + 1] - y[i]);
  return std::sqrt(s / static_cast<double>(y.size() - 1) / 2.0);
}

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

std::vector<std::size_t> mid_tau_grid(const Decimated& d) {
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
    // Four partial sums: the loop vectorizes (the ensembles spend much of their time here).
    double a[4] = {0, 0, 0, 0};
    std::size_t k = 0;
    for (; k + 4 <= terms; k += 4)
      for (std::size_t u = 0; u < 4; ++u) {
        const double e = th[k + u + 2 * m] - 2.0 * th[k + u + m] + th[k + u];
        a[u] += e * e;
      }
    for (; k < terms; ++k) {
      const double e = th[k + 2 * m] - 2.0 * th[k + m] + th[k];
      a[0] += e * e;
    }
    const double s = (a[0] + a[1]) + (a[2] + a[3]);
    const double tau = static_cast<double>(m) * d.tau_d;
    v[g] = s / (2.0 * tau * tau * static_cast<double>(terms));
  }
  return v;
}

void level_window(const std::vector<double>& P, std::size_t k, double pad, bool keep_size, std::vector<double>& v) {
  const std::size_t half = P.size() - 1;
  const auto W = static_cast<std::size_t>(24.0 * pad), gap = static_cast<std::size_t>(std::ceil(3.0 * pad));
  const auto stepb = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(pad)));
  std::size_t a = k > W ? k - W : 1, b = k + W;
  if (b > half) {
    if (keep_size) a = a > b - half ? a - (b - half) : 1;
    b = half;
  }
  v.clear();
  for (std::size_t j = a; j <= b; j += stepb)
    if (j + gap < k || j > k + gap) v.push_back(P[j]);
}

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

double ls_rss(const std::vector<double>& y, const std::vector<std::vector<double>>& extra, Eigen::VectorXd* coef,
              Eigen::MatrixXd* inv) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const auto p = static_cast<Eigen::Index>(2 + extra.size());
  Eigen::MatrixXd X(n, p);
  Eigen::VectorXd Y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    X(i, 0) = 1.0;
    X(i, 1) = (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) / static_cast<double>(n);
    for (std::size_t c = 0; c < extra.size(); ++c)
      X(i, static_cast<Eigen::Index>(2 + c)) = extra[c][static_cast<std::size_t>(i)];
    Y(i) = y[static_cast<std::size_t>(i)];
  }
  const Eigen::MatrixXd XtX = X.transpose() * X;
  const Eigen::VectorXd b = XtX.ldlt().solve(X.transpose() * Y);
  if (coef) *coef = b;
  if (inv) *inv = XtX.inverse();
  return (Y - X * b).squaredNorm();
}

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
  WlsOut o;
  if (p == 0) {  // nothing free (every term at its bound): the residuals are the data
    o.chi2 = (Y.array().square() * W.array()).sum();
    return o;
  }
  const Eigen::MatrixXd XtW = X.transpose() * W.asDiagonal();
  const Eigen::MatrixXd A = XtW * X;
  o.inv = A.completeOrthogonalDecomposition().pseudoInverse();
  o.coef = o.inv * (XtW * Y);
  const Eigen::VectorXd r = Y - X * o.coef;
  o.chi2 = (r.array().square() * W.array()).sum();
  return o;
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

double quantile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  if (i + 1 >= v.size()) return v.back();
  return v[i] * (1 - f) + v[i + 1] * f;
}

GumbelQuantile gumbel_quantile(const std::vector<double>& values, double alpha) {
  if (values.empty()) return {std::numeric_limits<double>::infinity(), 0.0};
  const double K = static_cast<double>(values.size());
  double mean = 0, mx = values.front();
  for (double x : values) {
    mean += x;
    mx = std::max(mx, x);
  }
  mean /= K;
  double var = 0;
  for (double x : values) var += (x - mean) * (x - mean);
  var /= std::max(1.0, K - 1.0);
  constexpr double kEuler = 0.5772156649;
  const double k = -std::sqrt(6.0) / kPi * (kEuler + std::log(-std::log(1.0 - alpha)));
  const double q = mean + k * std::sqrt(var);
  const double sigma = std::sqrt(var / K * (1.0 + 1.1396 * k + 1.1 * k * k));
  return {K * alpha < 1.0 ? std::max(q, mx) : q, sigma};
}

double gumbel_threshold(const std::vector<double>& values, double alpha) {
  return gumbel_quantile(values, alpha).value;
}

}  // namespace rwcalc::diag
