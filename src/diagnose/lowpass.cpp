// The output-chain low-pass family (lowpass.hpp).
#include "lowpass.hpp"

#include <array>
#include <cmath>

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

}  // namespace

OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration,
                                            double alpha) {
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
  // χ² at tf (0: no filter); columns scaled to unit maximum for the normal equations.
  auto fit_at = [&](double tf, std::array<double, 2>* scale) {
    std::array<std::vector<double>, 3> cols;
    for (auto& c : cols) c.resize(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) {
      cols[0][i] = output_lowpass_angle_avar(mm[i], tau0, tf);
      cols[1][i] = output_lowpass_rate_avar(mm[i], tau0, tf);
      cols[2][i] = 1.0;
    }
    std::array<double, 3> sc{1, 1, 1}, c{};
    for (std::size_t k = 0; k < 2; ++k) {
      sc[k] = *std::max_element(cols[k].begin(), cols[k].end());
      for (double& x : cols[k]) x /= sc[k];
    }
    const double chi2 = nn_fit3(y, w, cols, c);
    if (scale) *scale = {c[0] / sc[0], c[1] / sc[1]};
    return chi2;
  };
  const double chi0 = fit_at(0.0, nullptr);
  const double lo = std::log(tau0 / 4.0), hi = std::log(std::max(tau_cut / 4.0, tau0));
  const int grid = 80;
  double best = chi0, best_l = lo;
  for (int g = 0; g <= grid; ++g) {
    const double l = lo + (hi - lo) * g / grid, c = fit_at(std::exp(l), nullptr);
    if (c < best) best = c, best_l = l;
  }
  const double step = (hi - lo) / grid;
  const auto f = [&](double l) { return fit_at(std::exp(l), nullptr); };
  double l_hat = golden_min(f, best_l - step, best_l + step, 30);
  if (f(l_hat) > best) l_hat = best_l;
  std::array<double, 2> sc{0, 0};
  e.chi2 = fit_at(std::exp(l_hat), &sc);
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

}  // namespace rwcalc::diag
