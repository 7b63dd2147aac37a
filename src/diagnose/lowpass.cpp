// The output-chain low-pass family (lowpass.hpp).
#include "lowpass.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "rwcalc/nnls.hpp"
#include "rwcalc/output_filter.hpp"
#include "signal.hpp"

namespace rwcalc::diag {

namespace {

/// Non-negative weighted least squares of y on three columns: χ² and the coefficients.
double nn_fit3(const std::vector<double>& y, const std::vector<double>& w,
               const std::array<std::vector<double>, 3>& cols, std::array<double, 3>& coef) {
  const auto n = static_cast<Eigen::Index>(y.size());
  Eigen::MatrixXd g(n, 3);
  for (Eigen::Index c = 0; c < 3; ++c)
    g.col(c) = Eigen::Map<const Eigen::VectorXd>(cols[static_cast<std::size_t>(c)].data(), n);
  const NnlsFit fit =
      nnls(g, Eigen::Map<const Eigen::VectorXd>(y.data(), n), Eigen::Map<const Eigen::VectorXd>(w.data(), n), 0b111);
  coef = {fit.x[0], fit.x[1], fit.x[2]};
  return fit.chi2;
}

/// The octave points the filter is fitted to: τ ≤ min(20 s, T/100), each weighted by its EDF.
struct ShortTau {
  std::vector<std::size_t> m;
  std::vector<double> y, w;
  double tau0 = 0, tau_cut = 0;
};

ShortTau short_tau(const std::vector<std::int64_t>& m, const std::vector<double>& v, const std::vector<double>& edf,
                   double tau0, double duration) {
  ShortTau p;
  p.tau0 = tau0;
  p.tau_cut = std::min(20.0, duration / 100.0);
  for (std::size_t i = 0; i < m.size() && i < v.size() && i < edf.size(); ++i) {
    const double tau = static_cast<double>(m[i]) * tau0;
    if (tau > p.tau_cut || !(v[i] > 0) || !(edf[i] > 0)) continue;
    p.m.push_back(static_cast<std::size_t>(m[i]));
    p.y.push_back(v[i]);
    p.w.push_back(edf[i] / (2.0 * v[i] * v[i]));
  }
  return p;
}

/// The model's columns at time constant tf (0: no filter): white angle, white rate, floor.
std::array<std::vector<double>, 3> columns(const ShortTau& p, double tf) {
  std::array<std::vector<double>, 3> cols;
  for (auto& c : cols) c.resize(p.y.size());
  for (std::size_t i = 0; i < p.y.size(); ++i) {
    cols[0][i] = output_lowpass_angle_avar(p.m[i], p.tau0, tf);
    cols[1][i] = output_lowpass_rate_avar(p.m[i], p.tau0, tf);
    cols[2][i] = 1.0;
  }
  return cols;
}

/// χ² of the non-negative fit at tf and its coefficients (columns scaled to unit maximum for the
/// normal equations, the coefficients returned in the columns' own units).
double fit_at(const ShortTau& p, double tf, std::array<double, 3>* coef) {
  auto cols = columns(p, tf);
  std::array<double, 3> sc{1, 1, 1}, c{};
  for (std::size_t k = 0; k < 2; ++k) {
    sc[k] = *std::max_element(cols[k].begin(), cols[k].end());
    for (double& x : cols[k]) x /= sc[k];
  }
  const double chi2 = nn_fit3(p.y, p.w, cols, c);
  if (coef) *coef = {c[0] / sc[0], c[1] / sc[1], c[2]};
  return chi2;
}

/// χ² of the points against the model at tf with coefficients fixed.
double chi2_at(const ShortTau& p, double tf, const std::array<double, 3>& coef) {
  const auto cols = columns(p, tf);
  double chi2 = 0;
  for (std::size_t i = 0; i < p.y.size(); ++i) {
    const double r = p.y[i] - (coef[0] * cols[0][i] + coef[1] * cols[1][i] + coef[2]);
    chi2 += p.w[i] * r * r;
  }
  return chi2;
}

/// The time constant of the best fit, from a grid in ln tf refined by golden section.
double best_time_constant(const ShortTau& p) {
  const double lo = std::log(p.tau0 / 4.0), hi = std::log(std::max(p.tau_cut / 4.0, p.tau0));
  const int grid = 80;
  double best = fit_at(p, 0.0, nullptr), best_l = lo;
  for (int g = 0; g <= grid; ++g) {
    const double l = lo + (hi - lo) * g / grid, c = fit_at(p, std::exp(l), nullptr);
    if (c < best) best = c, best_l = l;
  }
  const double step = (hi - lo) / grid;
  const auto f = [&](double l) { return fit_at(p, std::exp(l), nullptr); };
  const double l_hat = golden_min(f, best_l - step, best_l + step, 30);
  return std::exp(f(l_hat) > best ? best_l : l_hat);
}

}  // namespace

OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration,
                                            double alpha) {
  OutputLowpassEstimate e;
  const ShortTau pts = short_tau(m, v, edf, tau0, duration);
  e.points = static_cast<double>(pts.y.size());
  if (pts.y.size() < 5) return e;
  const double chi0 = fit_at(pts, 0.0, nullptr);
  const double lo = std::log(tau0 / 4.0), hi = std::log(std::max(pts.tau_cut / 4.0, tau0));
  const auto f = [&](double l) { return fit_at(pts, std::exp(l), nullptr); };
  const double l_hat = std::log(best_time_constant(pts));
  std::array<double, 3> sc{};
  e.chi2 = fit_at(pts, std::exp(l_hat), &sc);
  e.tf = std::exp(l_hat);
  e.white_angle2 = sc[0];
  e.white_rate = sc[1];
  // Overdispersion: the octave points are correlated and the model is approximate.
  const double scale = std::max(1.0, e.chi2 / std::max(1.0, e.points - 4.0));
  e.statistic = std::max(0.0, chi0 - e.chi2) / scale;
  e.p = std::min(1.0, e.points * std::erfc(std::sqrt(0.5 * e.statistic)));
  double a = 0, b = 400;
  for (int it = 0; it < 100; ++it) (e.points * std::erfc(std::sqrt(0.25 * (a + b))) > alpha ? a : b) = 0.5 * (a + b);
  e.threshold = b;
  // 95 % profile interval in ln tf: where the scaled χ² rises by 3.84.
  const double target = e.chi2 + 3.841458820694124 * scale;
  auto side = [&](double dir) {
    double in = l_hat, out = l_hat;
    for (int i = 1; i <= 60; ++i) {
      out = l_hat + dir * 0.02 * std::pow(1.4, i);
      if (f(out) > target || out < lo - 5 || out > hi + 5) break;
      in = out;
    }
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (in + out);
      (f(mid) > target ? out : in) = mid;
    }
    return std::exp(0.5 * (in + out));
  };
  e.tf_low = side(-1.0);
  e.tf_high = side(1.0);
  return e;
}

double output_lowpass_holdout(const std::vector<std::int64_t>& m, const std::array<std::vector<double>, 2>& v,
                              const std::vector<double>& edf, double tau0, double duration) {
  const std::array<ShortTau, 2> half = {short_tau(m, v[0], edf, tau0, duration),
                                        short_tau(m, v[1], edf, tau0, duration)};
  double gain = 0;
  for (int fit = 0; fit < 2; ++fit) {
    const ShortTau &p = half[static_cast<std::size_t>(fit)], &test = half[static_cast<std::size_t>(1 - fit)];
    if (p.y.size() < 5 || test.y.size() != p.y.size()) return std::numeric_limits<double>::quiet_NaN();
    std::array<double, 3> with{}, without{};
    const double tf = best_time_constant(p);
    const double chi2 = fit_at(p, tf, &with);
    fit_at(p, 0.0, &without);
    const double scale = std::max(1.0, chi2 / std::max(1.0, static_cast<double>(p.y.size()) - 4.0));
    gain += (chi2_at(test, 0.0, without) - chi2_at(test, tf, with)) / scale;
  }
  return gain;
}

}  // namespace rwcalc::diag
