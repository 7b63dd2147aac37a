// The output-chain low-pass family (lowpass.hpp).
#include "lowpass.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "rwcalc/deviance.hpp"
#include "rwcalc/minimise.hpp"
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

/// The rate's Welch periodogram: Hann-windowed non-overlapping segments of L samples (a power of
/// two, L·τ0 ≥ τ_cut), every third bin from the fourth, each the mean of K segments' |X|²/Σw²:
/// S(ω)·Gamma(K)/K for a Gaussian rate. A Hann bin is ½X_k − ¼(X_{k−1} + X_{k+1}) of the plain
/// transform's (up to phases): bins two apart share one of those (their powers correlate by 1/36: τf's errors
/// were 1.12 times the stated spread over 80 records), bins three apart none (1.03).
struct RateSpectrum {
  std::vector<double> omega, p;  ///< bin frequency, rad per sample; periodogram, (rate unit)²
  double k = 0;                  ///< segments averaged
};

RateSpectrum rate_spectrum(std::vector<double> y, double tau0, double tau_cut) {
  RateSpectrum s;
  std::size_t len = 16;
  while (static_cast<double>(len) * tau0 < tau_cut) len *= 2;
  const std::size_t segments = y.size() / len;  // whole segments: hann_periodogram's average
  if (segments < 8) return s;
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / static_cast<double>(y.size());
  for (double& v : y) v -= mean;
  const std::vector<double> sum = hann_periodogram(y, len, len);
  s.k = static_cast<double>(segments);
  for (std::size_t b = 4; b + 2 <= len / 2; b += 3) {
    s.omega.push_back(2.0 * kPi * static_cast<double>(b) / static_cast<double>(len));
    s.p.push_back(sum[b]);
  }
  return s;
}

/// The rate spectrum's model at time constant tf, per unit level: white angle noise (the rate's
/// 2 − 2 cos ω), white rate and flicker (1/ω), each through the filter's |H|² =
/// (1 − φ)²/(1 − 2φ cos ω + φ²), φ = e^{−τ0/tf} (the AR(1) of output_filter.hpp).
Eigen::MatrixXd spectrum_columns(const RateSpectrum& s, double tau0, double tf) {
  const double phi = tf > 0 ? std::exp(-tau0 / tf) : 0.0;
  Eigen::MatrixXd g(static_cast<Eigen::Index>(s.p.size()), 3);
  for (Eigen::Index i = 0; i < g.rows(); ++i) {
    const double c = std::cos(s.omega[static_cast<std::size_t>(i)]);
    const double h2 = (1 - phi) * (1 - phi) / (1 - 2 * phi * c + phi * phi);
    g(i, 0) = h2 * (2 - 2 * c);
    g(i, 1) = h2;
    g(i, 2) = h2 / s.omega[static_cast<std::size_t>(i)];
  }
  for (Eigen::Index c = 0; c < 3; ++c) g.col(c) /= g.col(c).maxCoeff();
  return g;
}

/// The Whittle deviance Σ 2K(P/S − 1 − ln P/S) of the periodogram at tf, the levels at its minimum
/// (a Gamma fit with identity link, by iteratively reweighted least squares). The white rate and
/// flicker levels may go negative while the spectrum stays positive: held at 0, the white rate (a
/// small term under the read-out's) bent the profile and biased τf by half its standard error. The
/// white angle level may not: negative, its rate spectrum 2 − 2 cos ω falls with frequency as the
/// filter's does, and a real sensor's roll-off (the ADIS16405's) was fitted without a filter. The
/// non-negative fit where the spectrum is not positive.
double whittle_deviance(const RateSpectrum& s, double tau0, double tf) {
  const Eigen::MatrixXd g = spectrum_columns(s, tau0, tf);
  const Eigen::Map<const Eigen::VectorXd> p(s.p.data(), static_cast<Eigen::Index>(s.p.size()));
  Eigen::VectorXd model = p;
  for (int it = 0; it < 8; ++it) {
    const Eigen::VectorXd w = model.array().square().inverse();
    Eigen::VectorXd next = g * nnls(g, p, w, 0b111, 0b110).x;
    if (!(next.minCoeff() > 0)) next = g * nnls(g, p, w, 0b111).x;
    if (!(next.minCoeff() > 0)) break;
    const bool done = ((next - model).array() / model.array()).abs().maxCoeff() < 1e-9;
    model = next;
    if (done) break;
  }
  double d = 0;
  for (Eigen::Index i = 0; i < p.size(); ++i) d += gamma_deviance(p[i], model[i], 2 * s.k);
  return d;
}

/// The minimum of f(ln tf) on [lo, hi]: a grid of 80 refined by golden section; `none` is f at tf
/// = 0 (no filter), which wins unless some tf does better.
template <class F>
double argmin_log_tf(const F& f, double lo, double hi, double none) {
  const int grid = 80;
  double best = none, best_l = lo;
  for (int g = 0; g <= grid; ++g) {
    const double l = lo + (hi - lo) * g / grid, c = f(l);
    if (c < best) best = c, best_l = l;
  }
  const double step = (hi - lo) / grid;
  const double l_hat = golden_min(f, best_l - step, best_l + step, 30);
  return f(l_hat) > best ? best_l : l_hat;
}

/// Where f(ln tf) first rises above `target` from its minimum at l_hat in direction dir (±1).
template <class F>
double profile_side(const F& f, double l_hat, double target, double dir) {
  double in = l_hat, out = l_hat;
  for (int i = 1; i <= 60; ++i) {
    out = l_hat + dir * 0.02 * std::pow(1.4, i);
    if (f(out) > target || std::abs(out - l_hat) > 15) break;
    in = out;
  }
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (in + out);
    (f(mid) > target ? out : in) = mid;
  }
  return std::exp(0.5 * (in + out));
}

/// The time constant of the best fit to the octave AV.
double best_time_constant(const ShortTau& p) {
  const double lo = std::log(p.tau0 / 4.0), hi = std::log(std::max(p.tau_cut / 4.0, p.tau0));
  const auto f = [&](double l) { return fit_at(p, std::exp(l), nullptr); };
  return std::exp(argmin_log_tf(f, lo, hi, fit_at(p, 0.0, nullptr)));
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
  e.tf = best_time_constant(pts);
  std::array<double, 3> sc{};
  e.chi2 = fit_at(pts, e.tf, &sc);
  e.white_angle2 = sc[0];
  e.white_rate = sc[1];
  // Overdispersion: the octave points are correlated and the model is approximate.
  const double scale = std::max(1.0, e.chi2 / std::max(1.0, e.points - 4.0));
  e.statistic = std::max(0.0, chi0 - e.chi2) / scale;
  e.p = std::min(1.0, e.points * std::erfc(std::sqrt(0.5 * e.statistic)));
  double a = 0, b = 400;
  for (int it = 0; it < 100; ++it) (e.points * std::erfc(std::sqrt(0.25 * (a + b))) > alpha ? a : b) = 0.5 * (a + b);
  e.threshold = b;
  return e;
}

bool output_lowpass_estimate(std::vector<double> rate, const std::vector<std::int64_t>& m, const std::vector<double>& v,
                             const std::vector<double>& edf, double tau0, double duration, OutputLowpassEstimate& e) {
  const ShortTau pts = short_tau(m, v, edf, tau0, duration);
  const RateSpectrum spec = rate_spectrum(std::move(rate), tau0, pts.tau_cut);
  if (pts.y.size() < 5 || spec.p.size() < 16) return false;
  const double lo = std::log(tau0 / 4.0), hi = std::log(std::max(pts.tau_cut / 4.0, tau0));
  const auto f = [&](double l) { return whittle_deviance(spec, tau0, std::exp(l)); };
  const double l_hat = argmin_log_tf(f, lo, hi, whittle_deviance(spec, tau0, 0.0));
  const double d = f(l_hat);
  // Overdispersion: the deviance per bin against its mean for a spectrum the model describes.
  const double dof = static_cast<double>(spec.p.size()) - 4.0;
  e.dispersion = d / (dof * gamma_deviance_mean(2.0 * spec.k));
  const double scale = std::max(1.0, e.dispersion);
  const double target = d + 3.841458820694124 * scale;
  e.tf = std::exp(l_hat);
  e.tf_low = profile_side(f, l_hat, target, -1.0);
  e.tf_high = profile_side(f, l_hat, target, 1.0);
  std::array<double, 3> sc{};
  e.chi2 = fit_at(pts, e.tf, &sc);
  e.white_angle2 = sc[0];
  e.white_rate = sc[1];
  return true;
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
