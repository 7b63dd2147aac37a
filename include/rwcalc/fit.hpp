#pragma once
/// @file fit.hpp
/// Fit of the IEEE 952 five-term gyro noise model to Allan variances, with uncertainties.
///
///   σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2
///
/// Conventions (stated in every output):
///   Q  ″          rms white angle error (IEEE 952: σ² = 3Q²/τ²). The seed paper's eq. (2) writes
///                 Q²/τ², so Q_paper = √3·Q.
///   N  °/√h       angle random walk, σ(τ = 1 h) of the −½ line
///   B  °/h        bias instability; the AV floor is √(2 ln2/π)·B = 0.6643·B (the paper prints B
///                 where B² is meant)
///   K  °/h/√h     rate random walk, σ(τ = 3 h) of the +½ line
///   R  °/h²       rate ramp
/// Allan variances enter in (°/h)² at τ in seconds.
///
/// Method (docs/analysis.md): the squared coefficients c ≥ 0 minimise the Gamma deviance
///   D = Σ ν_j [σ̂²_j/σ²_j − 1 − ln(σ̂²_j/σ²_j)]
/// of the scaled-χ² law ν·σ̂²/σ² ~ χ²_ν, by iteratively reweighted non-negative least squares.
/// For the overlapping estimator the covariance of the AV points is computed from the fitted model
/// (model-based EDFs, and a sandwich inflation φ_i of each term's variance times 1 + a/ν_i); a
/// model-error floor comes from the residuals. Intervals are profile-likelihood intervals of the
/// deviance scaled by φ_i, never negative; a term whose lower bound is 0 is an upper bound.
#include <Eigen/Dense>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "rwcalc/allan.hpp"

namespace rwcalc {

/// The five IEEE 952 terms, in the order of the model.
enum class Term : int { Q = 0, N = 1, B = 2, K = 3, R = 4 };
inline constexpr int kTermCount = 5;
inline constexpr std::array<Term, kTermCount> kAllTerms{Term::Q, Term::N, Term::B, Term::K, Term::R};

/// "Q", "N", "B", "K", "R".
std::string_view term_name(Term t);
/// Unit of the coefficient: "arcsec", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)", "deg/h^2".
std::string_view term_unit(Term t);
/// The AV contributed by the term per unit of its squared fit-scale coefficient c, at τ (s):
/// {3/τ², 1/τ, 2 ln2/π, τ/3, τ²/2}, giving σ² in (°/h)².
double term_basis(Term t, double tau_s);
/// Coefficient in its IEEE unit from the fit-scale c (≥ 0): Q = √c, N = √c/60, B = √c,
/// K = 60√c, R = 3600√c (c uses seconds, the coefficients hours).
double coefficient_from_c(Term t, double c);
/// Inverse of coefficient_from_c.
double c_from_coefficient(Term t, double value);

/// One Allan-variance point: τ (s), σ² ((°/h)²) and its equivalent degrees of freedom.
struct FitPoint {
  double tau_s = 0;
  double var = 0;
  double edf = 0;
  std::int64_t m = 0;      ///< cluster size (0: unknown, no model covariance)
  std::int64_t terms = 0;  ///< second differences in the overlapping estimator (0: unknown)
};

/// Options of the fit. The defaults are the documented ones.
struct FitOptions {
  double tau_min_s = 0;                                         ///< fit range, s (inclusive)
  double tau_max_s = std::numeric_limits<double>::infinity();   ///< fit range, s (inclusive)
  /// Points with fewer EDF are left out of the fit (they are still listed in the AV table).
  double min_edf = 1.0;
  /// Model-error floor: each point's EDF enters as 1/(1/ν + 1/edf_cap), a relative model
  /// uncertainty of √(2/edf_cap) on σ². 0 (default): estimated from the fit's residuals
  /// (Paule–Mandel; none when they are within their sampling scatter, at most edf_cap = 10⁴).
  double edf_cap = 0;
  /// Which terms are fitted (false: held at 0 and reported as not fitted).
  std::array<bool, kTermCount> enabled{true, true, true, true, true};
  /// Two-sided confidence of the intervals.
  double confidence = 0.95;
  /// Constant variance inflation on top of the model-based one (1: none).
  double dispersion = 1.0;
  /// Small-EDF inflation a: each term's profile deviance is scaled by 1 + a/ν_i on top of its
  /// sandwich inflation, ν_i = 2ĉ²/Var(ĉ) the term's own effective EDF (a few-EDF term such as B
  /// has heavier tails than χ²₁). Calibrated by simulation (tests/slow_coverage_fit.cpp).
  double edf_inflation = 3.0;
  /// Use the model-based covariance of the AV points when they carry cluster sizes and terms.
  bool model_covariance = true;
  /// Term selection: a droppable term whose removal raises the scaled deviance by less than the χ²₁
  /// quantile is left out of the model (backward elimination R, K, Q) and reported as the full
  /// model's upper bound. N and B, the verdict's parameters, are never dropped.
  bool select_terms = true;
  std::array<bool, kTermCount> droppable{true, false, false, true, true};
};

/// One fitted coefficient in its IEEE unit (see term_unit).
struct Coefficient {
  bool enabled = true;    ///< fitted at all
  bool in_model = true;   ///< kept by the term selection (else reported as a full-model upper bound)
  bool resolved = false;  ///< the lower confidence bound is above 0
  double estimate = 0;    ///< maximum-likelihood estimate (may be 0: driven to the boundary)
  double value = 0;       ///< the estimate if resolved, else the upper bound (print "< value")
  double sigma = 0;       ///< standard error (delta method); for an upper bound high/(2·1.96)
  double low = 0;         ///< lower confidence bound (profile likelihood), ≥ 0
  double high = 0;        ///< upper confidence bound
};

struct FitResult {
  std::array<Coefficient, kTermCount> coef;
  Eigen::Matrix<double, kTermCount, 1> c;                  ///< fit-scale squared coefficients
  Eigen::Matrix<double, kTermCount, kTermCount> cov_c;     ///< their covariance (inflated; 0 rows for inactive terms)
  double deviance = 0;         ///< Gamma deviance at the optimum
  double chi2 = 0;             ///< deviance with the small-ν (Bartlett) correction, ≈ χ²_dof under the model
  int dof = 0;                 ///< points − active terms
  double chi2_per_dof = 0;
  double p_value = 1;          ///< P(χ²_dof ≥ chi2)
  double corr_NQ = 0;          ///< correlation of the N² and Q² estimates
  double corr_NB = 0;          ///< correlation of the N² and B² estimates
  /// Variance inflation of each term: sandwich / independent-points information, times
  /// options.dispersion·(1 + edf_inflation/ν_i).
  std::array<double, kTermCount> phi{1, 1, 1, 1, 1};
  bool model_covariance = false;  ///< the model-based AV covariance was used
  int iterations = 0;
  FitOptions options;
  std::vector<FitPoint> used;  ///< the points fitted (τ ascending; edf = the EDF the fit used)
  std::vector<double> model;   ///< model σ² at those points, (°/h)²

  [[nodiscard]] const Coefficient& operator[](Term t) const { return coef[static_cast<int>(t)]; }
  /// Model σ² at τ (s), (°/h)².
  [[nodiscard]] double model_var(double tau_s) const;
  /// Confidence distribution of a coefficient: P(true value ≤ `value`, IEEE unit) = Φ(sign·√(ΔD/φ))
  /// from the scaled profile deviance; cdf(low) = (1−conf)/2 and cdf(high) = (1+conf)/2.
  [[nodiscard]] double cdf(Term t, double value) const;
  /// Correlation of the log-estimates of two terms (0 when either is not active).
  [[nodiscard]] double log_correlation(Term a, Term b) const;
};

/// Covariance matrix, (°/h)⁴, of overlapping-AV estimates at the given points (each needs m and
/// terms) for Gaussian noise following the model with fit-scale squared coefficients c (the ramp
/// adds none); lags are summed on a mesh graded towards the kinks of the lag covariance. With
/// `diagonal_only` only the variances (the off-diagonal entries stay 0).
Eigen::MatrixXd av_covariance(std::span<const FitPoint> points, const Eigen::Matrix<double, kTermCount, 1>& c,
                              bool diagonal_only = false);

/// The points of an Allan result usable for a fit (σ² > 0 is checked by fit_noise); cluster sizes
/// and term counts are filled for the overlapping estimator only.
std::vector<FitPoint> fit_points(const AllanResult& allan);

/// Fit the model. Throws AnalysisError when fewer than (enabled terms + 1) points remain in the
/// range, when a point is not a positive finite variance, or when the fit does not converge.
FitResult fit_noise(std::span<const FitPoint> points, const FitOptions& options = {});

/// The classic slope-line readout (IEEE 952 Annex C): N from the −½ line through the AV point whose
/// local log-slope is closest to −½, read at τ = 1 h; B = σ_min/0.6643; K from the +½ line read at
/// τ = 3 h. Each is empty when no part of the curve has the slope within ±0.25.
struct SlopeReadout {
  std::optional<double> N;  ///< °/√h
  double tau_N_s = 0;       ///< τ of the point the −½ line goes through, s
  std::optional<double> B;  ///< °/h
  double sigma_min = 0;     ///< minimum ADEV, °/h
  double tau_min_s = 0;     ///< its τ, s
  std::optional<double> K;  ///< °/h/√h
  double tau_K_s = 0;       ///< τ of the point the +½ line goes through, s
};
SlopeReadout slope_readout(const AllanResult& allan);

}  // namespace rwcalc
