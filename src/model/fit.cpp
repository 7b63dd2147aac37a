// Gamma-deviance (scaled-χ² likelihood) fit of the five-term IEEE 952 model with non-negative
// squared coefficients, profile-likelihood intervals and the classic slope-line readout.
#include "rwcalc/fit.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <tuple>
#include <utility>

#include "rwcalc/deviance.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/nnls.hpp"
#include "rwcalc/parallel.hpp"

namespace rwcalc {

namespace {

constexpr int P = kTermCount;
using Vec5 = Eigen::Matrix<double, P, 1>;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// AV of flicker per B²: 2 ln2/π.
constexpr double kFlickerFactor = 2.0 * std::numbers::ln2 / std::numbers::pi;
/// Coefficient = kCoefScale·√c (c in s-based units, coefficients in h-based units).
constexpr std::array<double, P> kCoefScale{1.0, 1.0 / 60.0, 1.0, 60.0, 3600.0};

int idx(Term t) { return static_cast<int>(t); }

/// The terms that jitter the angle about its mean-rate line (counter_readout.hpp).
AngleJitter jitter_of(const Vec5& c) { return {c[idx(Term::Q)], c[idx(Term::N)], c[idx(Term::B)]}; }

/// A counter's read-out AV at the points: not a linear term, as the angle's jitter (from Q, N, B)
/// smooths its sawtooth.
struct CounterPart {
  CounterReadout counter;
  std::vector<std::int64_t> m;  // cluster sizes of the points
  [[nodiscard]] Eigen::VectorXd at(const Vec5& c) const {
    Eigen::VectorXd v(static_cast<Eigen::Index>(m.size()));
    for (std::size_t r = 0; r < m.size(); ++r)
      v[static_cast<Eigen::Index>(r)] = counter_avar(counter, m[r], jitter_of(c));
    return v;
  }
};

/// The problem in scaled parameters d = c / scale (columns of comparable size).
struct Problem {
  Eigen::MatrixXd g;       // J×P: basis_i(τ_j)·scale_i
  Eigen::VectorXd y;       // observed σ²
  Eigen::VectorXd nu;      // effective EDF
  Eigen::VectorXd offset;  // the part of the model linearised away (see linearised); 0 for the five terms
  std::shared_ptr<const CounterPart> counter;  // the counter read-out (FitOptions::readout), or none
  Vec5 scale = Vec5::Ones();
  unsigned enabled_mask = 0;
  int max_iterations = 300;  // FitOptions::max_iterations
};

Problem make_problem(std::span<const FitPoint> pts, const FitOptions& o) {
  Problem pr;
  pr.max_iterations = o.max_iterations;
  const auto j = static_cast<Eigen::Index>(pts.size());
  pr.g.resize(j, P);
  pr.y.resize(j);
  pr.nu.resize(j);
  pr.offset = Eigen::VectorXd::Zero(j);
  if (o.counter && o.readout == Readout::Counter) {
    auto part = std::make_shared<CounterPart>();
    part->counter = *o.counter;
    for (const FitPoint& p : pts) part->m.push_back(p.m > 0 ? p.m : std::llround(p.tau_s / o.counter->tau0_s));
    pr.counter = std::move(part);
  }
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

/// Model σ² at the points: the linear terms plus the counter's read-out.
Eigen::VectorXd mean_of(const Problem& pr, const Vec5& d) {
  Eigen::VectorXd mu = pr.g * d + pr.offset;
  if (pr.counter) mu += pr.counter->at(d.cwiseProduct(pr.scale));
  return mu;
}

/// The design at d: the basis plus the counter read-out's derivatives (forward differences in the
/// jitter's terms Q, N, B; its AV is smooth in them).
Eigen::MatrixXd design_at(const Problem& pr, const Vec5& d) {
  if (!pr.counter) return pr.g;
  Eigen::MatrixXd g = pr.g;
  const Eigen::VectorXd k0 = pr.counter->at(d.cwiseProduct(pr.scale));
  for (const Term t : {Term::Q, Term::N, Term::B}) {
    const int i = idx(t);
    Vec5 dh = d;
    const double h = 1e-5 * std::max(d[i], 1e-3);
    dh[i] += h;
    g.col(i) += (pr.counter->at(dh.cwiseProduct(pr.scale)) - k0) / h;
  }
  return g;
}

/// The counter's AV is computed for the flicker's mean jitter, but a record holds one realisation
/// of its slow wander, which leaves a partly smoothed sawtooth (τ ≈ 1–60 s on a GL-2D-like record)
/// higher or lower: half the change of the counter's AV between no flicker jitter and twice it is
/// taken as that model error's standard deviation, (°/h)².
Eigen::VectorXd wander_error(const Problem& pr, const Vec5& d) {
  if (!pr.counter) return Eigen::VectorXd::Zero(pr.y.size());
  Vec5 none = d.cwiseProduct(pr.scale), twice = none;
  none[idx(Term::B)] = 0;
  twice[idx(Term::B)] *= 2;
  return 0.5 * (pr.counter->at(twice) - pr.counter->at(none)).cwiseAbs();
}

/// The problem linearised at d (a Gauss–Newton step of the counter's part): μ ≈ G'·d' + offset'.
Problem linearised(const Problem& pr, const Vec5& d) {
  if (!pr.counter) return pr;
  Problem lin = pr;
  lin.g = design_at(pr, d);
  lin.offset = mean_of(pr, d) - lin.g * d;
  lin.counter.reset();
  return lin;
}

double deviance(const Problem& pr, const Eigen::VectorXd& mu) {
  double d = 0;
  for (Eigen::Index r = 0; r < mu.size(); ++r) {
    if (!(mu[r] > 0)) return kInf;
    d += gamma_deviance(pr.y[r], mu[r], pr.nu[r]);
  }
  return d;
}

/// Weighted least squares min Σ w (y − G d)² over d_free ≥ 0, the other components fixed at
/// `base`.
Vec5 nnls(const Problem& pr, const Eigen::VectorXd& w, unsigned free_mask, const Vec5& base) {
  Vec5 fixed = base;
  for (int i = 0; i < P; ++i)
    if (free_mask & (1u << i)) fixed[i] = 0;
  const NnlsFit fit = rwcalc::nnls(pr.g, pr.y - pr.offset - pr.g * fixed, w, free_mask);
  for (int i = 0; i < P; ++i)
    if (free_mask & (1u << i)) fixed[i] = fit.x[i];
  return fixed;
}

struct IrlsResult {
  Vec5 d;
  double dev = kInf;
  Termination termination;
};

/// Iteratively reweighted NNLS with weights ν/μ² (Fisher scoring of the Gamma likelihood with
/// identity link) and step halving on the deviance. `start` holds the fixed components and, when
/// `from_data` is false, the starting point.
IrlsResult irls(const Problem& pr, unsigned free_mask, const Vec5& start, bool from_data) {
  IrlsResult res;
  Vec5 d = start;
  Eigen::VectorXd mu = mean_of(pr, d);
  double dev = from_data ? kInf : deviance(pr, mu);
  if (!std::isfinite(dev)) {
    const Eigen::VectorXd w = pr.nu.array() / pr.y.array().square();
    d = nnls(linearised(pr, start), w, free_mask, start);
    mu = mean_of(pr, d);
    dev = deviance(pr, mu);
    if (!std::isfinite(dev)) {
      // Positive start on the free terms, so that every model point is positive.
      for (int i = 0; i < P; ++i)
        if (free_mask & (1u << i)) d[i] = std::max(d[i], 1e-3);
      mu = mean_of(pr, d);
      dev = deviance(pr, mu);
    }
  }
  // Converged: the deviance and the parameters both settled; no progress: no step, halved down to
  // 2⁻⁵⁰, lowered the deviance while the full step still moved the parameters.
  TerminationStatus status = std::isfinite(dev) ? TerminationStatus::IterationLimit : TerminationStatus::NoProgress;
  int it = 0;
  for (; it < pr.max_iterations && std::isfinite(dev); ++it) {
    const Eigen::VectorXd w = pr.nu.array() / mu.array().square();
    const Vec5 d_new = nnls(linearised(pr, d), w, free_mask, d);
    double step = 1.0;
    Vec5 d_try = d_new;
    Eigen::VectorXd mu_try = mean_of(pr, d_try);
    double dev_try = deviance(pr, mu_try);
    for (int h = 0; h < 50 && !(dev_try <= dev); ++h) {
      step *= 0.5;
      d_try = d + step * (d_new - d);
      mu_try = mean_of(pr, d_try);
      dev_try = deviance(pr, mu_try);
    }
    if (!(dev_try <= dev)) {
      // At the optimum the full step only rounds: it moves the parameters less than the test allows.
      const bool settled = (d_new - d).norm() / (1e-300 + d.norm()) < 1e-7;
      status = settled ? TerminationStatus::Converged : TerminationStatus::NoProgress;
      ++it;
      break;
    }
    const double gain = dev - dev_try;
    const double move = (d_try - d).norm() / (1e-300 + d_try.norm());
    d = d_try;
    mu = mu_try;
    dev = dev_try;
    if (gain <= 1e-12 * (1.0 + dev) && move < 1e-7) {
      status = TerminationStatus::Converged;
      ++it;
      break;
    }
  }
  res.d = d;
  res.dev = dev;
  res.termination = {status, it};
  return res;
}

/// Illinois false position for f(a)·f(b) < 0; returns the root to a relative tolerance, adding its
/// iterations (and the limit, when it takes all 100) to `t`.
template <class F>
double find_root(F&& f, double a, double fa, double b, double fb, Termination& t) {
  double c = b;
  int side = 0;
  int it = 0;
  auto done = [&](TerminationStatus s) {
    t = combine(t, {s, it});
    return c;
  };
  for (; it < 100; ++it) {
    c = (a * fb - b * fa) / (fb - fa);
    if (!std::isfinite(c)) c = 0.5 * (a + b);
    const double fc = f(c);
    if (fc == 0 || std::abs(b - a) <= 1e-6 * std::max(std::abs(a), std::abs(b))) {
      ++it;
      return done(TerminationStatus::Converged);
    }
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
    if (std::abs(b - a) <= 1e-6 * std::max(std::abs(a), std::abs(b))) {
      ++it;
      return done(TerminationStatus::Converged);
    }
  }
  return done(TerminationStatus::IterationLimit);
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

/// Upper confidence root of term i on the scale t = √d, given a finished fit.
double upper_root(const Profiler& prof, int i, double t_hat, double step, double thr, Termination& search) {
  auto g = [&](double t) { return std::sqrt(prof.delta(i, t * t)) - std::sqrt(thr); };
  if (!(step > 0)) step = std::max(t_hat, 1.0);
  double t_hi = t_hat + step;
  double g_hi = g(t_hi);
  for (int k = 0; k < 200 && !(g_hi > 0); ++k) {
    t_hi = t_hat + (t_hi - t_hat) * 2.0;
    g_hi = g(t_hi);
  }
  if (!(g_hi > 0)) return kInf;
  return find_root(g, t_hat, -std::sqrt(thr), t_hi, g_hi, search);
}

/// Fisher-scale step of term i for bracketing its upper bound: √(z·sd(d_i)) at d_i = 0.
double fisher_step(const Problem& pr, const Eigen::VectorXd& mu, int i, double z, double dispersion) {
  const Eigen::VectorXd wf = pr.nu.array() / (2.0 * mu.array().square());
  const Eigen::MatrixXd info = pr.g.transpose() * (pr.g.array().colwise() * wf.array()).matrix();
  return info(i, i) > 0 ? std::sqrt(z * std::sqrt(dispersion / info(i, i))) : 0.0;
}

/// Sandwich covariance I⁻¹(GᵀWΣWG)I⁻¹ over the terms in `set` (Σ empty: I⁻¹), and each term's
/// inflation: the ratio to I⁻¹ times dispersion·(1 + a/ν_i), ν_i = 2ĉ²/Var(ĉ).
struct Sandwich {
  Eigen::MatrixXd cov;        // over `set`, scaled parameters
  std::vector<double> phi;    // per member of `set`
  std::vector<double> extra;  // the part of phi beyond the sandwich ratio (small-EDF factor)
};

Sandwich sandwich(const Problem& pr, const Vec5& d, const std::vector<int>& set, const Eigen::MatrixXd& sigma_y,
                  const FitOptions& options) {
  Sandwich sw;
  const auto k = static_cast<Eigen::Index>(set.size());
  if (k == 0) return sw;
  const Eigen::VectorXd mu = mean_of(pr, d);
  const Eigen::MatrixXd design = design_at(pr, d);
  Eigen::MatrixXd g(pr.g.rows(), k);
  for (Eigen::Index q = 0; q < k; ++q) g.col(q) = design.col(set[static_cast<std::size_t>(q)]);
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
    const double v = sw.cov(q, q);
    const int i = set[static_cast<std::size_t>(q)];
    const double nu = v > 0 ? 2.0 * d[i] * d[i] / v : 0.0;
    const double f = options.dispersion * (1.0 + options.edf_inflation / std::max(nu, 1.0));
    sw.phi.push_back((std::isfinite(r) && r > 0 ? r : 1.0) * f);
    sw.extra.push_back(f);
  }
  return sw;
}

/// "No floor": the EDF cap used when the residuals call for none.
constexpr double kNoFloor = 1e12;
/// The largest estimated floor: a relative uncertainty of √(2/10⁴) = 1.4 % on σ² (the data then
/// depart from the five-term model far more than any floor can describe; χ²/dof says so).
constexpr double kMinCap = 1e4;

/// The model-error floor as an EDF cap 2/s²: s² ≥ 0 solves Σ r²/(2/ν + s²) = J − p for the
/// relative residuals r = (σ̂² − μ)/μ (Paule–Mandel); none when they are within their scatter.
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
                                 double edf_cap) {
  Eigen::MatrixXd s = av_covariance(pts, c);
  if (edf_cap > 0)
    for (Eigen::Index r = 0; r < s.rows(); ++r) s(r, r) += 2.0 * mu[r] * mu[r] / edf_cap;
  return s;
}

/// The coefficients whose Gaussian covariance stands for the points' sampling variance: a counter's
/// read-out error counts as white angle noise of its mean level q²/12 (its sawtooth varies less,
/// its blurred part as much).
Vec5 covariance_terms(Vec5 c, const FitOptions& o) {
  if (o.counter && o.readout == Readout::Counter) c[idx(Term::Q)] += o.counter->q_arcsec * o.counter->q_arcsec / 12.0;
  return c;
}

/// One fitted problem: its design and the IRLS optimum.
struct Stage {
  Problem pr;
  IrlsResult fit;
  [[nodiscard]] Vec5 coefficients() const { return fit.d.cwiseProduct(pr.scale); }
  [[nodiscard]] Eigen::VectorXd model() const { return mean_of(pr, fit.d); }
};

void require_converged(const IrlsResult& r) {
  if (!std::isfinite(r.dev) || !r.d.allFinite()) throw AnalysisError(tr("the noise-model fit did not converge"));
}

/// The points in the fit range with enough EDF, τ ascending; throws when too few remain.
std::vector<FitPoint> points_in_range(std::span<const FitPoint> points, const FitOptions& options) {
  require_valid(options);
  int n_enabled = 0;
  for (bool e : options.enabled) n_enabled += e ? 1 : 0;
  std::vector<FitPoint> used;
  for (const auto& p : points) {
    if (!(p.tau_s >= options.tau_min_s && p.tau_s <= options.tau_max_s)) continue;
    if (!(p.edf >= options.min_edf)) continue;
    if (!std::isfinite(p.var) || !(p.var > 0))
      throw AnalysisError(
          trf("the Allan variance at tau = {:g} s is {:g}: the record holds no noise there (constant "
              "or perfectly regular data); no noise model can be fitted",
              p.tau_s, p.var));
    used.push_back(p);
  }
  std::sort(used.begin(), used.end(), [](const auto& a, const auto& b) { return a.tau_s < b.tau_s; });
  const int j = static_cast<int>(used.size());
  if (j < n_enabled + 1)
    throw AnalysisError(
        trf("only {} Allan-variance point(s) with at least {:g} degrees of freedom lie in the fit range "
            "{:g}..{:g} s; a fit of {} terms needs at least {} (use a longer record or a wider "
            "--fit-range)",
            j, options.min_edf, options.tau_min_s, options.tau_max_s, n_enabled, n_enabled + 1));
  return used;
}

/// The full model with the estimator's EDFs; with the model covariance, again with the model's
/// EDFs (written into `used`); then again with the model-error floor (opt.edf_cap).
Stage fit_full_model(std::vector<FitPoint>& used, const FitOptions& options, bool use_cov, FitOptions& opt) {
  opt = options;
  Stage full{make_problem(used, options), {}};
  full.fit = irls(full.pr, full.pr.enabled_mask, Vec5::Zero(), true);
  require_converged(full.fit);
  if (use_cov) {
    const Vec5 c0 = full.coefficients();
    const Eigen::VectorXd mu0 = full.model();
    const Eigen::MatrixXd cov0 = av_covariance(used, covariance_terms(c0, options), true);  // its diagonal
    const Eigen::VectorXd wander = wander_error(full.pr, full.fit.d);
    for (std::size_t r = 0; r < used.size(); ++r) {
      const auto er = static_cast<Eigen::Index>(r);
      const double v = cov0(er, er) + wander[er] * wander[er];
      if (v > 0 && std::isfinite(v))
        used[r].edf = 2.0 * mu0[static_cast<Eigen::Index>(r)] * mu0[static_cast<Eigen::Index>(r)] / v;
    }
    full.pr = make_problem(used, opt);
    full.fit = irls(full.pr, full.pr.enabled_mask, c0.cwiseQuotient(full.pr.scale), false);
    require_converged(full.fit);
  }
  if (!(options.edf_cap > 0)) {
    opt.edf_cap = model_error_cap(full.pr, full.model(), std::popcount(full.pr.enabled_mask));
    if (opt.edf_cap < kNoFloor) {
      const Vec5 c_prev = full.coefficients();
      full.pr = make_problem(used, opt);
      full.fit = irls(full.pr, full.pr.enabled_mask, c_prev.cwiseQuotient(full.pr.scale), false);
      require_converged(full.fit);
    }
  }
  return full;
}

/// Term selection (FitOptions::select_terms); returns the selected model's options and fit.
std::pair<FitOptions, IrlsResult> select_terms(const std::vector<FitPoint>& used, const FitOptions& opt,
                                               const IrlsResult& full, const std::array<double, P>& phi_full,
                                               double chi2_1, std::array<bool, P>& dropped) {
  FitOptions final_opt = opt;
  IrlsResult best = full;
  for (int i : {idx(Term::R), idx(Term::K), idx(Term::Q)}) {
    const auto ui = static_cast<std::size_t>(i);
    if (!final_opt.enabled[ui] || !opt.droppable[ui]) continue;
    FitOptions trial = final_opt;
    trial.enabled[ui] = false;
    const Problem tp = make_problem(used, trial);
    Vec5 start = best.d;  // column scales do not depend on the enabled terms
    start[i] = 0;
    const IrlsResult r = irls(tp, tp.enabled_mask, start, false);
    if (std::isfinite(r.dev) && (r.dev - best.dev) / phi_full[ui] < chi2_1) {
      final_opt = trial;
      best = r;
      dropped[ui] = true;
    }
  }
  return {final_opt, best};
}

/// Goodness of fit of the selected model (points taken as independent with their EDFs; see docs).
void goodness_of_fit(const Stage& st, FitResult& res) {
  int active = 0;
  for (int i = 0; i < P; ++i) active += st.fit.d[i] > 0 ? 1 : 0;
  res.dof = static_cast<int>(st.pr.y.size()) - active;
  const Eigen::VectorXd mu = st.model();
  double chi2 = 0;
  // Each deviance over its small-sample (Bartlett) mean, so that the sum is ≈ χ².
  for (Eigen::Index r = 0; r < st.pr.y.size(); ++r)
    chi2 += gamma_deviance(st.pr.y[r], mu[r], st.pr.nu[r]) / gamma_deviance_mean(st.pr.nu[r]);
  res.chi2 = chi2;
  res.chi2_per_dof = res.dof > 0 ? chi2 / res.dof : 0.0;
  const boost::math::chi_squared_distribution<double> dist(std::max(res.dof, 1));
  res.p_value = res.dof > 0 ? boost::math::cdf(boost::math::complement(dist, chi2)) : 1.0;
}

/// Covariance of the active terms (sandwich) and each term's inflation; a term at the boundary of
/// the selected model takes it from the model with the term added, a dropped one from the full model.
void term_covariance(const Stage& st, const Eigen::MatrixXd& sigma_y, const FitOptions& options,
                     const std::array<double, P>& phi_full, const std::array<bool, P>& dropped, FitResult& res) {
  std::vector<int> act;
  for (int i = 0; i < P; ++i)
    if (st.fit.d[i] > 0) act.push_back(i);
  res.cov_c.setZero();
  const Sandwich sw = sandwich(st.pr, st.fit.d, act, sigma_y, options);
  for (std::size_t r = 0; r < act.size(); ++r) {
    res.phi[static_cast<std::size_t>(act[r])] = sw.phi[r];
    for (std::size_t q = 0; q < act.size(); ++q)
      res.cov_c(act[r], act[q]) = sw.cov(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(q)) *
                                  std::sqrt(sw.extra[r] * sw.extra[q]) * st.pr.scale[act[r]] * st.pr.scale[act[q]];
  }
  for (int i = 0; i < P; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (st.fit.d[i] > 0 || !res.options.enabled[ui]) {
      if (dropped[ui]) res.phi[ui] = phi_full[ui];
      continue;
    }
    std::vector<int> set = act;
    set.push_back(i);
    res.phi[ui] = sandwich(st.pr, st.fit.d, set, sigma_y, options).phi.back();
  }
}

/// B's estimate from the set with K (stage `st`) with the signs of K and B free: one Fisher-scoring
/// step from the bounded optimum, weighted by the model `mu_w`, and its root's bias taken out with the
/// EDF read at the bounded B² (deviance.hpp); NaN where the step is singular. K's bound biases B (a K ≥ 0
/// that cannot be told from flicker takes part of B² whether or not the record has K); the step's
/// equations are linear in the data, and unbiased when their weights do not follow the data: `mu_w` is
/// the K-free set's model, as the set with K bends to its last, least certain points. The other terms
/// move where they are inside their bounds; one held at 0 stays there (Q or R below 0 would stand for
/// a filter's roll-off or a drift that are not noise; docs/term-choice.md).
double sign_free_b(const Stage& st, const Eigen::VectorXd& mu_w, const Eigen::MatrixXd& sigma_y,
                   const FitOptions& options) {
  const int ib = idx(Term::B);
  std::vector<int> set;
  for (int i = 0; i < P; ++i)
    if (options.enabled[static_cast<std::size_t>(i)] && (st.fit.d[i] > 0 || i == ib || i == idx(Term::K)))
      set.push_back(i);
  const auto k = static_cast<Eigen::Index>(set.size());
  const Eigen::MatrixXd design = design_at(st.pr, st.fit.d);
  Eigen::MatrixXd g(design.rows(), k);
  for (Eigen::Index q = 0; q < k; ++q) g.col(q) = design.col(set[static_cast<std::size_t>(q)]);
  const Eigen::VectorXd w = st.pr.nu.array() / mu_w.array().square();
  const Eigen::MatrixXd gw = g.array().colwise() * w.array();
  const Eigen::VectorXd step = (g.transpose() * gw).ldlt().solve(gw.transpose() * (st.pr.y - st.model()));
  const auto qb = static_cast<Eigen::Index>(std::find(set.begin(), set.end(), ib) - set.begin());
  const Sandwich sw = sandwich(st.pr, st.fit.d, set, sigma_y, options);
  const double sc = st.pr.scale[ib];
  const double c = (st.fit.d[ib] + step[qb]) * sc;
  const double var = sw.cov(qb, qb) * sw.extra[static_cast<std::size_t>(qb)] * sc * sc;
  if (!std::isfinite(c) || !std::isfinite(var)) return std::numeric_limits<double>::quiet_NaN();
  return kCoefScale[static_cast<std::size_t>(ib)] * mean_unbiased_root(c, var, st.fit.d[ib] * sc);
}

/// One term's profile-likelihood interval on t = √d (a dropped term: the full model's upper bound).
Coefficient coefficient_interval(int i, const Stage& sel, const Stage& full, bool dropped, const FitResult& res,
                                 double z, double chi2_1) {
  const auto ui = static_cast<std::size_t>(i);
  Coefficient co;
  co.in_model = res.options.enabled[ui];
  const double phi = res.phi[ui];
  const double thr = phi * chi2_1;
  const Stage& st = dropped ? full : sel;
  const Profiler prof{st.pr, st.fit.d, st.fit.dev};
  const double kf = kCoefScale[ui] * std::sqrt(st.pr.scale[i]);  // coefficient = kf·t
  const double t_hat = std::sqrt(st.fit.d[i]);
  // The coefficient is the square root of a fitted c, itself unbiased but noisy: √ĉ falls short by
  // E√(χ²_ν/ν) (8 % at the ν ≈ 3 of B on a 30-min record), which the estimate takes out
  // (docs/term-choice.md); the profile interval is that of √c itself.
  co.estimate = dropped ? kf * t_hat : kCoefScale[ui] * mean_unbiased_root(res.c[i], res.cov_c(i, i));
  co.curve = dropped ? 0.0 : coefficient_from_c(kAllTerms[ui], res.c[i]);
  double t_low = 0;
  if (!dropped && t_hat > 0) {
    auto g = [&](double t) { return std::sqrt(prof.delta(i, t * t)) - std::sqrt(thr); };
    const double g0 = g(0.0);
    if (g0 > 0) {
      t_low = find_root(g, 0.0, g0, t_hat, -std::sqrt(thr), co.termination);
      co.resolved = true;
    }
  }
  double step = fisher_step(st.pr, st.model(), i, z, phi);
  if (dropped)
    step = std::max(step, t_hat);
  else if (t_hat > 0 && res.cov_c(i, i) > 0)
    step = std::max(step, z * std::sqrt(res.cov_c(i, i)) / st.pr.scale[i] / (2.0 * t_hat));
  co.low = co.resolved ? kf * t_low : 0.0;
  co.high = kf * upper_root(prof, i, t_hat, step, thr, co.termination);
  co.value = co.resolved ? co.estimate : co.high;
  // Delta method for a resolved term: coefficient = k√c → sd = k·sd(c)/(2√c).
  co.sigma =
      co.resolved ? kCoefScale[ui] * std::sqrt(res.cov_c(i, i)) / (2.0 * std::sqrt(res.c[i])) : co.high / (2.0 * z);
  return co;
}

/// One term set's confidence distribution of a coefficient: Φ(sign·√(ΔD/φ)) from its scaled profile
/// deviance; a K the set leaves out is 0 (a point mass there).
double member_cdf(const FitResult& f, Term t, double value) {
  const int i = idx(t);
  const auto ui = static_cast<std::size_t>(i);
  if (!f.coef[ui].enabled || (t == Term::K && !f.options.enabled[ui])) return value >= 0 ? 1.0 : 0.0;
  if (!(value > 0)) return 0.0;
  if (!std::isfinite(value)) return 1.0;
  const Problem pr = make_problem(f.used, f.options);
  Vec5 d_hat;
  for (int k = 0; k < P; ++k) d_hat[k] = f.c[k] / pr.scale[k];
  const Profiler prof{pr, d_hat, f.deviance};
  const double v = c_from_coefficient(t, value) / pr.scale[i];
  const double dd = prof.delta(i, v);
  const double r = std::sqrt(dd / f.phi[ui]);
  return boost::math::cdf(boost::math::normal_distribution<double>(), v >= d_hat[i] ? r : -r);
}

/// The p-quantile of a confidence distribution F between a and b (F(a) ≤ p ≤ F(b)).
template <class F>
double quantile_between(F&& cdf, double p, double a, double b, Termination& t) {
  if (!(b > a)) return a;
  const double fa = cdf(a) - p, fb = cdf(b) - p;
  if (!(fa < 0)) return a;
  if (!(fb > 0)) return b;
  return find_root([&](double x) { return cdf(x) - p; }, a, fa, b, fb, t);
}

/// The coefficient of term t averaged over the two term sets with weights w and 1 − w: the mixture
/// of their confidence distributions, its quantiles for the interval and its standard deviation for
/// sigma; the estimate is given (average_over_k).
Coefficient averaged(const FitResult& avg, Term t, const Coefficient& a, const Coefficient& b, double w_b,
                     double estimate, double z) {
  Coefficient co = a;
  co.termination = combine(a.termination, b.termination);
  const double alpha = (1.0 - avg.options.confidence) / 2.0;
  auto cdf = [&](double x) { return avg.cdf(t, x); };
  co.estimate = estimate;
  co.resolved = cdf(std::numeric_limits<double>::min()) < alpha;
  co.low =
      co.resolved ? quantile_between(cdf, alpha, std::min(a.low, b.low), std::max(a.low, b.low), co.termination) : 0.0;
  co.high = quantile_between(cdf, 1.0 - alpha, std::min(a.high, b.high), std::max(a.high, b.high), co.termination);
  co.value = co.resolved ? co.estimate : co.high;
  const double mean = (1.0 - w_b) * a.estimate + w_b * b.estimate;
  const double da = a.estimate - mean, db = b.estimate - mean;
  co.sigma = co.resolved ? std::sqrt((1.0 - w_b) * (a.sigma * a.sigma + da * da) + w_b * (b.sigma * b.sigma + db * db))
                         : co.high / (2.0 * z);
  return co;
}

/// Averages `res` (the selected term set) with `other` (the same set with K toggled): weights from
/// the scaled deviances with the AIC's penalty of one parameter, w(K) = 1/(1 + e^(1 − ΔD/(2φ_K))).
/// N, B (and Q, R where both sets keep them) take the mixture of the two confidence distributions;
/// B's estimate is `b_estimate`, the set with K's sign-free one (sign_free_b: unbiased whether or not
/// the record has K; an average of the two sets' estimates is not, as its weights follow the data);
/// K is resolved only when the mixture's lower bound, which carries the K-free set's point mass at
/// 0, is above 0 (docs/term-choice.md).
void average_over_k(FitResult& res, FitResult other, double b_estimate, double phi_k, double z) {
  const auto uk = static_cast<std::size_t>(idx(Term::K));
  const bool has_k = res.options.enabled[uk];
  const double d_on = has_k ? res.deviance : other.deviance, d_off = has_k ? other.deviance : res.deviance;
  const double gain = std::max(0.0, d_off - d_on) / phi_k;
  res.k_weight = 1.0 / (1.0 + std::exp(1.0 - gain / 2.0));
  const double w_other = has_k ? 1.0 - res.k_weight : res.k_weight;
  const std::array<Coefficient, P> own = res.coef;
  res.k_alternative = std::make_shared<const FitResult>(std::move(other));
  const FitResult& alt = *res.k_alternative;
  for (int i = 0; i < P; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (i == idx(Term::K) || !own[ui].enabled || !res.options.enabled[ui] || !alt.options.enabled[ui]) continue;
    // B from the sign-free step (a singular one, where the points cannot separate the terms, leaves
    // the members' weighted mean); N, Q and R from that mean: both members fit them from the same
    // short-τ points, and the step's weights, the K-free set's, would move N where the model describes
    // the points only roughly (1–4 % on ADIS16405 accelerometer axes).
    const double estimate = i == idx(Term::B) && std::isfinite(b_estimate)
                                ? b_estimate
                                : (1.0 - w_other) * own[ui].estimate + w_other * alt.coef[ui].estimate;
    res.coef[ui] = averaged(res, kAllTerms[ui], own[ui], alt.coef[ui], w_other, estimate, z);
  }
  Coefficient& k = res.coef[uk];
  if (k.enabled && k.resolved &&
      !(res.cdf(Term::K, std::numeric_limits<double>::min()) < (1.0 - res.options.confidence) / 2.0)) {
    k.resolved = false;
    k.low = 0;
    k.value = k.high;
    k.sigma = k.high / (2.0 * z);
  }
}

}  // namespace

std::string_view term_name(Term t) {
  static constexpr std::array<std::string_view, P> n{"Q", "N", "B", "K", "R"};
  return n[static_cast<std::size_t>(idx(t))];
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

double coefficient_from_c(Term t, double c) {
  return kCoefScale[static_cast<std::size_t>(idx(t))] * std::sqrt(std::max(c, 0.0));
}

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
  double v = counter_var(tau_s);
  for (int i = 0; i < P; ++i) v += c[i] * term_basis(kAllTerms[static_cast<std::size_t>(i)], tau_s);
  return v;
}

double FitResult::counter_var(double tau_s) const {
  if (!counter_readout || !options.counter) return 0.0;
  const CounterReadout& ctr = *options.counter;
  return counter_avar(ctr, std::llround(tau_s / ctr.tau0_s), jitter_of(c));
}

double FitResult::counter_increment_var(std::int64_t h) const {
  return counter_readout && options.counter ? rwcalc::counter_increment_var(*options.counter, h, jitter_of(c)) : 0.0;
}

double FitResult::readout_var(double tau_s) const {
  return c[idx(Term::Q)] * term_basis(Term::Q, tau_s) + counter_var(tau_s);
}

Eigen::Matrix<double, kTermCount, 1> FitResult::covariance_c() const { return covariance_terms(c, options); }

double FitResult::log_correlation(Term a, Term b) const {
  const double va = cov_c(idx(a), idx(a));
  const double vb = cov_c(idx(b), idx(b));
  if (!(va > 0) || !(vb > 0)) return 0;
  return std::clamp(cov_c(idx(a), idx(b)) / std::sqrt(va * vb), -1.0, 1.0);
}

double FitResult::cdf(Term t, double value) const {
  const double own = member_cdf(*this, t, value);
  if (!k_alternative) return own;
  const double w_other = options.enabled[static_cast<std::size_t>(idx(Term::K))] ? 1.0 - k_weight : k_weight;
  return (1.0 - w_other) * own + w_other * member_cdf(*k_alternative, t, value);
}

namespace {

/// χ²₁ at 0.999: how much better the counter's fit must be to be chosen over the white one.
constexpr double kCounterMargin = 10.83;

/// What every term set fitted to one record shares: the points, the full model, the points'
/// covariance and each term's inflation in the full model.
struct FitBase {
  std::vector<FitPoint> used;
  FitOptions options;  // as given
  FitOptions opt;      // with the EDF cap in force
  Stage full;
  Eigen::MatrixXd sigma_y;
  std::array<double, P> phi_full{1, 1, 1, 1, 1};
  bool model_covariance = false;
  double z = 0, chi2_1 = 0;
};

FitBase fit_base(std::span<const FitPoint> points, const FitOptions& options) {
  FitBase b;
  b.options = options;
  b.used = points_in_range(points, options);
  b.z = boost::math::quantile(boost::math::normal_distribution<double>(), 0.5 + options.confidence / 2.0);
  b.chi2_1 = boost::math::quantile(boost::math::chi_squared_distribution<double>(1.0), options.confidence);
  auto has_terms = [](const FitPoint& p) { return p.m > 0 && p.terms > 0; };
  b.model_covariance = options.model_covariance && std::all_of(b.used.begin(), b.used.end(), has_terms);
  b.full = fit_full_model(b.used, options, b.model_covariance, b.opt);
  if (b.model_covariance)
    b.sigma_y =
        point_covariance(b.used, covariance_terms(b.full.coefficients(), options), b.full.model(), b.opt.edf_cap);
  // Inflation of every enabled term in the full model (at the boundary too).
  std::vector<int> full_set;
  for (int i = 0; i < P; ++i)
    if (options.enabled[static_cast<std::size_t>(i)]) full_set.push_back(i);
  const Sandwich sw_full = sandwich(b.full.pr, b.full.fit.d, full_set, b.sigma_y, options);
  for (std::size_t q = 0; q < full_set.size(); ++q) b.phi_full[static_cast<std::size_t>(full_set[q])] = sw_full.phi[q];
  return b;
}

/// One term set's fit (`set`: the enabled terms, `dropped` those the selection left out, reported from
/// the full model) before its coefficients' intervals: what choosing between fits reads (χ²), and the
/// stage the intervals' profiles start from.
struct SetFit {
  Stage sel;
  FitResult res;
  std::array<bool, P> dropped{};
};

/// The fit of one term set started from `start`, its intervals not yet taken (add_intervals).
SetFit fit_term_set(const FitBase& b, const FitOptions& set, const std::array<bool, P>& dropped, const Vec5& start) {
  FitResult res;
  res.counter_readout = b.options.counter && b.options.readout == Readout::Counter;
  res.used = b.used;
  res.model_covariance = b.model_covariance;
  res.options = set;
  Stage sel{make_problem(res.used, res.options), {}};
  sel.fit = irls(sel.pr, sel.pr.enabled_mask, start, false);
  require_converged(sel.fit);
  res.termination = combine(b.full.fit.termination, sel.fit.termination);
  res.deviance = sel.fit.dev;
  res.c = sel.coefficients();
  const Eigen::VectorXd mu = sel.model();
  res.model.assign(mu.data(), mu.data() + mu.size());
  goodness_of_fit(sel, res);
  term_covariance(sel, b.sigma_y, b.options, b.phi_full, dropped, res);
  res.corr_NQ = res.log_correlation(Term::N, Term::Q);
  res.corr_NB = res.log_correlation(Term::N, Term::B);
  return {std::move(sel), std::move(res), dropped};
}

/// Every coefficient's interval from its profile: the costly part of a fit, taken only for the fit
/// that is reported (or averaged).
FitResult add_intervals(const FitBase& b, SetFit f) {
  const Stage& sel = f.sel;
  const auto& dropped = f.dropped;
  FitResult& res = f.res;
  // Each term's interval is a profile of its own (a counter read-out's the costliest): in parallel.
  parallel_for(static_cast<std::size_t>(P), [&](std::size_t ui) {
    auto& co = res.coef[ui];
    if (!b.options.enabled[ui]) {
      co.enabled = false;
      co.in_model = res.options.enabled[ui];
      return;
    }
    co = coefficient_interval(static_cast<int>(ui), sel, b.full, dropped[ui], res, b.z, b.chi2_1);
  });
  for (std::size_t ui = 0; ui < static_cast<std::size_t>(P); ++ui) {
    const auto& co = res.coef[ui];
    if (!b.options.enabled[ui]) continue;
    if (!std::isfinite(co.value) || !std::isfinite(co.sigma) || !std::isfinite(co.low) || !std::isfinite(co.high))
      throw AnalysisError(trf("the data do not bound the {} coefficient", term_name(kAllTerms[ui])));
  }
  return std::move(res);
}

/// The selected term set's fit with the read-out model of options.readout (Auto taken as White), and
/// what its average over K needs.
struct Selected {
  FitBase base;
  Vec5 d;  // the selected set's optimum, scaled
  SetFit fit;
};

Selected fit_selected(std::span<const FitPoint> points, const FitOptions& options) {
  FitBase base = fit_base(points, options);
  FitOptions set = base.opt;
  IrlsResult best = base.full.fit;
  std::array<bool, P> dropped{};
  if (options.select_terms)
    std::tie(set, best) = select_terms(base.used, base.opt, best, base.phi_full, base.chi2_1, dropped);
  SetFit fit = fit_term_set(base, set, dropped, best.d);
  return {std::move(base), best.d, std::move(fit)};
}

/// With the term selection, the selected set's coefficients averaged with the set that differs in K.
FitResult averaged_over_k(Selected s) {
  const FitBase& b = s.base;
  const auto uk = static_cast<std::size_t>(idx(Term::K));
  if (!b.options.select_terms || !b.options.enabled[uk] || !b.options.droppable[uk])
    return add_intervals(b, std::move(s.fit));
  FitOptions other = s.fit.res.options;
  other.enabled[uk] = !other.enabled[uk];
  std::array<bool, P> other_dropped = s.fit.dropped;
  other_dropped[uk] = !other.enabled[uk];
  Vec5 start = s.d;
  start[idx(Term::K)] = other.enabled[uk] ? b.full.fit.d[idx(Term::K)] : 0.0;
  std::optional<FitResult> alt;
  double b_estimate = 0;
  try {
    SetFit fit = fit_term_set(b, other, other_dropped, start);
    const SetFit& with_k = other.enabled[uk] ? fit : s.fit;
    const SetFit& without_k = other.enabled[uk] ? s.fit : fit;
    b_estimate = sign_free_b(with_k.sel, without_k.sel.model(), b.sigma_y, with_k.res.options);
    alt = add_intervals(b, std::move(fit));
  } catch (const AnalysisError&) {  // the other set cannot be fitted: the selected one stands alone
  }
  FitResult res = add_intervals(b, std::move(s.fit));
  if (alt) average_over_k(res, std::move(*alt), b_estimate, b.phi_full[uk], b.z);
  return res;
}

}  // namespace

FitResult fit_noise(std::span<const FitPoint> points, const FitOptions& options) {
  if (!options.counter || options.readout != Readout::Auto) return averaged_over_k(fit_selected(points, options));
  // A counter with or without dither. The white model (the simpler, and a dithered counter's) stands
  // unless the counter's fits better by more than χ²₁ at 0.001 (10.83, the level at which a fit is
  // rejected): on dithered records the two differ by chance by a few units, on a plain counter's
  // by 10³–10⁴ per point.
  FitOptions white = options, counter = options;
  white.readout = Readout::White;
  counter.readout = Readout::Counter;
  // Only the chosen model's intervals are profiled: the choice reads the two fits' χ² alone.
  Selected w = fit_selected(points, white);
  try {
    Selected c = fit_selected(points, counter);
    if (c.fit.res.chi2 + kCounterMargin < w.fit.res.chi2) return averaged_over_k(std::move(c));
  } catch (const AnalysisError&) {  // the white model stands
  }
  return averaged_over_k(std::move(w));
}

SlopeReadout slope_readout(const AllanResult& allan) {
  SlopeReadout s;
  const auto& p = allan.points;
  // The minimum is searched at τ ≤ T/10 only: beyond, a point has a handful of EDF and the
  // smallest of several such points is mostly chance.
  const double t_total = allan.points_in > 1 ? static_cast<double>(allan.points_in - 1) * allan.tau0_s : 0.0;
  const double tau_cap = t_total > 0 ? t_total / 10.0 : std::numeric_limits<double>::infinity();
  std::size_t imin = 0;
  bool any = false;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!(p[k].dev > 0) || p[k].tau_s > tau_cap * (1 + 1e-12)) continue;
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
