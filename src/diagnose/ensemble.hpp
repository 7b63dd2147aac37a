#pragma once
/// @file ensemble.hpp
/// The simulated ensemble of a model (per-record statistics, the band of σ per τ, the deviance)
/// and the fits of the mid-τ AV against its reference (mid_tau.cpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

class RecordDetector;

/// Ensemble reference of the mid-τ AV: mean and variance over the runs per τ.
struct MidTauReference {
  std::vector<std::size_t> grid;
  std::vector<double> tau;
  std::vector<double> mean, var;
  /// Covariance of the runs' AV between grid points (row-major; neighbouring τ are strongly
  /// correlated); empty: treated as independent.
  std::vector<double> cov;
};

struct ShapeEstimate {
  double statistic = 0;               ///< χ² drop when a Gauss–Markov bump joins the N, B, K corrections
  double scale = 0, scale_sigma = 0;  ///< its variance σ², (°/h)², and standard error
  double time = 0, time_low = 0, time_high = 0;  ///< its correlation time and Δχ² = 1 range, s
  std::array<double, 4> dc{0, 0, 0, 0};          ///< corrections of the fit-scale Q², N², B², K²
  /// White rate noise left beside the bump (fit scale, ≥ 0) and its standard error: a bump with
  /// none left is a low-pass of the white noise.
  double white_rest = 0, white_rest_sigma = 0;
  /// Largest rise of the fitted mid-τ AV above the reference, in ensemble standard deviations.
  double excess = 0;
  /// The bump's AV at its peak (τ = 1.89·Tc) over the reference's mean AV there.
  double peak_ratio = 0;
};
/// AV of a unit-variance Gauss–Markov process of correlation time tc.
double gauss_markov_avar(double tau, double tc);
/// Fit `v` against the reference plus N, B, K corrections (corrected N², B², K² of `c_base`
/// kept ≥ 0) plus a Gauss–Markov bump; `fixed_time` > 0: its correlation time, else a grid search.
ShapeEstimate shape_detect(const std::vector<double>& v, const MidTauReference& ref,
                           const std::array<double, 4>& c_base, double fixed_time = 0.0);
/// Corrections of the fit-scale Q², N², B², K² that bring the reference to `v` on τ ≤ tau_max
/// (corrected N², B², K² kept ≥ 0; Q² held, its correction 0); `hold_k`: K keeps the reference
/// model's value.
std::array<double, 4> power_law_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                            const std::array<double, 4>& c_base,
                                            double tau_max = std::numeric_limits<double>::infinity(),
                                            bool hold_k = false);
/// `v` being one ensemble member, the reference's mean and variance without it.
MidTauReference leave_one_out(const MidTauReference& ref, const std::vector<double>& v, std::size_t runs);
/// Gamma deviance Σ ν(r − 1 − ln r), r = v/E v, ν = 2(E v)²/Var v with a 1000-EDF model floor.
double mid_deviance(const std::vector<double>& v, const MidTauReference& ref);

/// What each simulated record of an ensemble is reduced to.
struct EnsemblePlan {
  std::vector<std::int64_t> octave_m;         ///< octave cluster sizes (the band)
  std::vector<std::size_t> grid;              ///< mid-τ grid (decimated periods)
  bool clean_mid = true;                      ///< also the mid-τ AV without the record's own candidate
  std::vector<const RecordDetector*> scored;  ///< detectors whose statistic each record gets
  bool raw_mid = true;                        ///< the mid-τ AV of the record as simulated (mid_var)
  /// Records from this one on get only the scored statistics, mean rate and octave AV (a
  /// detector calibration beyond the band's records).
  std::size_t stats_from = static_cast<std::size_t>(-1);
};

struct RunStats {
  std::vector<double> octave_var;
  std::vector<double> mid_var;
  std::vector<double> mid_var_clean;        ///< without the record's own candidate (clean_mid)
  std::array<double, kEffectCount> stat{};  ///< the scored detectors' statistics, by Effect
  double mean_rate = 0;                     ///< °/h
};

/// Simulate `runs` records of `model` (realisation r from ensemble_seed(settings.seed, r)),
/// reduced as `plan` says, in record order.
std::vector<RunStats> run_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                   const EnsemblePlan& plan, Progress* progress);

std::vector<BandPoint> make_band(const std::vector<AllanPoint>& measured, const std::vector<RunStats>& runs,
                                 double level);
/// Mean, variance and covariance of the runs' mid-τ AV (`clean`: of mid_var_clean).
MidTauReference make_reference(const std::vector<std::size_t>& grid, double tau_d, const std::vector<RunStats>& runs,
                               bool clean = false);

/// The band's Gamma deviance terms ν·(r − 1 − ln r), summed, and their number.
struct BandDeviance {
  double sum = 0;
  std::size_t points = 0;
  [[nodiscard]] double per_point() const { return points ? sum / static_cast<double>(points) : 0.0; }
};
BandDeviance band_deviance(const std::vector<BandPoint>& band, std::size_t runs);

/// Changes of the fit-scale N, B, K (term_basis) that minimise the band's Gamma deviance when the
/// ensemble mean σ² moves by Σ Δc·basis(τ), every c + Δc ≥ 0 (Fisher scoring, bounded active set,
/// halving line search); terms not `free` are held. All zero when nothing improves.
std::array<double, 3> band_refit(const std::vector<BandPoint>& band, std::size_t runs, const std::array<double, 3>& c,
                                 const std::array<bool, 3>& free = {true, true, true});

}  // namespace rwcalc::diag
