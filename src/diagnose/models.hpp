#pragma once
/// @file models.hpp
/// The noise models of the diagnosis: the five-term base model of a record (fitted without its
/// own mean-shape candidate, calibrated by a pilot ensemble), the extended model built from the
/// named effects, and the helpers both share.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "diagnose/detector.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/fit.hpp"

namespace rwcalc::diag {

/// The five-term model of an analysis, read out like the data `x`.
NoiseModel base_model(const AnalysisResult& a, const PhaseSeries& x);
/// Pulse weight of the simulations: the data's for pulse data; a negligible one otherwise.
double sim_scale(const PhaseSeries& x, const AnalysisResult& a);
/// The five-term analysis; when the fit range leaves too few Allan points (a short record or
/// block), it is widened to τ ≥ 1 s, then to all τ.
AnalysisResult analyze_for_base(const Recording& rec, const AnalysisOptions& aopt);
/// Samples a … b of a series, and a recording of a series.
PhaseSeries slice(const PhaseSeries& x, std::size_t a, std::size_t b);
Recording with_series(const Recording& rec, PhaseSeries s);
/// Whether a floating series is pulse counts given as numbers: its first 10⁵ increments are
/// within 10⁻³ of integer multiples of the smallest non-zero one, and that step is coarse against
/// the increments' own scatter (a finely quantized ADC read-out is not counting).
bool on_lattice(const PhaseSeries& x);
std::vector<std::int64_t> octave_of(const AllanResult& a);
/// The series with the deterministic terms of `det` removed: floating phase.
PhaseSeries cleaned(const PhaseSeries& x, const NoiseModel& det);

/// Fit-scale squared coefficients Q², N², B², K² of a model (Q free: the read-out is simulated).
std::array<double, 4> c_of(const NoiseModel& m);
/// Add a fit-scale correction to a coefficient (°/√h, °/h, …), the corrected square kept ≥ 0.
void correct(double& coef, Term t, double dc);

/// The mean over [0, T] of the rate added by a model's deterministic terms, °/h.
double mean_rate_of(const NoiseModel& det, double T);

/// Calibrate N and B of a five-term model by a pilot ensemble of `runs` records: the corrections
/// (K held) that bring the pilot's mean mid-τ AV onto that of `dec`, from 1 s to T/6, data and
/// pilot records alike without their own candidates.
NoiseModel calibrated(const NoiseModel& m0, const SimulationSettings& settings, std::size_t runs,
                      const EnsemblePlan& plan, const Decimated& dec, Progress* progress);

/// The base model of a stretch: the five-term fit of the data without the mean-shape candidate,
/// calibrated on the mid-τ AV by a pilot ensemble; the simulated mean rate is the measured one.
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

/// N and B re-fitted to the whole band of the data (band_refit, K held), the re-fitted model
/// simulated again with the same seeds and kept, with its band, when that band fits better.
void refit_whole_band(NoiseModel& m, std::vector<BandPoint>& band, const std::vector<AllanPoint>& measured,
                      const SimulationSettings& settings, std::size_t runs, const EnsemblePlan& plan,
                      const DiagnoseOptions& opt);

}  // namespace rwcalc::diag
