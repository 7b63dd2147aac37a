#pragma once
/// @file gls.hpp
/// The exact Gaussian likelihood of a record's block-mean rates under the noise model, the base of
/// every decision of the diagnosis (docs/diagnosis.md). The block means' second differences
/// z_i = y_{i+2} − 2y_{i+1} + y_i annihilate the rate's level and ramp, so their covariance is
/// Toeplitz for every term (white angle Q, white rate N, flicker B, rate random walk K, a
/// Gauss–Markov rate of correlation time Tc), each a known sequence times its level. The
/// likelihood of z is the restricted (REML) likelihood of the block means with level and ramp as
/// nuisance; the levels are profiled (maximised) under every hypothesis.
#include <Eigen/Dense>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "rwcalc/termination.hpp"

namespace rwcalc::diag {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A covariance term of the block means: its kind, and its correlation time for a Gauss–Markov one.
/// Counter: a plain counter's read-out error at the block edges, the sawtooth of the angle, whose
/// correlation across blocks (counter_correlation) the term carries.
enum class CovKind { Q, N, B, K, GM, Counter };
struct CovTerm {
  CovKind kind = CovKind::N;
  double tc_s = 0;  ///< Gauss–Markov correlation time, s
  /// Counter: the error's correlation c(u) at lags u = 0, 1, … (c(0) = 1, 0 beyond the last).
  std::shared_ptr<const std::vector<double>> correlation;
  /// > 0: the term's level is known, not profiled (a counter's error variance q²/12, ″²). With a
  /// known level the overall scale is no longer free: every other level is searched on its own.
  double known_level = 0;
};
[[nodiscard]] bool has_known_level(const std::vector<CovTerm>& terms);

/// Autocovariance r[0 … n−1] of z at unit level: Q and Counter (angle error variance 1 ″²), N (AV 1/τ (°/h)²·s),
/// B (AV 1 (°/h)², the flicker floor's), K (AV τ (°/h)²/s), GM (variance 1 (°/h)²); blocks of tb s.
std::vector<double> term_autocov(const CovTerm& t, std::size_t n, double tb);
/// A counter's error correlation c(u), u = 0 … lags − 1 (until negligible): the sawtooth's phase
/// advances by `advance[k]` of a pulse per block near block k (the local mean rate; c is their
/// average) plus Gaussian noise of variance `spread` pulses² a block (white rate and angle noise):
/// c(u) = (6/π²) Σ_m m⁻² cos(2πmu·advance) e^{−2π²m²u·spread}.
std::vector<double> counter_correlation(const std::vector<double>& advance, double spread, std::size_t lags);
/// Its AV at τ (same unit levels), to turn profiled levels into the model's coefficients.
double term_avar(const CovTerm& t, double tau);

/// Whitening of a Toeplitz covariance by the Durbin–Levinson recursion: W (lower triangular,
/// W Σ Wᵀ = I) applied to the columns of `v`, and log det Σ. With `w_out`, W itself.
struct Whitened {
  Eigen::MatrixXd v;  ///< W·v
  double logdet = 0;
  bool ok = true;  ///< false: Σ not positive definite (a level out of range)
};
Whitened whiten(const std::vector<double>& r, const Eigen::MatrixXd& v, Eigen::MatrixXd* w_out = nullptr);

/// Second differences of a block-mean series or of a regressor's block means.
Eigen::VectorXd second_differences(const std::vector<double>& y);

/// A hypothesis: deterministic regressors (columns in z space) and covariance terms.
struct Hypothesis {
  Eigen::MatrixXd x;           ///< n × p regressors (second differences of block-mean columns)
  std::vector<CovTerm> terms;  ///< covariance terms, levels profiled
};

/// The profiled likelihood of z under a hypothesis: −2 ln L (up to a constant), the levels, the
/// regressors' coefficients and their covariance.
struct Profile {
  double m2ll = 0;
  std::vector<double> level;  ///< per term (Hypothesis::terms), unit levels as term_autocov's
  Eigen::VectorXd beta;
  Eigen::MatrixXd beta_cov;
  /// −2 ln of the restricted likelihood (REML: the regressors' coefficients integrated out, up to
  /// a constant). Profiled on it, the levels are not pulled down by the power the regressors take.
  double restricted_m2ll = 0;
  std::vector<double> r;    ///< the fitted autocovariance of z
  Termination termination;  ///< how the search over the levels stopped
};

/// The block means a record's likelihood reads.
struct Blocks {
  double tb = 10;         ///< block length, s
  double t0 = 0;          ///< start of the first block from the record's start, s
  std::vector<double> y;  ///< block-mean rates, °/h
  Eigen::VectorXd z;      ///< their second differences
  /// A plain counter's read-out error at the block edges (its correlation from the record's mean
  /// rate, its level q²/12 known); empty for other records.
  std::optional<CovTerm> counter;
  [[nodiscard]] std::size_t n() const { return static_cast<std::size_t>(z.size()); }
  [[nodiscard]] double duration() const { return tb * static_cast<double>(y.size()); }
};

/// −2 ln L at fixed levels, with the regressors' GLS coefficients.
Profile evaluate(const Blocks& b, const Hypothesis& h, const std::vector<double>& level);
/// The same at exactly `level`, the overall scale not profiled: the likelihood as a function of
/// every level, whose curvature is the levels' information (level_spread.hpp).
Profile evaluate_exact(const Blocks& b, const Hypothesis& h, const std::vector<double>& level);
/// Maximise over the levels (Nelder–Mead on their logarithms, the overall scale in closed form),
/// starting from `start` (one per term, > 0).
Profile profile(const Blocks& b, const Hypothesis& h, const std::vector<double>& start);

/// −2 ln L at fixed levels and coefficients (nothing profiled): a held-out stretch's score.
double m2ll_fixed(const Blocks& b, const Hypothesis& h, const std::vector<double>& level, const Eigen::VectorXd& beta);

/// The AV (°/h)² of the flicker term at level 1 in B units: 2 ln 2/π, the floor σ² per B².
inline constexpr double kFlickerFloorPerB2 = 0.4412712003053032;

/// The sum of the terms' autocovariances at `level`.
std::vector<double> total_autocov(const Blocks& b, const std::vector<CovTerm>& terms, const std::vector<double>& level);

}  // namespace rwcalc::diag
