// The exact likelihood of the block means' second differences (gls.hpp): the terms' Toeplitz
// autocovariances, Durbin–Levinson whitening and the levels' profile.
#include "gls.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rwcalc/minimise.hpp"

namespace rwcalc::diag {

namespace {

/// Autocorrelation of the third difference (−1, 3, −3, 1) at lags 0 … 3: z_i is the third
/// difference of the angle at the block edges over tb.
constexpr long double kR[4] = {20, -15, 6, -1};

/// Σ_d kR[|d|]·g(|m + d|), d = −3 … 3: the covariance of z at lag m for a term whose generalised
/// covariance of the angle at lag u blocks is g(u) (an intrinsic covariance: its polynomial part of
/// degree ≤ 2 cancels).
template <class G>
long double lag_sum(std::size_t m, const G& g) {
  long double s = 0;
  for (int d = -3; d <= 3; ++d) s += kR[std::abs(d)] * g(static_cast<std::size_t>(std::abs(static_cast<long>(m) + d)));
  return s;
}

/// Flicker: g(u) = u² ln u (the generalised covariance of a 1/f rate, the τ² ln tb part cancels).
/// Beyond 32 lags the difference is taken from its series (the direct sum loses every digit):
/// −δ⁶f = −(f⁽⁶⁾ + f⁽⁸⁾/4 + 7f⁽¹⁰⁾/240), f⁽⁶⁾ = −12/u⁴, f⁽⁸⁾ = −240/u⁶, f⁽¹⁰⁾ = −10080/u⁸.
double flicker_lag(std::size_t m) {
  if (m < 32)
    return static_cast<double>(lag_sum(m, [](std::size_t u) {
      const long double x = static_cast<long double>(u);
      return u ? x * x * std::log(x) : 0.0L;
    }));
  const double u2 = 1.0 / (static_cast<double>(m) * static_cast<double>(m));
  return 12.0 * u2 * u2 + 60.0 * u2 * u2 * u2 + 294.0 * u2 * u2 * u2 * u2;
}

}  // namespace

std::vector<double> counter_correlation(const std::vector<double>& advance, double spread, std::size_t lags) {
  constexpr double pi = 3.141592653589793;
  constexpr int kHarmonics = 64;  // beyond, m⁻² leaves under 2 % of c(0) even undamped
  std::vector<double> c = {1.0};
  for (std::size_t u = 1; u < lags; ++u) {
    const double damp = 2 * pi * pi * static_cast<double>(u) * spread;
    if (damp > 30) break;  // e^{−30}: every harmonic is gone
    double sum = 0;
    for (int m = 1; m <= kHarmonics; ++m) {
      const double md = m, e = std::exp(-damp * md * md) / (md * md);
      if (e < 1e-17) break;
      double mean_cos = 0;
      for (const double a : advance) mean_cos += std::cos(2 * pi * md * static_cast<double>(u) * a);
      sum += e * mean_cos / static_cast<double>(advance.size());
    }
    c.push_back(6.0 * sum / (pi * pi));
  }
  return c;
}

std::vector<double> term_autocov(const CovTerm& t, std::size_t n, double tb) {
  std::vector<double> r(n, 0.0);
  const double tb2 = tb * tb;
  switch (t.kind) {
    case CovKind::Q:  // G(0) = 1 ″², 0 beyond
      for (std::size_t m = 0; m < std::min<std::size_t>(n, 4); ++m) r[m] = static_cast<double>(kR[m]) / tb2;
      break;
    case CovKind::Counter: {  // G(u) = c(u) ″²
      const std::vector<double>& c = *t.correlation;
      const auto g = [&](std::size_t u) { return u < c.size() ? static_cast<long double>(c[u]) : 0.0L; };
      for (std::size_t m = 0; m < std::min(n, c.size() + 3); ++m) r[m] = static_cast<double>(lag_sum(m, g)) / tb2;
      break;
    }
    case CovKind::N:  // AV 1/τ: G(τ) = −τ/2
      for (std::size_t m = 0; m < std::min<std::size_t>(n, 4); ++m)
        r[m] = static_cast<double>(lag_sum(m, [&](std::size_t u) { return -0.5L * u * tb; })) / tb2;
      break;
    case CovKind::B: {  // AV 1 = 2 ln2·h: G(τ) = (h/2)τ² ln τ
      const double h = 1.0 / (2.0 * std::log(2.0));
      for (std::size_t m = 0; m < n; ++m) r[m] = 0.5 * h * flicker_lag(m);
      break;
    }
    case CovKind::K:  // AV τ: G(τ) = τ³/4; exact in integers, 0 from lag 3 on
      for (std::size_t m = 0; m < std::min<std::size_t>(n, 3); ++m)
        r[m] = static_cast<double>(lag_sum(m, [](std::size_t u) { return static_cast<long double>(u * u * u); })) * tb /
               4.0;
      break;
    case CovKind::GM: {  // variance 1, G(τ) = −Tc²(τ/Tc − 1 + e^{−τ/Tc})
      const long double tc = t.tc_s, a = tb / tc;
      for (std::size_t m = 0; m < std::min<std::size_t>(n, 3); ++m)
        r[m] = static_cast<double>(lag_sum(m,
                                           [&](std::size_t u) {
                                             const long double x = u * a;
                                             return -tc * tc * (x - 1.0L + std::exp(-x));
                                           })) /
               tb2;
      // From lag 3 on only the exponential is left: Tc²(2 sinh(a/2))⁶ e^{−ma}/tb².
      const double s6 = std::pow(2.0 * std::sinh(0.5 * static_cast<double>(a)), 6.0);
      for (std::size_t m = 3; m < n; ++m)
        r[m] = static_cast<double>(tc * tc) * s6 * std::exp(-static_cast<double>(a) * static_cast<double>(m)) / tb2;
      break;
    }
  }
  return r;
}

double term_avar(const CovTerm& t, double tau) {
  switch (t.kind) {
    case CovKind::Q:
    case CovKind::Counter: return 3.0 / (tau * tau);
    case CovKind::N: return 1.0 / tau;
    case CovKind::B: return 1.0;
    case CovKind::K: return tau;
    case CovKind::GM: {
      const double x = tau / t.tc_s;
      const double h = x < 1e-3 ? 1.0 - x * x / 3.0 : (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x);
      return 2.0 / x * (1.0 - h);
    }
  }
  return 0.0;
}

namespace {

/// Σ a[i]·b[i] in four partial sums (the loop vectorises; the order is fixed, so the result too).
double dot4(const double* a, const double* b, std::size_t n) {
  double acc[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t u = 0; u < 4; ++u) acc[u] += a[i + u] * b[i + u];
  for (; i < n; ++i) acc[0] += a[i] * b[i];
  return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

}  // namespace

Whitened whiten(const std::vector<double>& r, const Eigen::MatrixXd& v, Eigen::MatrixXd* w_out) {
  const std::size_t n = r.size();
  const auto q = v.cols();
  Whitened out;
  out.v.resize(static_cast<Eigen::Index>(n), q);
  RowMatrix w;
  if (w_out) w.setZero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  // The order-k predictor reversed, ψ[i] = φ_{k−i}, kept at the end of `buf` (it grows at its
  // front): both the recursion's sums and the prediction of sample k are then ascending dot
  // products.
  std::vector<double> buf(n + 1, 0.0);
  double* psi = buf.data() + n;  // order 0: empty
  double var = r[0];
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) {
      const double kappa = (r[k] - dot4(psi, r.data() + 1, k - 1)) / var;
      // φ_j ← φ_j − κ φ_{k−j}: in ψ, ψ[m] ← ψ[m] − κ ψ[k−2−m], pairwise; then κ in front.
      for (std::size_t m = 0, e = k - 1; m < e / 2 + (e % 2); ++m) {
        const std::size_t o = k - 2 - m;
        const double a = psi[m], b = psi[o];
        psi[m] = a - kappa * b;
        if (o != m) psi[o] = b - kappa * a;
      }
      *--psi = kappa;
      var *= 1.0 - kappa * kappa;
    }
    if (!(var > 0) || !std::isfinite(var)) {
      out.ok = false;
      return out;
    }
    out.logdet += std::log(var);
    const double s = 1.0 / std::sqrt(var);
    const auto K = static_cast<Eigen::Index>(k);
    for (Eigen::Index c = 0; c < q; ++c) out.v(K, c) = (v(K, c) - dot4(psi, &v(0, c), k)) * s;
    if (w_out) {
      for (std::size_t i = 0; i < k; ++i) w(K, static_cast<Eigen::Index>(i)) = -psi[i] * s;
      w(K, K) = s;
    }
  }
  if (w_out) *w_out = w;
  return out;
}

Eigen::VectorXd second_differences(const std::vector<double>& y) {
  const std::size_t n = y.size() < 3 ? 0 : y.size() - 2;
  Eigen::VectorXd z(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) z(static_cast<Eigen::Index>(i)) = y[i + 2] - 2.0 * y[i + 1] + y[i];
  return z;
}

std::vector<double> total_autocov(const Blocks& b, const std::vector<CovTerm>& terms,
                                  const std::vector<double>& level) {
  std::vector<double> r(b.n(), 0.0);
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const auto rt = term_autocov(terms[t], b.n(), b.tb);
    for (std::size_t m = 0; m < r.size(); ++m) r[m] += level[t] * rt[m];
  }
  return r;
}

double m2ll_fixed(const Blocks& b, const Hypothesis& h, const std::vector<double>& level, const Eigen::VectorXd& beta) {
  Eigen::MatrixXd v(b.z.size(), 1);
  v.col(0) = b.z;
  if (h.x.cols()) v.col(0) -= h.x * beta;
  const Whitened w = whiten(total_autocov(b, h.terms, level), v);
  if (!w.ok) return std::numeric_limits<double>::infinity();
  return w.v.col(0).squaredNorm() + w.logdet;
}

namespace {

/// −2 ln L of z with the overall scale s of `r` profiled: n ln(RSS/n) + ln det Σ(r) + n; with
/// `free_scale` false, s = 1: RSS + ln det Σ(r). The returned profile's levels are s times the given
/// ones.
Profile scaled_fit(const Blocks& b, const Hypothesis& h, const std::vector<double>& r, bool free_scale) {
  Profile p;
  const Eigen::Index n = static_cast<Eigen::Index>(b.n()), k = h.x.cols();
  Eigen::MatrixXd v(n, 1 + k);
  v.col(0) = b.z;
  if (k) v.rightCols(k) = h.x;
  const Whitened w = whiten(r, v);
  if (!w.ok) {
    p.m2ll = std::numeric_limits<double>::infinity();
    return p;
  }
  Eigen::VectorXd res = w.v.col(0);
  double logdet_xtx = 0;  // ln det XᵀR⁻¹X
  if (k) {
    const Eigen::MatrixXd xw = w.v.rightCols(k);
    const Eigen::MatrixXd xtx = xw.transpose() * xw;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(xtx);
    p.beta = ldlt.solve(xw.transpose() * res);
    res -= xw * p.beta;
    p.beta_cov = ldlt.solve(Eigen::MatrixXd::Identity(k, k));
    logdet_xtx = ldlt.vectorD().array().log().sum();
  }
  const double rss = res.squaredNorm(), nn = static_cast<double>(n), nr = static_cast<double>(n - k);
  const double s = free_scale ? rss / nn : 1.0;
  p.m2ll = free_scale ? nn * std::log(s) + w.logdet + nn : rss + w.logdet;
  // REML: n − k degrees of freedom for the scale, and ln det XᵀΣ⁻¹X for the coefficients.
  p.restricted_m2ll = free_scale ? nr * std::log(rss / nr) + w.logdet + logdet_xtx + nr : rss + w.logdet + logdet_xtx;
  if (k) p.beta_cov *= s;
  p.r = r;
  for (double& x : p.r) x *= s;
  p.level.assign(1, s);  // the caller scales its levels by this
  return p;
}

}  // namespace

bool has_known_level(const std::vector<CovTerm>& terms) {
  return std::any_of(terms.begin(), terms.end(), [](const CovTerm& t) { return t.known_level > 0; });
}

Profile evaluate(const Blocks& b, const Hypothesis& h, const std::vector<double>& level) {
  std::vector<double> lv = level;
  for (std::size_t t = 0; t < h.terms.size(); ++t)
    if (h.terms[t].known_level > 0) lv[t] = h.terms[t].known_level;
  const bool free_scale = !has_known_level(h.terms);
  Profile p = scaled_fit(b, h, total_autocov(b, h.terms, lv), free_scale);
  const double s = p.level.empty() ? 1.0 : p.level[0];
  p.level = lv;
  for (double& l : p.level) l *= s;
  return p;
}

Profile evaluate_exact(const Blocks& b, const Hypothesis& h, const std::vector<double>& level) {
  Profile p = scaled_fit(b, h, total_autocov(b, h.terms, level), false);
  p.level = level;
  return p;
}

namespace {

/// Log-levels below the reference's by more than this are a term switched off (e^{−40}).
constexpr double kLogFloor = -40.0;

}  // namespace

Profile profile(const Blocks& b, const Hypothesis& h, const std::vector<double>& start) {
  const std::size_t nt = h.terms.size();
  std::vector<std::vector<double>> unit(nt);
  for (std::size_t t = 0; t < nt; ++t) unit[t] = term_autocov(h.terms[t], b.n(), b.tb);
  // The reference term (level 1, the scale profiled) is the one with the largest share of Var z.
  // With a known level there is no free scale: no reference, every other level searched.
  const bool free_scale = !has_known_level(h.terms);
  std::size_t ref = nt;
  if (free_scale) {
    ref = 0;
    for (std::size_t t = 1; t < nt; ++t)
      if (start[t] * unit[t][0] > start[ref] * unit[ref][0]) ref = t;
  }
  const double ref_start = free_scale ? start[ref] : 1.0;
  const auto searched = [&](std::size_t t) { return t != ref && !(h.terms[t].known_level > 0); };
  auto levels_of = [&](const std::vector<double>& u) {
    std::vector<double> lv(nt);
    for (std::size_t t = 0, j = 0; t < nt; ++t)
      lv[t] = t == ref ? 1.0 : searched(t) ? std::exp(std::clamp(u[j++], kLogFloor, 40.0)) : h.terms[t].known_level;
    return lv;
  };
  auto fit_at = [&](const std::vector<double>& u) {
    const auto lv = levels_of(u);
    std::vector<double> r(b.n(), 0.0);
    for (std::size_t t = 0; t < nt; ++t)
      for (std::size_t m = 0; m < r.size(); ++m) r[m] += lv[t] * unit[t][m];
    Profile p = scaled_fit(b, h, r, free_scale);
    const double s = p.level.empty() ? 1.0 : p.level[0];
    p.level = lv;
    for (double& l : p.level) l *= s;
    return p;
  };
  std::vector<double> u0;
  for (std::size_t t = 0; t < nt; ++t)
    if (searched(t)) u0.push_back(std::log(std::max(start[t], 1e-300) / ref_start));
  if (u0.empty()) return fit_at(u0);
  const auto f = [&](const std::vector<double>& u) { return fit_at(u).m2ll; };
  // Two rounds: a restart from the first optimum escapes a collapsed simplex.
  // The first round's end is only a start: the second's test decides, over both rounds' evaluations.
  const SimplexMinimum first = nelder_mead(f, u0, 1.0, 300, 1e-4);
  const SimplexMinimum second = nelder_mead(f, first.x, 0.3, 150, 1e-5);
  Profile p = fit_at(second.x);
  p.termination = second.termination;
  p.termination.iterations += first.termination.iterations;
  return p;
}

}  // namespace rwcalc::diag
