#pragma once
/// @file mid_tau.hpp
/// Fits of the mid-τ Allan variance against an ensemble reference: the Q, N, B, K corrections
/// that calibrate a model, and the Gauss–Markov bump fitted beside them.
#include <array>
#include <cstddef>
#include <vector>

namespace rwcalc::diag {

/// Ensemble reference of the mid-τ AV: mean and variance over the runs per τ.
struct MidTauReference {
  std::vector<std::size_t> grid;
  std::vector<double> tau;
  std::vector<double> mean, var;
  /// Sample covariance of the runs' AV between grid points (row-major, grid.size()²; the
  /// overlapping AV at neighbouring τ is strongly correlated); empty: treated as independent.
  std::vector<double> cov;
};

struct ShapeEstimate {
  double statistic = 0;   ///< χ² drop when a Gauss–Markov bump joins the free Q, N, B, K corrections
  double scale = 0, scale_sigma = 0;   ///< its variance σ², (°/h)², and standard error
  double time = 0, time_low = 0, time_high = 0;  ///< its correlation time and the Δχ² = 1 range, s
  std::array<double, 4> dc{0, 0, 0, 0};  ///< corrections of the fit-scale Q², N², B², K² at the optimum
  /// White rate noise left beside the bump, c_N,base + ΔN² ≥ 0 (fit scale, (°/h)²·s), and its
  /// standard error. A bump with no white noise left is a low-pass of the white noise.
  double white_rest = 0, white_rest_sigma = 0;
  /// Largest rise of the fitted mid-τ AV (bump plus corrections) above the reference, in ensemble
  /// standard deviations: a Gauss–Markov term adds variance somewhere.
  double excess = 0;
  /// The bump's AV at its peak (τ = 1.89·Tc) over the reference's mean AV there.
  double peak_ratio = 0;
};
/// AV of a unit-variance Gauss–Markov process of correlation time tc.
double gauss_markov_avar(double tau, double tc);
/// Fit `v` (measured mid-τ AV) against the reference plus Q, N, B, K corrections plus a
/// Gauss–Markov bump; `c_base` holds the reference model's Q², N², B², K² on the fit scale: the
/// corrected N², B², K² are kept ≥ 0 (Q² is free). `fixed_time` > 0: the correlation time is
/// given (only σ² and the corrections are fitted), else searched on a grid.
ShapeEstimate shape_detect(const std::vector<double>& v, const MidTauReference& ref,
                           const std::array<double, 4>& c_base, double fixed_time = 0.0);
/// Corrections of the fit-scale Q², N², B², K² that bring the reference to `v` (weighted least
/// squares with the ensemble's variances, corrected N², B², K² kept ≥ 0).
std::array<double, 4> power_law_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                            const std::array<double, 4>& c_base);
/// The pilot calibration of a model: as power_law_corrections on τ ≤ tau_max, with K held at the
/// reference model's value.
std::array<double, 4> calibration_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                              const std::array<double, 4>& c_base, double tau_max);
/// `v` being one ensemble member, the reference's mean and variance without it.
MidTauReference leave_one_out(const MidTauReference& ref, const std::vector<double>& v, std::size_t runs);
/// Gamma deviance of a mid-τ AV against a reference: Σ ν(r − 1 − ln r), r = v/E v, with the EDF
/// ν = 2(E v)²/Var v of the ensemble and a 1000-EDF model floor (as band_misfit).
double mid_deviance(const std::vector<double>& v, const MidTauReference& ref);

}  // namespace rwcalc::diag
