#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/methods.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file methods.hpp
/// The seed paper's cross-checks of the AV results as unbiased estimators with intervals
/// (docs/analysis.md, "Cross-checks"): N from the angle variance against interval, B from the
/// 100-s averages, B from the ADEV minimum, and the spread of block-mean rates beside its model
/// expectation.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rwcalc/fit.hpp"
#include "rwcalc/series.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

struct MethodOptions {
  double direct_t_min_s = 1.0;    ///< shortest interval of the direct method
  double direct_t_max_s = 100.0;  ///< longest (also at most T/50)
  int direct_points = 12;         ///< interval lengths, log-spaced
  int bootstrap_replicates = 64;  ///< parametric-bootstrap replicates of the direct N interval
  double block_s = 100.0;         ///< block of the averaging method

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

struct MethodEstimate {
  bool valid = false;  ///< false: the record is too short for the method
  double value = 0;    ///< °/√h or °/h
  double sigma = 0;    ///< standard error
  double low = 0;      ///< 95 % bounds (≥ 0)
  double high = 0;
  bool resolved = true;  ///< false: value is an upper bound
  double estimate = 0;   ///< the point estimate √max(0, ·²) even when not resolved (mean-unbiased)
};

/// Interval t, number of increments, variance of the angle increments (″²) about their mean.
struct DirectPoint {
  double t_s = 0;
  std::size_t intervals = 0;
  double var_arcsec2 = 0;
};

/// Expectation of the sample variance (divisor count − 1) of angle increments of `t` sample
/// steps, mean removed, per unit coefficient of each term (fit scale, fit.hpp): Q² (″²), N″²
/// (″²/s), B² ((″/s)²). `points` phase points `step_s` apart; overlapping increments (stride one
/// step) or non-overlapping ones (stride t). Exact for stationary-increment Gaussian noise.
struct IncrementBasis {
  double q = 0, n = 0, b = 0;
};
IncrementBasis increment_basis(std::size_t t, std::size_t points, double step_s, bool overlapping = true);

/// The paper's literal figure: a straight line a + b·t through the non-overlapping variances.
struct StraightLineN {
  bool valid = false;
  double value = 0;                ///< √b/60, °/√h (biased: see bias_factor)
  double intercept_arcsec2 = 0;    ///< a
  double slope_arcsec2_per_s = 0;  ///< b
  double bias_factor = 0;          ///< expected value/true N under the fitted model (0: not computed)
  std::vector<DirectPoint> points;
};

struct DirectNResult {
  MethodEstimate N;                   ///< unbiased N² regression; interval by parametric bootstrap
  double q2_arcsec2 = 0;              ///< fitted white-angle coefficient Q² (may be < 0)
  double n2_arcsec2_per_s = 0;        ///< fitted N″² = (60·N)² (may be < 0)
  double b2_arcsec2_per_s2 = 0;       ///< fitted B² (may be < 0)
  std::vector<DirectPoint> points;    ///< overlapping increments
  std::vector<IncrementBasis> basis;  ///< g at each point
  int replicates = 0;                 ///< bootstrap replicates used
  StraightLineN straight;             ///< the paper's straight line
};

/// Direct N of a phase series in ″. Invalid (not thrown) when fewer than four lengths fit.
/// `fit` (optional): the AV fit, whose counter read-out (FitResult::counter_readout) is taken off
/// the increment variances.
DirectNResult direct_n(const PhaseSeries& x, const MethodOptions& options = {}, const FitResult* fit = nullptr);

/// Fills the straight line's bias factor from the fitted Q, N, B.
void attach_straight_line_bias(DirectNResult& r, const FitResult& fit, double duration_s, double tau0_s);

/// B from the overlapping AV at the block length (what the block-average method measures) with the
/// fitted white terms removed: B² = [σ²(τ) − N″²/τ − 3Q²/τ²]/(2 ln2/π) (and K²τ/3, R²τ²/2 when the
/// fit keeps them); χ² interval with the EDF of σ̂²(τ) under the fitted model.
struct AvBEstimate {
  MethodEstimate B;                          ///< °/h
  double tau_s = 0;                          ///< τ of the AV used
  double var = 0;                            ///< σ̂²(τ), (°/h)²
  double white = 0;                          ///< the fitted other terms at τ removed, (°/h)²
  double edf = 0;                            ///< model-based EDF of σ̂²(τ)
  double bias_factor = 1;                    ///< expected value/true B under the fitted model (1: unbiased)
  [[nodiscard]] double cdf(double b) const;  ///< confidence distribution P(true B ≤ b)
};
AvBEstimate b_from_averages(const PhaseSeries& x, const FitResult& fit, double block_s);

/// σ_min/0.6643 of a slope readout (minimum over τ ≤ T/10); interval from the model-based EDF of
/// σ̂² at τ_min, the point looked up in `allan`. It estimates σ(τ_min)/0.6643, which exceeds B where
/// other terms contribute: bias_factor is that ratio under the fit.
AvBEstimate b_from_minimum(const AllanResult& allan, const SlopeReadout& s, const FitResult& fit);

struct BlockSpreadResult {
  MethodEstimate spread;  ///< std of the block mean rates, °/h (≈ 1.5 B: not an estimate of B)
  double block_s = 0;     ///< the block used (whole samples)
  std::size_t blocks = 0;
  double expected = 0;        ///< expectation under a fitted model (0: not computed)
  double expected_sigma = 0;  ///< its standard error from the fit covariance
};

/// Spread of block-mean rates. Invalid when fewer than 3 blocks fit.
BlockSpreadResult block_spread(const PhaseSeries& x, double block_s = 100.0);

/// Expected sample variance, (°/h)², of `blocks` consecutive block means of length block_s under
/// the five-term model with fit-scale coefficients c (fit.hpp): exact for the asymptotic model.
double expected_block_variance(const Eigen::Matrix<double, kTermCount, 1>& c, double block_s, std::size_t blocks);

/// Fills `expected` and `expected_sigma` from a fit.
void attach_expectation(BlockSpreadResult& r, const FitResult& fit);

/// (a − b)/√(σa² + σb²); 0 when both sigmas vanish.
double discrepancy_sigma(double a, double sa, double b, double sb);

}  // namespace rwcalc
