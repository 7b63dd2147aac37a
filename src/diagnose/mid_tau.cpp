// Fits of the mid-τ Allan variance against an ensemble reference: N, B, K corrections kept
// ≥ 0, the Gauss–Markov bump beside them, and the reference without one run.
#include "diagnose/ensemble.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "diagnose/signal.hpp"

namespace rwcalc::diag {

namespace {

/// Weight of the identity in the mid-τ correlation matrix: the runs are fewer than the grid points.
constexpr double kCorrShrink = 0.2;
constexpr double kModelEdf = 1000.0;  ///< model floor of the EDF in the deviance (as band_misfit)

/// Measured-minus-reference mid-τ AV, weights 1/variance, normalised Q, N, B, K basis columns.
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

/// The problem decorrelated (C = L·Lᵀ; y, x → L⁻¹y, L⁻¹x, weights 1) so that least squares
/// minimise the generalised χ². Without a correlation matrix: unchanged.
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
  Eigen::MatrixXd C(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const std::size_t ia = p.index[a], ib = p.index[b];
      const double d = std::sqrt(ref.var[ia] * ref.var[ib]);
      double rho = a == b ? 1.0 : (d > 0 ? std::clamp(ref.cov[ia * g + ib] / d, -1.0, 1.0) * (1.0 - kCorrShrink) : 0.0);
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

/// Weighted least squares with c_base + Δc ≥ 0 for N², B², K² (active set: the most negative is
/// held at −c_base and the rest re-fitted); `shape`: a further, free column. Q² is held: the
/// read-out and the white angle noise are simulated as the five-term fit gave them and no model
/// carries a Q² correction; left free, its 3/τ² traded with N²'s 1/τ over 1–10 s, where a record's
/// evidence of N lies, and the simulated model then had neither (docs/diagnosis.md, Method).
struct ConstrainedFit {
  double chi2 = 0;
  std::array<double, 4> dc{0, 0, 0, 0};
  double a = 0, a_var = 0;  ///< shape coefficient (column as given) and its variance
  double dn_var = 0;        ///< variance of ΔN² when N is free, fit scale²
};

ConstrainedFit constrained_fit(const MidTauProblem& p, const std::array<double, 4>& c_base,
                               const std::vector<double>* shape, std::array<bool, 4> free = {false, true, true, true}) {
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
      if (idx[k] == 1)
        f.dn_var = o.inv(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)) / (p.colscale[1] * p.colscale[1]);
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

double gauss_markov_avar(double tau, double tc) {
  const double x = tau / tc;
  // (2Tc/τ)(1 − h), h = (Tc/(2τ))(3 − 4e^{−x} + e^{−2x}) with a series for small x.
  const double h = x < 1e-3 ? 1.0 - x * x / 3.0 : (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x);
  return 2.0 / x * (1.0 - h);
}

std::array<double, 4> power_law_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                            const std::array<double, 4>& c_base, double tau_max, bool hold_k) {
  std::vector<double> w = v;
  for (std::size_t i = 0; i < w.size() && i < ref.tau.size(); ++i)
    if (ref.tau[i] > tau_max) w[i] = 0.0;  // left out of the problem
  const MidTauProblem p = mid_tau_problem(w, ref);
  if (p.y.size() < 6) return {0, 0, 0, 0};
  return constrained_fit(p, c_base, nullptr, {false, true, true, !hold_k}).dc;
}

ShapeEstimate shape_detect(const std::vector<double>& v, const MidTauReference& ref,
                           const std::array<double, 4>& c_base, double fixed_time) {
  ShapeEstimate e;
  const MidTauProblem p0 = mid_tau_problem(v, ref);
  if (p0.y.size() < 8) return e;
  MidTauProblem p = p0;
  const Whitener wh = whiten(p, ref);
  using Fit = ConstrainedFit;
  auto fit = [&](const std::vector<double>* shape) { return constrained_fit(p, c_base, shape); };
  const Fit null = fit(nullptr);
  // Correlation times from 3× the shortest τ (a bump peaking earlier is white rate noise there) to
  // half the longest, or fixed_time alone.
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
      col[i] = gauss_markov_avar(p.tau[i], T);
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
    double net = e.scale * gauss_markov_avar(p0.tau[i], e.time);
    for (std::size_t t = 0; t < 4; ++t) net += best.dc[t] * p0.cols[t][i] * p0.colscale[t];
    e.excess = std::max(e.excess, net * std::sqrt(p0.w[i]));
  }
  {
    const double tp = 1.8926 * e.time;
    std::size_t k = 0;
    for (std::size_t i = 1; i < p0.tau.size(); ++i)
      if (std::abs(std::log(p0.tau[i] / tp)) < std::abs(std::log(p0.tau[k] / tp))) k = i;
    const double m = ref.mean[p0.index[k]];
    e.peak_ratio = m > 0 ? e.scale * gauss_markov_avar(tp, e.time) / m : 0.0;
  }
  e.white_rest = std::max(0.0, c_base[1] + best.dc[1]);
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
  r.cov.clear();  // the deviance reads means and variances only
  return r;
}

double mid_deviance(const std::vector<double>& v, const MidTauReference& ref) {
  double d = 0;
  for (std::size_t i = 0; i < v.size() && i < ref.mean.size(); ++i) {
    if (!(v[i] > 0) || !(ref.mean[i] > 0) || !(ref.var[i] > 0)) continue;
    const double nu = 1.0 / (ref.var[i] / (2.0 * ref.mean[i] * ref.mean[i]) + 1.0 / kModelEdf);
    const double q = v[i] / ref.mean[i];
    d += nu * (q - 1.0 - std::log(q));
  }
  return d;
}

}  // namespace rwcalc::diag
