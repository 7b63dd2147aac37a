// The extended model's gain on the block means' likelihood (gain.hpp).
#include "gain.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace rwcalc::diag {

namespace {

/// The held-out design: the block means in kChunks runs, alternate runs held out. Each run is long
/// against the blocks and short against the terms' forms, so a step or a warm-up in a held-out run
/// is seen in the kept runs beside it (blocked cross-validation).
constexpr std::size_t kChunks = 20;

/// Contrasts of the block means in alternate runs (`part` 0: even, 1: odd) that annihilate their
/// level and ramp, written as rows b on z = D y (the second differences): the unequally spaced
/// second difference a of each three consecutive kept blocks, Dᵀb = a solved for b by running
/// sums (b vanishes outside the three blocks' span). Their likelihood is the REML likelihood of the
/// kept blocks alone; the flicker's and the random walk's memory across a held-out run is carried
/// by Σ.
struct Contrast {
  std::size_t start = 0;     ///< first z the row reads
  std::vector<double> coef;  ///< b over z[start …]
};

std::vector<Contrast> contrasts(std::size_t blocks, int part) {
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < blocks; ++i)
    if (static_cast<int>(i * kChunks / blocks % 2) == part) kept.push_back(i);
  std::vector<Contrast> rows;
  for (std::size_t r = 0; r + 2 < kept.size(); ++r) {
    const std::size_t i1 = kept[r], i2 = kept[r + 1], i3 = kept[r + 2];
    const auto t1 = static_cast<double>(i1), t2 = static_cast<double>(i2), t3 = static_cast<double>(i3);
    std::vector<double> a(i3 - i1 + 1, 0.0);
    a[0] = (t3 - t2) / (t3 - t1);
    a[i2 - i1] = -1.0;
    a[i3 - i1] = (t2 - t1) / (t3 - t1);
    Contrast c{i1, std::vector<double>(i3 - i1 - 1)};
    double b1 = 0, b2 = 0;  // (Dᵀb)_k = b_k − 2b_{k−1} + b_{k−2} = a_k
    for (std::size_t k = 0; k + 2 <= i3 - i1; ++k) {
      c.coef[k] = a[k] + 2.0 * b1 - b2;
      b2 = b1, b1 = c.coef[k];
    }
    rows.push_back(std::move(c));
  }
  return rows;
}

/// −2 ln L of whitened data w = L⁻¹[z X] (log det Σ given), the regressors' coefficients
/// integrated out under a flat prior: the GLS fit's −2 ln L plus ln det XᵀΣ⁻¹X (the constants,
/// equal for two models on the same data, left out).
double integrated_m2ll(const Eigen::MatrixXd& w, double logdet) {
  const Eigen::Index k = w.cols() - 1;
  Eigen::VectorXd res = w.col(0);
  double logdet_x = 0;
  if (k) {
    const Eigen::MatrixXd xw = w.rightCols(k);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(xw.transpose() * xw);
    res -= xw * ldlt.solve(xw.transpose() * res);
    logdet_x = ldlt.vectorD().array().log().sum();
  }
  return res.squaredNorm() + logdet + logdet_x;
}

/// The same for the contrasts `rows` of z (autocovariance r, data and regressors v = [z X]).
double integrated_m2ll(const std::vector<Contrast>& rows, const std::vector<double>& r, const Eigen::MatrixXd& v) {
  const auto n = static_cast<Eigen::Index>(rows.size()), nz = v.rows();
  // Σbᵀ column by column over each row's span, then b(Σbᵀ).
  Eigen::MatrixXd sb = Eigen::MatrixXd::Zero(nz, n), bv = Eigen::MatrixXd::Zero(n, v.cols());
  for (Eigen::Index q = 0; q < n; ++q) {
    const Contrast& c = rows[static_cast<std::size_t>(q)];
    for (std::size_t k = 0; k < c.coef.size(); ++k) {
      const auto col = static_cast<Eigen::Index>(c.start + k);
      bv.row(q) += c.coef[k] * v.row(col);
      for (Eigen::Index i = 0; i < nz; ++i) sb(i, q) += c.coef[k] * r[static_cast<std::size_t>(std::abs(i - col))];
    }
  }
  Eigen::MatrixXd cov(n, n);
  for (Eigen::Index p = 0; p < n; ++p) {
    const Contrast& c = rows[static_cast<std::size_t>(p)];
    for (Eigen::Index q = 0; q < n; ++q) {
      double sum = 0;
      for (std::size_t k = 0; k < c.coef.size(); ++k) sum += c.coef[k] * sb(static_cast<Eigen::Index>(c.start + k), q);
      cov(p, q) = sum;
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  return integrated_m2ll(llt.matrixL().solve(bv), 2.0 * llt.matrixLLT().diagonal().array().log().sum());
}

/// −2 ln p(held-out runs | kept runs) under `m` at its levels, summed over both ways of holding
/// out: the predictive density, the deterministic terms' coefficients integrated over what the
/// kept runs tell of them.
double held_out_score(const Blocks& b, const GlsModel& m, const std::array<std::vector<Contrast>, 2>& parts) {
  const Hypothesis h = hypothesis_of(b, m.det, m.cov);
  const std::vector<double> r = total_autocov(b, m.cov, m.fit.level);
  Eigen::MatrixXd v(b.z.size(), 1 + h.x.cols());
  v.col(0) = b.z;
  if (h.x.cols()) v.rightCols(h.x.cols()) = h.x;
  const Whitened w = whiten(r, v);
  if (!w.ok) return std::numeric_limits<double>::infinity();
  const double whole = integrated_m2ll(w.v, w.logdet);
  return 2.0 * whole - integrated_m2ll(parts[0], r, v) - integrated_m2ll(parts[1], r, v);
}

}  // namespace

double added_parameter_charge(const GlsModel& base, const GlsModel& extended) {
  // A line: frequency and two coefficients; a step or a transient: its time (constant) and size; a
  // Gauss–Markov term: σ and Tc.
  const auto parameters = [](const GlsModel& m) {
    double k = 0;
    for (const auto& d : m.det) k += d.effect == Effect::Sinusoid || d.effect == Effect::Line ? 3 : 2;
    for (const auto& c : m.cov) k += c.kind == CovKind::GM ? 2 : 0;
    return k;
  };
  return 2.0 * (parameters(extended) - parameters(base));
}

LikelihoodGain block_gain(const Blocks& b, const GlsModel& base, const GlsModel& extended) {
  LikelihoodGain g;
  g.in_sample = base.fit.m2ll - extended.fit.m2ll - added_parameter_charge(base, extended);
  if (b.y.size() < 4 * kChunks) return g;  // too few blocks for runs of four
  const std::array<std::vector<Contrast>, 2> parts = {contrasts(b.y.size(), 0), contrasts(b.y.size(), 1)};
  g.holdout = held_out_score(b, base, parts) - held_out_score(b, extended, parts);
  return g;
}

}  // namespace rwcalc::diag
