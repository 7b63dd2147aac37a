#pragma once
/// @file ensemble.hpp
/// The simulated ensemble of a model: per-record statistics (octave AV, mid-τ AV, detector
/// statistics), the band of σ per τ, the mid-τ reference, and the measured-versus-ensemble
/// deviance.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "diagnose/mid_tau.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

class RecordDetector;

/// What each simulated record of an ensemble is reduced to.
struct EnsemblePlan {
  std::vector<std::int64_t> octave_m;  ///< octave cluster sizes (the band)
  std::vector<std::size_t> grid;       ///< mid-τ grid (decimated periods)
  /// Also the mid-τ AV of each record without its own mean-shape candidate (own_candidates), as
  /// the measurement is taken.
  bool clean_mid = true;
  std::vector<const RecordDetector*> scored;  ///< detectors whose statistic each record gets
};

/// One simulated record's statistics.
struct RunStats {
  std::vector<double> octave_var;
  std::vector<double> mid_var;
  std::vector<double> mid_var_clean;  ///< mid_var without the record's own candidate (clean_mid)
  std::array<double, kEffectCount> stat{};  ///< the scored detectors' statistics, by Effect
  double mean_rate = 0;               ///< the record's mean rate, °/h
};

/// Simulate `runs` records of `model` (realisation r from ensemble_seed(settings.seed, r)) and
/// reduce each as `plan` says; the results are in record order.
std::vector<RunStats> run_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                   const EnsemblePlan& plan, Progress* progress);

/// The band from the ensemble's octave variances and the measured points.
std::vector<BandPoint> make_band(const std::vector<AllanPoint>& measured, const std::vector<RunStats>& runs,
                                 double level);
/// Mean, variance and covariance of the runs' mid-τ AV (`clean`: of mid_var_clean).
MidTauReference make_reference(const std::vector<std::size_t>& grid, double tau_d, const std::vector<RunStats>& runs,
                               bool clean = false);

/// The band's Gamma deviance terms ν·(r − 1 − ln r), summed, and their number.
struct BandDeviance {
  double sum = 0;
  std::size_t points = 0;
};
BandDeviance band_deviance(const std::vector<BandPoint>& band, std::size_t runs);

/// Re-fit of a simulated model's N, B and K to the whole band: the changes of their fit-scale c
/// (order N, B, K; term_basis) that minimise the band's Gamma deviance when the ensemble mean σ²
/// moves by Σ Δc·basis(τ), with every c + Δc ≥ 0 (Fisher scoring with a bounded active set and a
/// halving line search); the terms not in `free` are held. All zero when nothing improves.
std::array<double, 3> band_refit(const std::vector<BandPoint>& band, std::size_t runs, const std::array<double, 3>& c,
                                 const std::array<bool, 3>& free = {true, true, true});

}  // namespace rwcalc::diag
