#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/fit.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file fit.hpp
/// Fit of the IEEE 952 five-term model σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2
/// (AV in (°/h)², τ in s) by Gamma deviance with c ≥ 0, and profile-likelihood intervals
/// (method and conventions: docs/analysis.md).
#include <Eigen/Dense>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/counter_readout.hpp"
#include "rwcalc/termination.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

/// The five IEEE 952 terms, in the order of the model.
enum class Term : int { Q = 0, N = 1, B = 2, K = 3, R = 4 };
inline constexpr int kTermCount = 5;
inline constexpr std::array<Term, kTermCount> kAllTerms{Term::Q, Term::N, Term::B, Term::K, Term::R};

/// "Q", "N", "B", "K", "R".
std::string_view term_name(Term t);
/// AV per unit of the fit-scale c at τ (s): {3/τ², 1/τ, 2 ln2/π, τ/3, τ²/2}, (°/h)².
double term_basis(Term t, double tau_s);
/// Q = √c, N = √c/60, B = √c, K = 60√c, R = 3600√c (c uses seconds, the coefficients hours).
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

/// How the pulses of a record were counted (FitOptions::readout).
enum class Readout {
  Auto,     ///< pulse counts: the counter model and the white one both fitted, the better kept
  Counter,  ///< a plain counter: its read-out AV (counter_readout.hpp) plus a white angle term Q
  White,    ///< white angle noise only (dithered or randomised read-out, floating data): Q alone
};

struct FitOptions {
  double tau_min_s = 0;                                        ///< fit range, s (inclusive)
  double tau_max_s = std::numeric_limits<double>::infinity();  ///< fit range, s (inclusive)
  double min_edf = 1.0;  ///< points with fewer EDF are left out of the fit (still listed)
  /// Model-error floor: EDF enter as 1/(1/ν + 1/edf_cap); 0: estimated from the residuals.
  double edf_cap = 0;
  std::array<bool, kTermCount> enabled{true, true, true, true, true};  ///< false: held at 0
  double confidence = 0.95;                                            ///< two-sided
  double dispersion = 1.0;  ///< constant variance inflation on top of the model-based one
  /// Profile deviance scaled by 1 + a/ν_i (ν_i the term's own EDF); calibrated by
  /// tests/slow_coverage_fit.cpp.
  double edf_inflation = 1.0;
  bool model_covariance = true;  ///< when the points carry cluster sizes and terms
  /// Backward elimination (R, K, Q) of terms that lower the scaled deviance by less than the χ²₁
  /// quantile; a dropped term is reported as the full model's upper bound. N, B: never dropped.
  bool select_terms = true;
  std::array<bool, kTermCount> droppable{true, false, false, true, true};
  /// The record's counter (pulse counts only); without it the read-out is white (Q).
  std::optional<CounterReadout> counter;
  Readout readout = Readout::Auto;  ///< with `counter`: which read-out model
  /// Most iterations of each reweighted least-squares fit (Fisher scoring; a few dozen suffice):
  /// a fit that takes them all reports TerminationStatus::IterationLimit.
  int max_iterations = 300;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// One fitted coefficient in its IEEE unit (Q ″, N °/√h, B °/h, K °/h/√h, R °/h²; coefficient_from_c).
struct Coefficient {
  bool enabled = true;    ///< fitted at all
  bool in_model = true;   ///< kept by the term selection (else reported as a full-model upper bound)
  bool resolved = false;  ///< the lower confidence bound is above 0
  /// √ĉ, its square root's bias taken out (0: ĉ ≤ 0); B averaged over K: ĉ is the set with K's sign-free c
  double estimate = 0;
  double value = 0;  ///< the estimate if resolved, else the upper bound (print "< value")
  /// The coefficient of the fitted model curve: the selected term set's √ĉ as fitted (0 for a term
  /// the selection left out). The curve a figure draws through the points; not the estimate, which
  /// has its root's bias taken out and, for B averaged over K, comes from another set.
  double curve = 0;
  double sigma = 0;  ///< standard error (delta method); for an upper bound high/(2z), z the interval's quantile
  double low = 0;    ///< lower confidence bound (profile likelihood), ≥ 0
  double high = 0;   ///< upper confidence bound
  /// How the profile searches for the bounds ended (their root-finding iterations).
  Termination termination;
};

struct FitResult {
  std::array<Coefficient, kTermCount> coef;
  Eigen::Matrix<double, kTermCount, 1> c;               ///< fit-scale squared coefficients
  Eigen::Matrix<double, kTermCount, kTermCount> cov_c;  ///< their covariance (inflated; 0 rows for inactive terms)
  double deviance = 0;                                  ///< Gamma deviance at the optimum
  double chi2 = 0;  ///< deviance with the small-ν (Bartlett) correction, ≈ χ²_dof under the model
  int dof = 0;      ///< points − active terms
  double chi2_per_dof = 0;
  double p_value = 1;                                 ///< P(χ²_dof ≥ chi2)
  double corr_NQ = 0;                                 ///< correlation of the N² and Q² estimates
  double corr_NB = 0;                                 ///< correlation of the N² and B² estimates
  std::array<double, kTermCount> phi{1, 1, 1, 1, 1};  ///< variance inflation of each term
  bool model_covariance = false;                      ///< the model-based AV covariance was used
  /// How the reported fit's iterations ended: the full model's fit and the selected term set's.
  Termination termination;
  FitOptions options;
  std::vector<FitPoint> used;  ///< the points fitted (τ ascending; edf = the EDF the fit used)
  std::vector<double> model;   ///< model σ² at those points, (°/h)²
  /// The counter read-out's AV is part of the model (Q is then the white angle noise beyond it);
  /// false: the read-out is the white term Q.
  bool counter_readout = false;
  /// With the term selection: the term set that differs from this one in K, and the weight of the set
  /// with K in the average of the two (docs/term-choice.md). The coefficients, their intervals and cdf
  /// are the average's; c, the model, the goodness of fit and cov_c are this (the selected) set's.
  std::shared_ptr<const FitResult> k_alternative;
  double k_weight = 0;

  [[nodiscard]] const Coefficient& operator[](Term t) const { return coef[static_cast<std::size_t>(t)]; }
  /// Model σ² at τ (s), (°/h)².
  [[nodiscard]] double model_var(double tau_s) const;
  /// The counter read-out's part of model_var at τ (s), (°/h)² (0 unless counter_readout).
  [[nodiscard]] double counter_var(double tau_s) const;
  /// The counter read-out's part of the variance of angle increments over h samples, ″² (0 unless
  /// counter_readout; counter_increment_var).
  [[nodiscard]] double counter_increment_var(std::int64_t h) const;
  /// The read-out's part of model_var at τ (s): the white angle term Q and the counter's, (°/h)².
  [[nodiscard]] double readout_var(double tau_s) const;
  /// `c` with a counter read-out counted as white angle noise of its mean level q²/12: the
  /// coefficients whose Gaussian AV covariance (av_covariance) stands for the points' variance.
  [[nodiscard]] Eigen::Matrix<double, kTermCount, 1> covariance_c() const;
  /// Confidence distribution of a coefficient: P(true value ≤ `value`, IEEE unit) = Φ(sign·√(ΔD/φ))
  /// from the scaled profile deviance, averaged over the two term sets (k_alternative, k_weight);
  /// cdf(low) = (1−conf)/2 and cdf(high) = (1+conf)/2.
  [[nodiscard]] double cdf(Term t, double value) const;
  /// Correlation of the log-estimates of two terms (0 when either is not active).
  [[nodiscard]] double log_correlation(Term a, Term b) const;
};

/// Covariance, (°/h)⁴, of overlapping-AV estimates at points with m and terms, for Gaussian noise
/// with fit-scale coefficients c (the ramp adds none).
Eigen::MatrixXd av_covariance(std::span<const FitPoint> points, const Eigen::Matrix<double, kTermCount, 1>& c,
                              bool diagonal_only = false);

/// Cluster sizes and term counts are filled for the overlapping estimator only.
std::vector<FitPoint> fit_points(const AllanResult& allan);

/// Throws AnalysisError when fewer than (enabled terms + 1) points remain in the range, a point is
/// not a positive finite variance, or the fit does not converge.
FitResult fit_noise(std::span<const FitPoint> points, const FitOptions& options = {});

/// The slope-line readout (IEEE 952 Annex C): N at 1 h of the −½ line, B = σ_min/0.6643 (minimum
/// over τ ≤ T/10), K at 3 h of the +½ line; empty when no part of the curve has the slope within ±0.25.
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
