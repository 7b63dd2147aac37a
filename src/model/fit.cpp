// Gamma-deviance (scaled-χ² likelihood) fit of the five-term IEEE 952 model with non-negative
// squared coefficients, profile-likelihood intervals and the classic slope-line readout.
#include "rwcalc/fit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/special_functions/digamma.hpp>
#include <cmath>
#include <numbers>
#include <thread>

#include "model/fit_kernels.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/thread.hpp"

namespace rwcalc {

namespace {

constexpr int P = kTermCount;
using Vec5 = Eigen::Matrix<double, P, 1>;
using Mat5 = Eigen::Matrix<double, P, P>;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// AV of flicker per B²: 2 ln2/π.
constexpr double kFlickerFactor = 2.0 * std::numbers::ln2 / std::numbers::pi;
/// Coefficient = kCoefScale·√c (c in s-based units, coefficients in h-based units).
constexpr std::array<double, P> kCoefScale{1.0, 1.0 / 60.0, 1.0, 60.0, 3600.0};

int idx(Term t) { return static_cast<int>(t); }

/// The problem in scaled parameters d = c / scale (columns of comparable size).
struct Problem {
  Eigen::MatrixXd g;   // J×P: basis_i(τ_j)·scale_i
  Eigen::VectorXd y;   // observed σ²
  Eigen::VectorXd nu;  // effective EDF
  Vec5 scale = Vec5::Ones();
  unsigned enabled_mask = 0;
};

Problem make_problem(std::span<const FitPoint> pts, const FitOptions& o) {
  Problem pr;
  const auto j = static_cast<Eigen::Index>(pts.size());
  pr.g.resize(j, P);
  pr.y.resize(j);
  pr.nu.resize(j);
  for (Eigen::Index r = 0; r < j; ++r) {
    const auto& p = pts[static_cast<std::size_t>(r)];
    pr.y[r] = p.var;
    pr.nu[r] = o.edf_cap > 0 ? 1.0 / (1.0 / p.edf + 1.0 / o.edf_cap) : p.edf;
    for (int i = 0; i < P; ++i) pr.g(r, i) = term_basis(kAllTerms[static_cast<std::size_t>(i)], p.tau_s);
  }
  for (int i = 0; i < P; ++i) {
    if (o.enabled[static_cast<std::size_t>(i)]) pr.enabled_mask |= 1u << i;
    // Scale each column to unit weighted norm relative to the data.
    const double norm = (pr.g.col(i).array() / pr.y.array() * pr.nu.array().sqrt()).matrix().norm();
    pr.scale[i] = norm > 0 ? 1.0 / norm : 1.0;
    pr.g.col(i) *= pr.scale[i];
  }
  return pr;
}

double deviance(const Problem& pr, const Eigen::VectorXd& mu) {
  double d = 0;
  for (Eigen::Index r = 0; r < mu.size(); ++r) {
    if (!(mu[r] > 0)) return kInf;
    const double q = pr.y[r] / mu[r];
    d += pr.nu[r] * (q - 1.0 - std::log(q));
  }
  return d;
}

/// Unconstrained weighted LS on the support `s` (normal equations a·d = b, Jacobi-scaled).
/// Writes the solution into `d` and its objective (−bᵀd) into `obj`; false when singular or when
/// any component is not strictly positive.
bool solve_support(const Mat5& a, const Vec5& b, unsigned s, Vec5& d, double& obj) {
  const int k = std::popcount(s);
  std::array<int, P> ids{};
  int n = 0;
  for (int i = 0; i < P; ++i)
    if (s & (1u << i)) ids[static_cast<std::size_t>(n++)] = i;
  // At most 5×5: fixed-capacity storage, no heap allocation (this runs for every support of
  // every NNLS of every IRLS step of every profile).
  using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, P, P>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, P, 1>;
  SmallMat as(k, k);
  SmallVec bs(k);
  SmallVec dsc(k);
  for (int r = 0; r < k; ++r) {
    const double diag = a(ids[static_cast<std::size_t>(r)], ids[static_cast<std::size_t>(r)]);
    if (!(diag > 0)) return false;
    dsc[r] = 1.0 / std::sqrt(diag);
  }
  for (int r = 0; r < k; ++r) {
    bs[r] = b[ids[static_cast<std::size_t>(r)]] * dsc[r];
    for (int q = 0; q < k; ++q)
      as(r, q) = a(ids[static_cast<std::size_t>(r)], ids[static_cast<std::size_t>(q)]) * dsc[r] * dsc[q];
  }
  const Eigen::LLT<SmallMat> llt(as);
  if (llt.info() != Eigen::Success || llt.rcond() < 1e-13) return false;
  const SmallVec z = llt.solve(bs);
  const SmallVec cs = z.cwiseProduct(dsc);
  if (!cs.allFinite() || (cs.array() <= 0).any()) return false;
  obj = -bs.dot(z);
  for (int r = 0; r < k; ++r) d[ids[static_cast<std::size_t>(r)]] = cs[r];
  return true;
}

/// Weighted least squares min Σ w (y − G d)² over d_free ≥ 0, the other components fixed at
/// `base`. Exact: enumerates the supports (at most 2⁵) and keeps the best feasible unconstrained
/// solution on its support, which is the NNLS optimum.
Vec5 nnls(const Problem& pr, const Eigen::VectorXd& w, unsigned free_mask, const Vec5& base) {
  Vec5 fixed = base;
  for (int i = 0; i < P; ++i)
    if (free_mask & (1u << i)) fixed[i] = 0;
  const Eigen::VectorXd target = pr.y - pr.g * fixed;
  const Eigen::MatrixXd gw = pr.g.array().colwise() * w.array();
  const Mat5 a = pr.g.transpose() * gw;
  const Vec5 b = gw.transpose() * target;

  Vec5 best = fixed;
  double best_obj = 0;  // objective relative to tᵀWt; the empty support gives 0
  for (unsigned s = free_mask; s != 0; s = (s - 1) & free_mask) {
    Vec5 cand = fixed;
    double obj = 0;
    if (solve_support(a, b, s, cand, obj) && obj < best_obj) {
      best_obj = obj;
      best = cand;
    }
  }
  return best;
}

struct IrlsResult {
  Vec5 d;
  double dev = kInf;
  int iterations = 0;
};

/// Iteratively reweighted NNLS with weights ν/μ² (Fisher scoring of the Gamma likelihood with
/// identity link) and step halving on the deviance. `start` holds the fixed components and, when
/// `from_data` is false, the starting point.
IrlsResult irls(const Problem& pr, unsigned free_mask, const Vec5& start, bool from_data) {
  IrlsResult res;
  Vec5 d = start;
  Eigen::VectorXd mu = pr.g * d;
  double dev = from_data ? kInf : deviance(pr, mu);
  if (!std::isfinite(dev)) {
    const Eigen::VectorXd w = pr.nu.array() / pr.y.array().square();
    d = nnls(pr, w, free_mask, start);
    mu = pr.g * d;
    dev = deviance(pr, mu);
    if (!std::isfinite(dev)) {
      // Positive start on the free terms, so that every model point is positive.
      for (int i = 0; i < P; ++i)
        if (free_mask & (1u << i)) d[i] = std::max(d[i], 1e-3);
      mu = pr.g * d;
      dev = deviance(pr, mu);
    }
  }
  int it = 0;
  for (; it < 300 && std::isfinite(dev); ++it) {
    const Eigen::VectorXd w = pr.nu.array() / mu.array().square();
    const Vec5 d_new = nnls(pr, w, free_mask, d);
    double step = 1.0;
    Vec5 d_try = d_new;
    Eigen::VectorXd mu_try = pr.g * d_try;
    double dev_try = deviance(pr, mu_try);
    for (int h = 0; h < 50 && !(dev_try <= dev); ++h) {
      step *= 0.5;
      d_try = d + step * (d_new - d);
      mu_try = pr.g * d_try;
      dev_try = deviance(pr, mu_try);
    }
    if (!(dev_try <= dev)) break;
    const double gain = dev - dev_try;
    const double move = (d_try - d).norm() / (1e-300 + d_try.norm());
    d = d_try;
    mu = mu_try;
    dev = dev_try;
    if (gain <= 1e-12 * (1.0 + dev) && move < 1e-7) break;
  }
  res.d = d;
  res.dev = dev;
  res.iterations = it;
  return res;
}

/// Small-sample (Bartlett) factor E[ν(x − 1 − ln x)] for x ~ χ²_ν/ν, so that Σ d_j/b(ν_j) ≈ χ².
double bartlett(double nu) {
  if (nu > 1e3) return 1.0 + 1.0 / (3.0 * nu);
  return -nu * (boost::math::digamma(nu / 2.0) - std::log(nu / 2.0));
}

double normal_quantile(double p) {
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}
double normal_cdf(double x) { return boost::math::cdf(boost::math::normal_distribution<double>(), x); }
double chi2_quantile(double p, double dof) {
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

/// Illinois false position for f(a)·f(b) < 0; returns the root to a relative tolerance.
template <class F>
double find_root(F&& f, double a, double fa, double b, double fb) {
  double c = b;
  int side = 0;
  for (int it = 0; it < 100; ++it) {
    c = (a * fb - b * fa) / (fb - fa);
    if (!std::isfinite(c)) c = 0.5 * (a + b);
    const double fc = f(c);
    if (fc == 0 || std::abs(b - a) <= 1e-6 * std::max(std::abs(a), std::abs(b))) break;
    if ((fc > 0) == (fb > 0)) {
      b = c;
      fb = fc;
      if (side == -1) fa *= 0.5;
      side = -1;
    } else {
      a = c;
      fa = fc;
      if (side == +1) fb *= 0.5;
      side = +1;
    }
    if (std::abs(b - a) <= 1e-6 * std::max(std::abs(a), std::abs(b))) break;
  }
  return c;
}

/// Everything needed to evaluate profiles of a finished fit.
struct Profiler {
  const Problem& pr;
  Vec5 d_hat;
  double dev_min;

  /// Profile deviance increase with d_i fixed at v (≥ 0).
  double delta(int i, double v) const {
    Vec5 start = d_hat;
    start[i] = v;
    const unsigned free_mask = pr.enabled_mask & ~(1u << i);
    const IrlsResult r = irls(pr, free_mask, start, false);
    return std::isfinite(r.dev) ? std::max(0.0, r.dev - dev_min) : kInf;
  }
};

}  // namespace

std::string_view term_name(Term t) {
  static constexpr std::array<std::string_view, P> n{"Q", "N", "B", "K", "R"};
  return n[static_cast<std::size_t>(idx(t))];
}

std::string_view term_unit(Term t) {
  static constexpr std::array<std::string_view, P> u{"arcsec", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)",
                                                     "deg/h^2"};
  return u[static_cast<std::size_t>(idx(t))];
}

double term_basis(Term t, double tau_s) {
  switch (t) {
    case Term::Q: return 3.0 / (tau_s * tau_s);
    case Term::N: return 1.0 / tau_s;
    case Term::B: return kFlickerFactor;
    case Term::K: return tau_s / 3.0;
    case Term::R: return tau_s * tau_s / 2.0;
  }
  return 0;
}

double coefficient_from_c(Term t, double c) { return kCoefScale[static_cast<std::size_t>(idx(t))] * std::sqrt(std::max(c, 0.0)); }

double c_from_coefficient(Term t, double value) {
  const double s = value / kCoefScale[static_cast<std::size_t>(idx(t))];
  return s * s;
}

std::vector<FitPoint> fit_points(const AllanResult& allan) {
  std::vector<FitPoint> pts;
  pts.reserve(allan.points.size());
  const bool ovl = allan.estimator == Estimator::Overlapping;
  for (const auto& p : allan.points) pts.push_back({p.tau_s, p.var, p.edf, ovl ? p.m : 0, ovl ? p.n : 0});
  return pts;
}

double FitResult::model_var(double tau_s) const {
  double v = 0;
  for (int i = 0; i < P; ++i) v += c[i] * term_basis(kAllTerms[static_cast<std::size_t>(i)], tau_s);
  return v;
}

double FitResult::log_correlation(Term a, Term b) const {
  const double va = cov_c(idx(a), idx(a));
  const double vb = cov_c(idx(b), idx(b));
  if (!(va > 0) || !(vb > 0)) return 0;
  return std::clamp(cov_c(idx(a), idx(b)) / std::sqrt(va * vb), -1.0, 1.0);
}

double FitResult::cdf(Term t, double value) const {
  const int i = idx(t);
  if (!coef[static_cast<std::size_t>(i)].enabled) return value >= 0 ? 1.0 : 0.0;
  if (!(value > 0)) return 0.0;
  if (!std::isfinite(value)) return 1.0;
  const Problem pr = make_problem(used, options);
  Vec5 d_hat;
  for (int k = 0; k < P; ++k) d_hat[k] = c[k] / pr.scale[k];
  const Profiler prof{pr, d_hat, deviance};
  const double v = c_from_coefficient(t, value) / pr.scale[i];
  const double dd = prof.delta(i, v);
  const double r = std::sqrt(dd / phi[static_cast<std::size_t>(i)]);
  return normal_cdf(v >= d_hat[i] ? r : -r);
}

namespace {

/// Upper confidence root of term i on the scale t = √d, given a finished fit.
double upper_root(const Profiler& prof, int i, double t_hat, double step, double thr) {
  auto g = [&](double t) { return std::sqrt(prof.delta(i, t * t)) - std::sqrt(thr); };
  if (!(step > 0)) step = std::max(t_hat, 1.0);
  double t_hi = t_hat + step;
  double g_hi = g(t_hi);
  for (int k = 0; k < 200 && !(g_hi > 0); ++k) {
    t_hi = t_hat + (t_hi - t_hat) * 2.0;
    g_hi = g(t_hi);
  }
  if (!(g_hi > 0)) return kInf;
  return find_root(g, t_hat, -std::sqrt(thr), t_hi, g_hi);
}

/// Fisher-scale step of term i for bracketing its upper bound: √(z·sd(d_i)) at d_i = 0.
double fisher_step(const Eigen::MatrixXd& info, int i, double z, double dispersion) {
  return info(i, i) > 0 ? std::sqrt(z * std::sqrt(dispersion / info(i, i))) : 0.0;
}

Eigen::MatrixXd fisher_info(const Problem& pr, const Eigen::VectorXd& mu) {
  const Eigen::VectorXd wf = pr.nu.array() / (2.0 * mu.array().square());
  return pr.g.transpose() * (pr.g.array().colwise() * wf.array()).matrix();
}

}  // namespace

namespace {

/// Covariance of the fit-scale estimates: sandwich I⁻¹ (GᵀWΣWG) I⁻¹ over the terms in `set`, and
/// each term's inflation over the independent-points I⁻¹. Σ is the covariance of the AV points
/// (empty: independent with variance 2μ²/ν, where the sandwich equals I⁻¹).
struct Sandwich {
  Eigen::MatrixXd cov;      // over `set`, scaled parameters
  std::vector<double> phi;  // per member of `set`
  std::vector<double> extra;  // the part of phi beyond the sandwich ratio (small-EDF factor)
};

Sandwich sandwich(const Problem& pr, const Eigen::VectorXd& mu, const std::vector<int>& set,
                  const Eigen::MatrixXd& sigma_y) {
  Sandwich sw;
  const auto k = static_cast<Eigen::Index>(set.size());
  if (k == 0) return sw;
  Eigen::MatrixXd g(pr.g.rows(), k);
  for (Eigen::Index q = 0; q < k; ++q) g.col(q) = pr.g.col(set[static_cast<std::size_t>(q)]);
  const Eigen::VectorXd w = pr.nu.array() / (2.0 * mu.array().square());
  const Eigen::MatrixXd gw = g.array().colwise() * w.array();
  const Eigen::MatrixXd info = g.transpose() * gw;
  const Eigen::MatrixXd inv = info.inverse();
  if (sigma_y.size() == 0) {
    sw.cov = inv;
  } else {
    const Eigen::MatrixXd meat = gw.transpose() * sigma_y * gw;
    sw.cov = inv * meat * inv;
  }
  for (Eigen::Index q = 0; q < k; ++q) {
    const double r = inv(q, q) > 0 ? sw.cov(q, q) / inv(q, q) : 1.0;
    sw.phi.push_back(std::isfinite(r) && r > 0 ? r : 1.0);
  }
  return sw;
}

/// "No floor": the EDF cap used when the residuals call for none.
constexpr double kNoFloor = 1e12;
/// The largest estimated floor: a relative uncertainty of √(2/10⁴) = 1.4 % on σ² (the data then
/// depart from the five-term model far more than any floor can describe; χ²/dof says so).
constexpr double kMinCap = 1e4;

/// The model-error floor as an EDF cap 2/s²: s² ≥ 0 solves Σ r²/(2/ν + s²) = J − p for the
/// relative residuals r = (σ̂² − μ)/μ (Paule–Mandel), none when the residuals are already within
/// their sampling scatter, at most kMinCap's. The points' correlation is ignored here (positively
/// correlated points scatter less about a fit than independent ones, so this errs towards no floor).
double model_error_cap(const Problem& pr, const Eigen::VectorXd& mu, int p) {
  const auto j = pr.y.size();
  const double target = static_cast<double>(std::max<Eigen::Index>(1, j - p));
  auto x2 = [&](double s2) {
    double x = 0;
    for (Eigen::Index r = 0; r < j; ++r) {
      const double q = (pr.y[r] - mu[r]) / mu[r];
      x += q * q / (2.0 / pr.nu[r] + s2);
    }
    return x;
  };
  if (!(x2(0.0) > target)) return kNoFloor;
  double lo = 0, hi = 1e-6;
  while (x2(hi) > target && hi < 1e6) hi *= 4;
  for (int it = 0; it < 100; ++it) {
    const double m = 0.5 * (lo + hi);
    (x2(m) > target ? lo : hi) = m;
  }
  return std::clamp(2.0 / hi, kMinCap, kNoFloor);
}

/// Σ_y: the model covariance of the points plus the model-error floor 2μ²/edf_cap on the diagonal.
Eigen::MatrixXd point_covariance(std::span<const FitPoint> pts, const Vec5& c, const Eigen::VectorXd& mu,
                                 double edf_cap, unsigned threads) {
  Eigen::MatrixXd s = av_covariance(pts, c, false, threads);
  if (edf_cap > 0)
    for (Eigen::Index r = 0; r < s.rows(); ++r) s(r, r) += 2.0 * mu[r] * mu[r] / edf_cap;
  return s;
}

}  // namespace

Eigen::MatrixXd av_covariance(std::span<const FitPoint> pts, const Eigen::Matrix<double, kTermCount, 1>& c) {
  return av_covariance(pts, c, false, 1);
}

Eigen::MatrixXd av_covariance(std::span<const FitPoint> pts, const Eigen::Matrix<double, kTermCount, 1>& c,
                              bool diagonal_only, unsigned threads) {
  const auto j = static_cast<Eigen::Index>(pts.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(j, j);
  if (j == 0) return cov;
  const double tau0 = pts[0].tau_s / static_cast<double>(pts[0].m);
  const double cq = c[0];
  // Generalized structure function of the continuous terms, ″², at lag u samples.
  auto s_cont = [&](double u) {
    if (u <= 0) return 0.0;
    const double t = u * tau0;
    return c[1] * t - c[2] / std::numbers::pi * t * t * std::log(t) - c[3] * t * t * t / 6.0;
  };
  constexpr std::array<double, 3> kw{1.0, -2.0, 1.0};
  // Row a of the upper triangle; rows go to the threads alternately (row a has j − a entries).
  auto row = [&](Eigen::Index a, std::vector<double>& centres, std::vector<double>& weights) {
    for (Eigen::Index b = a; b < (diagonal_only ? a + 1 : j); ++b) {
      const auto& pa = pts[static_cast<std::size_t>(a)];
      const auto& pb = pts[static_cast<std::size_t>(b)];
      const std::int64_t ma = pa.m, mb = pb.m, na = pa.terms, nb = pb.terms;
      if (ma <= 0 || mb <= 0 || na <= 0 || nb <= 0) continue;
      const std::int64_t mn = std::min(ma, mb), mx = std::max(ma, mb);
      const std::array<std::int64_t, 3> oa{0, ma, 2 * ma}, ob{0, mb, 2 * mb};
      // Cov(z^a_i, z^b_{i+h}) = −½ Σ a_k b_l S(o_k − h − p_l), continuous part.
      auto gamma_c = [&](double h) {
        double g = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l)
            g += kw[static_cast<std::size_t>(k)] * kw[static_cast<std::size_t>(l)] *
                 s_cont(std::abs(static_cast<double>(oa[static_cast<std::size_t>(k)]) - h -
                                 static_cast<double>(ob[static_cast<std::size_t>(l)])));
        return -0.5 * g;
      };
      auto count = [&](double h) {
        const double hi = std::min(static_cast<double>(na), static_cast<double>(nb) - h);
        const double lo = std::max(0.0, -h);
        return std::max(0.0, hi - lo);
      };
      // Σ_h count(h)·γ(h)² over the integer lags. γ is smooth between its kinks h = o_k − p_l
      // (where a structure-function argument crosses 0) and varies there on the scale of the
      // smaller cluster, farther away on the scale of the distance to the nearest kink. So each
      // stretch between kinks is summed with blocks that are single lags (or mn/16) next to a
      // kink and grow geometrically towards the middle of the stretch; each block contributes
      // its length times the summand at its centre. Pairs of any τ ratio are covered (the
      // correlation of white-angle-dominated points decays slowly with the ratio).
      const std::int64_t lo = -(2 * mb + 4 * mx), hi = 2 * ma + 4 * mx + 1;
      std::array<std::int64_t, 11> knots{};
      int nk = 0;
      knots[static_cast<std::size_t>(nk++)] = lo;
      knots[static_cast<std::size_t>(nk++)] = hi;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) knots[static_cast<std::size_t>(nk++)] = oa[static_cast<std::size_t>(k)] - ob[static_cast<std::size_t>(l)];
      std::sort(knots.begin(), knots.begin() + nk);
      const std::int64_t s0 = std::max<std::int64_t>(1, mn / 16);
      // Each block contributes its length times the summand at its centre; the centres and
      // weights are gathered first and γ² summed over them in one vectorised pass.
      centres.clear();
      weights.clear();
      auto block = [&](std::int64_t start, std::int64_t len) {
        const double hc = static_cast<double>(start) + 0.5 * static_cast<double>(len - 1);
        const double wc = static_cast<double>(len) * count(hc);
        if (wc > 0) {
          centres.push_back(hc);
          weights.push_back(wc);
        }
      };
      double total = 0;
      for (int q = 0; q + 1 < nk; ++q) {
        const std::int64_t left = knots[static_cast<std::size_t>(q)], right = knots[static_cast<std::size_t>(q + 1)];
        if (right <= left) continue;
        // Lags left .. right−1, graded towards both ends.
        const std::int64_t mid = left + (right - left) / 2;
        for (std::int64_t h = left; h < mid;) {
          const std::int64_t len = std::min(mid - h, std::max(s0, (h - left) / 4));
          block(h, len);
          h += len;
        }
        for (std::int64_t h = right; h > mid;) {
          const std::int64_t len = std::min(h - mid, std::max(s0, (right - h) / 4));
          block(h - len, len);
          h -= len;
        }
      }
      {
        detail::GammaPair gp;
        gp.tau0 = tau0;
        gp.c1 = c[1];
        gp.c2 = c[2];
        gp.c3 = c[3];
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            const auto q = static_cast<std::size_t>(3 * k + l);
            gp.d[q] = static_cast<double>(oa[static_cast<std::size_t>(k)] - ob[static_cast<std::size_t>(l)]);
            gp.w[q] = kw[static_cast<std::size_t>(k)] * kw[static_cast<std::size_t>(l)];
          }
        total += detail::gamma_sq_sum(gp, centres.data(), weights.data(), centres.size());
      }
      // White angle noise: exact additions at the few lags where sample indices coincide.
      if (cq > 0) {
        std::array<std::int64_t, 9> lags{};
        int nl = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            const std::int64_t h = oa[static_cast<std::size_t>(k)] - ob[static_cast<std::size_t>(l)];
            if (std::find(lags.begin(), lags.begin() + nl, h) == lags.begin() + nl) lags[static_cast<std::size_t>(nl++)] = h;
          }
        for (int q = 0; q < nl; ++q) {
          const std::int64_t h = lags[static_cast<std::size_t>(q)];
          double gq = 0;
          for (int k = 0; k < 3; ++k)
            for (int l = 0; l < 3; ++l)
              if (oa[static_cast<std::size_t>(k)] == h + ob[static_cast<std::size_t>(l)])
                gq += kw[static_cast<std::size_t>(k)] * kw[static_cast<std::size_t>(l)];
          gq *= cq;
          const double hd = static_cast<double>(h);
          const double gc = gamma_c(hd);
          // The grid already holds (about) gc²; add the cross term and the Q² term.
          total += count(hd) * (2.0 * gc * gq + gq * gq);
        }
      }
      const double ta = pa.tau_s, tb = pb.tau_s;
      const double v = 2.0 * total / (4.0 * ta * ta * tb * tb * static_cast<double>(na) * static_cast<double>(nb));
      cov(a, b) = cov(b, a) = v;
    }
  };
  if (threads == 0) threads = std::thread::hardware_concurrency();
  if (threads > 1 && !diagonal_only && j >= 8) {
    Thread other([&] {
      std::vector<double> centres, weights;
      for (Eigen::Index a = 1; a < j; a += 2) row(a, centres, weights);
    });
    std::vector<double> centres, weights;
    for (Eigen::Index a = 0; a < j; a += 2) row(a, centres, weights);
  } else {
    std::vector<double> centres, weights;
    for (Eigen::Index a = 0; a < j; ++a) row(a, centres, weights);
  }
  return cov;
}

FitResult fit_noise(std::span<const FitPoint> points, const FitOptions& options) {
  if (!(options.dispersion > 0) || !(options.confidence > 0 && options.confidence < 1) ||
      !(options.edf_cap >= 0) || !(options.edf_inflation >= 0))
    throw UsageError("fit options: dispersion and EDF cap must be positive, confidence in (0, 1)");
  FitResult res;
  int n_enabled = 0;
  for (bool e : options.enabled) n_enabled += e ? 1 : 0;
  if (n_enabled == 0) throw UsageError("fit: no term enabled");

  for (const auto& p : points) {
    if (!(p.tau_s >= options.tau_min_s && p.tau_s <= options.tau_max_s)) continue;
    if (!(p.edf >= options.min_edf)) continue;
    if (!std::isfinite(p.var) || !(p.var > 0))
      throw AnalysisError(fmt::format(
          "the Allan variance at tau = {:g} s is {:g}: the record holds no noise there (constant "
          "or perfectly regular data); no noise model can be fitted",
          p.tau_s, p.var));
    res.used.push_back(p);
  }
  std::sort(res.used.begin(), res.used.end(), [](const auto& a, const auto& b) { return a.tau_s < b.tau_s; });
  const int j = static_cast<int>(res.used.size());
  if (j < n_enabled + 1)
    throw AnalysisError(fmt::format(
        "only {} Allan-variance point(s) with at least {:g} degrees of freedom lie in the fit range "
        "{:g}..{:g} s; a fit of {} terms needs at least {} (use a longer record or a wider "
        "--fit-range)",
        j, options.min_edf, options.tau_min_s, options.tau_max_s, n_enabled, n_enabled + 1));

  const double z = normal_quantile(0.5 + options.confidence / 2.0);
  const double chi2_1 = chi2_quantile(options.confidence, 1.0);
  const bool use_cov = options.model_covariance &&
                       std::all_of(res.used.begin(), res.used.end(), [](const FitPoint& p) { return p.m > 0 && p.terms > 0; });
  res.model_covariance = use_cov;

  // 1. The full model (all enabled terms) with the estimator's own EDFs.
  Problem full_pr = make_problem(res.used, options);
  IrlsResult full = irls(full_pr, full_pr.enabled_mask, Vec5::Zero(), true);
  if (!std::isfinite(full.dev) || !full.d.allFinite()) throw AnalysisError("the noise-model fit did not converge");
  FitOptions opt = options;  // edf_cap: the one in force (estimated when options.edf_cap is 0)

  // 2. Model-based EDFs and point covariance, then the full model again.
  Eigen::MatrixXd sigma_y;
  if (use_cov) {
    Vec5 c0;
    for (int i = 0; i < P; ++i) c0[i] = full.d[i] * full_pr.scale[i];
    const Eigen::VectorXd mu0 = full_pr.g * full.d;
    const Eigen::MatrixXd cov0 = av_covariance(res.used, c0, true, 1);  // only its diagonal is used
    for (int r = 0; r < j; ++r) {
      const double v = cov0(r, r);
      if (v > 0 && std::isfinite(v)) res.used[static_cast<std::size_t>(r)].edf = 2.0 * mu0[r] * mu0[r] / v;
    }
    full_pr = make_problem(res.used, opt);
    Vec5 d1;
    for (int i = 0; i < P; ++i) d1[i] = c0[i] / full_pr.scale[i];
    full = irls(full_pr, full_pr.enabled_mask, d1, false);
    if (!std::isfinite(full.dev) || !full.d.allFinite()) throw AnalysisError("the noise-model fit did not converge");
  }
  // Model-error floor: estimated from the residuals unless fixed by the options.
  if (!(options.edf_cap > 0)) {
    opt.edf_cap = model_error_cap(full_pr, full_pr.g * full.d, std::popcount(full_pr.enabled_mask));
    if (opt.edf_cap < kNoFloor) {
      const Vec5 c_prev = full.d.cwiseProduct(full_pr.scale);
      full_pr = make_problem(res.used, opt);
      full = irls(full_pr, full_pr.enabled_mask, c_prev.cwiseQuotient(full_pr.scale), false);
      if (!std::isfinite(full.dev) || !full.d.allFinite()) throw AnalysisError("the noise-model fit did not converge");
    }
  }
  if (use_cov) {
    Vec5 c1;
    for (int i = 0; i < P; ++i) c1[i] = full.d[i] * full_pr.scale[i];
    sigma_y = point_covariance(res.used, c1, full_pr.g * full.d, opt.edf_cap, options.threads);
  }
  auto phis = [&](const Problem& pr, const IrlsResult& fit, const std::vector<int>& set) {
    Sandwich sw = sandwich(pr, pr.g * fit.d, set, sigma_y);
    // Each term's inflation: the sandwich ratio times the small-EDF factor 1 + a/ν_i, ν_i the
    // term's own effective EDF 2ĉ²/Var(ĉ) (at most 1 + a: a term at the boundary).
    for (std::size_t q = 0; q < set.size(); ++q) {
      const int i = set[q];
      const double v = sw.cov(static_cast<Eigen::Index>(q), static_cast<Eigen::Index>(q));
      const double nu = v > 0 ? 2.0 * fit.d[i] * fit.d[i] / v : 0.0;
      const double f = options.dispersion * (1.0 + options.edf_inflation / std::max(nu, 1.0));
      sw.phi[q] *= f;
      sw.extra.push_back(f);
    }
    return sw;
  };

  // Inflation of every enabled term in the full model (at the boundary too).
  std::vector<int> full_set;
  for (int i = 0; i < P; ++i)
    if (options.enabled[static_cast<std::size_t>(i)]) full_set.push_back(i);
  const Sandwich sw_full = phis(full_pr, full, full_set);
  std::array<double, P> phi_full{1, 1, 1, 1, 1};
  for (std::size_t q = 0; q < full_set.size(); ++q)
    phi_full[static_cast<std::size_t>(full_set[q])] = sw_full.phi[q];

  // 3. Term selection: a droppable term whose removal raises the scaled deviance by less than the
  //    χ²₁ quantile is left out of the model; it is reported as an upper bound from the full model.
  FitOptions final_opt = opt;
  IrlsResult best = full;
  std::array<bool, P> dropped{};
  if (options.select_terms) {
    for (int i : {idx(Term::R), idx(Term::K), idx(Term::Q)}) {
      if (!final_opt.enabled[static_cast<std::size_t>(i)] || !options.droppable[static_cast<std::size_t>(i)]) continue;
      FitOptions trial = final_opt;
      trial.enabled[static_cast<std::size_t>(i)] = false;
      const Problem tp = make_problem(res.used, trial);
      Vec5 start = best.d;  // column scales do not depend on the enabled terms
      start[i] = 0;
      const IrlsResult r = irls(tp, tp.enabled_mask, start, false);
      if (std::isfinite(r.dev) && (r.dev - best.dev) / phi_full[static_cast<std::size_t>(i)] < chi2_1) {
        final_opt = trial;
        best = r;
        dropped[static_cast<std::size_t>(i)] = true;
      }
    }
  }
  res.options = final_opt;

  const Problem pr = make_problem(res.used, final_opt);
  best = irls(pr, pr.enabled_mask, best.d, false);
  if (!std::isfinite(best.dev) || !best.d.allFinite()) throw AnalysisError("the noise-model fit did not converge");
  res.iterations = best.iterations + full.iterations;
  res.deviance = best.dev;
  for (int i = 0; i < P; ++i) res.c[i] = best.d[i] * pr.scale[i];
  const Eigen::VectorXd mu = pr.g * best.d;
  res.model.assign(mu.data(), mu.data() + mu.size());

  // Goodness of fit (points taken as independent with their EDFs; see docs).
  int active = 0;
  for (int i = 0; i < P; ++i) active += best.d[i] > 0 ? 1 : 0;
  res.dof = j - active;
  double chi2 = 0;
  for (int r = 0; r < j; ++r) {
    const double q = pr.y[r] / mu[r];
    chi2 += pr.nu[r] * (q - 1.0 - std::log(q)) / bartlett(pr.nu[r]);
  }
  res.chi2 = chi2;
  res.chi2_per_dof = res.dof > 0 ? chi2 / res.dof : 0.0;
  res.p_value = res.dof > 0
                    ? boost::math::cdf(boost::math::complement(
                          boost::math::chi_squared_distribution<double>(res.dof), chi2))
                    : 1.0;

  // Covariance of the active terms (sandwich) and each term's inflation.
  std::vector<int> act;
  for (int i = 0; i < P; ++i)
    if (best.d[i] > 0) act.push_back(i);
  res.cov_c.setZero();
  const Sandwich sw = phis(pr, best, act);
  for (std::size_t r = 0; r < act.size(); ++r) {
    res.phi[static_cast<std::size_t>(act[r])] = sw.phi[r];
    for (std::size_t q = 0; q < act.size(); ++q)
      res.cov_c(act[r], act[q]) = sw.cov(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(q)) *
                                  std::sqrt(sw.extra[r] * sw.extra[q]) * pr.scale[act[r]] * pr.scale[act[q]];
  }
  // Terms at the boundary in the selected model: inflation from the model with the term added.
  for (int i = 0; i < P; ++i) {
    if (best.d[i] > 0 || !final_opt.enabled[static_cast<std::size_t>(i)]) {
      if (dropped[static_cast<std::size_t>(i)]) res.phi[static_cast<std::size_t>(i)] = phi_full[static_cast<std::size_t>(i)];
      continue;
    }
    std::vector<int> set = act;
    set.push_back(i);
    const Sandwich s1 = phis(pr, best, set);
    res.phi[static_cast<std::size_t>(i)] = s1.phi.back();
  }
  res.corr_NQ = res.log_correlation(Term::N, Term::Q);
  res.corr_NB = res.log_correlation(Term::N, Term::B);

  // 4. Profile-likelihood intervals on the coefficient scale t = √d.
  const Profiler prof{pr, best.d, best.dev};
  const Eigen::MatrixXd info_all = fisher_info(pr, mu);
  const Eigen::MatrixXd info_full = fisher_info(full_pr, full_pr.g * full.d);
  const Profiler prof_full{full_pr, full.d, full.dev};
  for (int i = 0; i < P; ++i) {
    auto& co = res.coef[static_cast<std::size_t>(i)];
    const Term term = kAllTerms[static_cast<std::size_t>(i)];
    co.enabled = options.enabled[static_cast<std::size_t>(i)];
    co.in_model = final_opt.enabled[static_cast<std::size_t>(i)];
    if (!co.enabled) continue;
    const double phi = res.phi[static_cast<std::size_t>(i)];
    const double thr = phi * chi2_1;
    if (dropped[static_cast<std::size_t>(i)]) {
      // Upper bound from the full model's profile.
      const double kf = kCoefScale[static_cast<std::size_t>(i)] * std::sqrt(full_pr.scale[i]);
      const double t_hat = std::sqrt(full.d[i]);
      const double t_up = upper_root(prof_full, i, t_hat, std::max(fisher_step(info_full, i, z, phi), t_hat), thr);
      co.resolved = false;
      co.estimate = kf * t_hat;
      co.low = 0;
      co.high = kf * t_up;
      co.value = co.high;
      co.sigma = co.high / (2.0 * z);
    } else {
      const double kf = kCoefScale[static_cast<std::size_t>(i)] * std::sqrt(pr.scale[i]);  // coefficient = kf·t
      const double t_hat = std::sqrt(best.d[i]);
      auto g = [&](double t) { return std::sqrt(prof.delta(i, t * t)) - std::sqrt(thr); };
      double t_low = 0;
      co.resolved = false;
      if (t_hat > 0) {
        const double g0 = g(0.0);
        if (g0 > 0) {
          t_low = find_root(g, 0.0, g0, t_hat, -std::sqrt(thr));
          co.resolved = true;
        }
      }
      double step = fisher_step(info_all, i, z, phi);
      if (t_hat > 0 && res.cov_c(i, i) > 0)
        step = std::max(step, z * std::sqrt(res.cov_c(i, i)) / pr.scale[i] / (2.0 * t_hat));
      const double t_up = upper_root(prof, i, t_hat, step, thr);
      co.estimate = kf * t_hat;
      co.low = co.resolved ? kf * t_low : 0.0;
      co.high = kf * t_up;
      if (co.resolved) {
        co.value = co.estimate;
        // Delta method: coefficient = k√c → sd = k·sd(c)/(2√c).
        co.sigma = kCoefScale[static_cast<std::size_t>(i)] * std::sqrt(res.cov_c(i, i)) / (2.0 * std::sqrt(res.c[i]));
      } else {
        co.value = co.high;
        co.sigma = co.high / (2.0 * z);
      }
    }
    if (!std::isfinite(co.value) || !std::isfinite(co.sigma) || !std::isfinite(co.low) || !std::isfinite(co.high))
      throw AnalysisError(fmt::format("the data do not bound the {} coefficient", term_name(term)));
  }
  return res;
}

SlopeReadout slope_readout(const AllanResult& allan) {
  SlopeReadout s;
  const auto& p = allan.points;
  std::size_t imin = 0;
  bool any = false;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!(p[k].dev > 0)) continue;
    if (!any || p[k].dev < p[imin].dev) imin = k;
    any = true;
  }
  if (!any) return s;
  s.sigma_min = p[imin].dev;
  s.tau_min_s = p[imin].tau_s;
  s.B = s.sigma_min / std::sqrt(kFlickerFactor);

  double best_n = 0.25;
  double best_k = 0.25;
  for (std::size_t k = 0; k + 1 < p.size(); ++k) {
    if (!(p[k].dev > 0) || !(p[k + 1].dev > 0)) continue;
    const double slope = std::log(p[k + 1].dev / p[k].dev) / std::log(p[k + 1].tau_s / p[k].tau_s);
    const double tau = std::sqrt(p[k].tau_s * p[k + 1].tau_s);
    const double sig = std::sqrt(p[k].dev * p[k + 1].dev);
    if (std::abs(slope + 0.5) <= best_n) {
      best_n = std::abs(slope + 0.5);
      s.N = sig * std::sqrt(tau / 3600.0);
      s.tau_N_s = tau;
    }
    if (std::abs(slope - 0.5) <= best_k) {
      best_k = std::abs(slope - 0.5);
      s.K = sig * std::sqrt(3.0 * 3600.0 / tau);
      s.tau_K_s = tau;
    }
  }
  return s;
}

}  // namespace rwcalc
