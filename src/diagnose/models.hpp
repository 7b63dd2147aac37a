#pragma once
/// @file models.hpp
/// The noise models of the diagnosis: the base model of a record, the extended model built from
/// the named effects, and their out-of-sample check (holdout.cpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "diagnose/detector.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/fit.hpp"

namespace rwcalc::diag {

/// s, the shortest record the diagnosis takes; blocks of thirds are used when each lasts as long.
constexpr double kMinDuration = 1200.0;

/// The effects named on the whole record and what they tell the blocks.
struct Named {
  std::vector<const Detector*> detectors;  ///< in naming order (Effect)
  double sin_hint_hz = 0;                  ///< frequency of a named sinusoid
  double line_hint_hz = 0;                 ///< frequency of a named coherent high-frequency line
};

/// Mean per-point prediction deviance of the base and the extended model over the folds.
struct HoldoutScores {
  double base = 0, extended = 0;
};
/// `full`: the whole record as a stretch; `r`: the diagnosis so far.
HoldoutScores out_of_sample(const Stretch& full, const DiagnoseResult& r, const Named& named);

/// The five-term model of an analysis, read out like the data `x`.
NoiseModel base_model(const AnalysisResult& a, const PhaseSeries& x);
/// Pulse weight of the simulations: the data's for pulse data; a negligible one otherwise.
double sim_scale(const PhaseSeries& x, const AnalysisResult& a);
/// The five-term analysis, its fit range widened (to τ ≥ 1 s, then all τ) when it leaves too few
/// Allan points.
AnalysisResult analyze_for_base(const Recording& rec, const AnalysisOptions& aopt);
/// Samples a … b of a series, and a recording of a series.
PhaseSeries slice(const PhaseSeries& x, std::size_t a, std::size_t b);
Recording with_series(const Recording& rec, PhaseSeries s);
/// Whether a floating series is pulse counts given as numbers: its first 10⁵ increments are
/// integer multiples of the smallest one, a step coarse against their scatter (a finely
/// quantized ADC read-out is not counting).
bool on_lattice(const PhaseSeries& x);
std::vector<std::int64_t> octave_of(const AllanResult& a);
/// The series with the deterministic terms of `det` removed: floating phase.
PhaseSeries cleaned(const PhaseSeries& x, const NoiseModel& det);

/// Fit-scale squared coefficients Q², N², B², K² of a model; Q²'s entry is −∞ (no bound: Q² is held in
/// the mid-τ fits, never corrected).
std::array<double, 4> c_of(const NoiseModel& m);
/// Add a fit-scale correction to a coefficient, the corrected square kept ≥ 0.
void correct(double& coef, Term t, double dc);
/// Correct N, B and K by dc[1 … 3] (the order of c_of).
void correct_nbk(NoiseModel& m, const std::array<double, 4>& dc);

/// The mean over [0, T] of the rate added by a model's deterministic terms, °/h.
double mean_rate_of(const NoiseModel& det, double T);

/// N and B of a five-term model calibrated by a pilot ensemble (K held): the pilot's mean mid-τ
/// AV brought onto that of `dec` from 1 s to T/6, both without their own candidates.
NoiseModel calibrated(const NoiseModel& m0, const SimulationSettings& settings, std::size_t runs,
                      const EnsemblePlan& plan, const Decimated& dec, Progress* progress);

/// The base model of a stretch: the five-term fit of the data without the mean-shape candidate,
/// calibrated by a pilot ensemble; the simulated mean rate is the measured one.
struct RobustBase {
  NoiseModel model;
  NoiseModel candidate;
  Coefficient b_fit;  ///< B of the five-term fit without the candidate (its confidence interval)
};
RobustBase robust_base(const Recording& rec, const AnalysisResult& original, const AnalysisOptions& aopt,
                       const Decimated& dec, const SimulationSettings& pilot, std::size_t pilot_runs,
                       const EnsemblePlan& plan, Progress* progress);

/// The extended model of a stretch: the named effects estimated by their detectors, the rest
/// re-fitted as the base was, on the data without the named terms.
Extension extend(const Stretch& s, const std::vector<const Detector*>& named);

/// N and B re-fitted to the whole band (K held), kept with their band when it fits better.
void refit_whole_band(NoiseModel& m, std::vector<BandPoint>& band, const std::vector<AllanPoint>& measured,
                      const SimulationSettings& settings, std::size_t runs, const EnsemblePlan& plan,
                      const DiagnoseOptions& opt);

}  // namespace rwcalc::diag
