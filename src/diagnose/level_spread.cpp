// The noise levels' spread and the effective degrees of freedom of a variance (level_spread.hpp).
#include "level_spread.hpp"

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <numbers>

namespace rwcalc::diag {

namespace {

/// Eigenvalues of the information (unit diagonal) below this are directions the record does
/// not resolve (two terms of one shape over the blocks' band); they carry no spread.
constexpr double kResolved = 1e-6;

/// A term's spectrum over the Fourier frequencies 2πk/n, k = 0 … n − 1, from its autocovariance.
std::vector<double> spectrum(const std::vector<double>& r, const std::vector<double>& cosine) {
  const std::size_t n = r.size();
  std::vector<double> s(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    double v = r[0];
    for (std::size_t m = 1; m < n; ++m) v += 2 * r[m] * cosine[(k * m) % n];
    s[k] = v;
  }
  return s;
}

}  // namespace

LevelSpread level_spread(const Blocks& b, const Hypothesis& h, const std::vector<double>& level) {
  const std::size_t n = b.n(), nt = level.size();
  LevelSpread s{level, Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nt), static_cast<Eigen::Index>(nt))};
  std::vector<std::size_t> free;
  for (std::size_t t = 0; t < nt; ++t)
    if (!(h.terms[t].known_level > 0)) free.push_back(t);
  if (free.empty() || n < 8) return s;
  std::vector<double> cosine(n);
  for (std::size_t k = 0; k < n; ++k)
    cosine[k] = std::cos(2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
  std::vector<std::vector<double>> spec(nt);
  std::vector<double> total(n, 0.0);
  for (std::size_t t = 0; t < nt; ++t) {
    spec[t] = spectrum(term_autocov(h.terms[t], n, b.tb), cosine);
    const double l = h.terms[t].known_level > 0 ? h.terms[t].known_level : level[t];
    for (std::size_t k = 0; k < n; ++k) total[k] += l * spec[t][k];
  }
  // Whittle's information of the levels: ½ Σ_k S_i S_j / S² (k = 0 left out: every term is nil there).
  const auto k_free = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(k_free, k_free);
  for (std::size_t k = 1; k < n; ++k) {
    if (!(total[k] > 0)) continue;
    const double w = 0.5 / (total[k] * total[k]);
    for (Eigen::Index i = 0; i < k_free; ++i)
      for (Eigen::Index j = 0; j <= i; ++j)
        info(i, j) += w * spec[free[static_cast<std::size_t>(i)]][k] * spec[free[static_cast<std::size_t>(j)]][k];
  }
  info = info.selfadjointView<Eigen::Lower>();
  // On the levels' own scales (unit diagonal), where a direction the record does not resolve shows
  // as a small eigenvalue whatever the levels' sizes (they span 20 decades).
  Eigen::VectorXd d = Eigen::VectorXd::Zero(k_free);
  for (Eigen::Index i = 0; i < k_free; ++i) d(i) = info(i, i) > 0 ? 1 / std::sqrt(info(i, i)) : 0.0;
  const Eigen::MatrixXd unit = d.asDiagonal() * info * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(unit);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(k_free, k_free);
  for (Eigen::Index e = 0; e < k_free; ++e) {
    const double lambda = eig.eigenvalues()(e);
    if (lambda > kResolved) cov += eig.eigenvectors().col(e) * eig.eigenvectors().col(e).transpose() / lambda;
  }
  cov = d.asDiagonal() * cov * d.asDiagonal();
  for (Eigen::Index i = 0; i < k_free; ++i)
    for (Eigen::Index j = 0; j < k_free; ++j)
      s.cov(static_cast<Eigen::Index>(free[static_cast<std::size_t>(i)]),
            static_cast<Eigen::Index>(free[static_cast<std::size_t>(j)])) = cov(i, j);
  return s;
}

double effective_dof(const LevelSpread& s, const std::function<double(const std::vector<double>&)>& variance) {
  const double v0 = variance(s.level);
  const auto nt = static_cast<Eigen::Index>(s.level.size());
  Eigen::VectorXd g = Eigen::VectorXd::Zero(nt);
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (!(s.cov(t, t) > 0)) continue;
    // Forward, by a tenth of the level's standard deviation: a level on its bound of 0 stays positive.
    const double step = 0.1 * std::sqrt(s.cov(t, t));
    auto up = s.level;
    up[static_cast<std::size_t>(t)] += step;
    g(t) = (variance(up) - v0) / step;
  }
  const double var_v = g.dot(s.cov * g);
  if (!(v0 > 0) || !std::isfinite(var_v) || !(var_v > 0)) return std::numeric_limits<double>::infinity();
  return 2 * v0 * v0 / var_v;
}

double profile_cutoff(double dof) {
  if (!(dof < 1e6)) return kChi2Cut95;
  const double t = boost::math::quantile(boost::math::students_t(std::max(dof, 1.0)), 0.975);
  return t * t;
}

}  // namespace rwcalc::diag
