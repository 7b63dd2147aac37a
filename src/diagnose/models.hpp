#pragma once
/// @file models.hpp
/// The base model of a record: the five-term fit read out like the data, and the data without a
/// model's deterministic terms.
#include "rwcalc/analysis.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

/// s, the shortest record the diagnosis takes.
constexpr double kMinDuration = 1200.0;

/// The five-term model of an analysis, read out like the data `x`.
NoiseModel base_model(const AnalysisResult& a, const PhaseSeries& x);
/// Sets the rate noise of `extended` (N, B, K, R) to the five-term fit of the record less its named
/// deterministic terms: the base fit's points, options and read-out, each point's variance that of
/// `cleaned_var` (the same τ, in order), and returns that fit. Base and extended model are then
/// fitted alike: the base fit's N and B have taken up what the terms add to the AV.
FitResult refit_noise(const AnalysisResult& a, const std::vector<double>& cleaned_var, NoiseModel& extended);
/// Pulse weight of the model's read-out: the data's for pulse data; a negligible one otherwise.
double sim_scale(const PhaseSeries& x, const AnalysisResult& a);
/// The five-term analysis, its fit range widened (to τ ≥ 1 s, then all τ) when it leaves too few
/// Allan points.
AnalysisResult analyze_for_base(const Recording& rec, const AnalysisOptions& aopt);
/// Whether a floating series is pulse counts given as numbers: its first 10⁵ increments are
/// integer multiples of the smallest one, a step coarse against their scatter (a finely
/// quantized ADC read-out is not counting).
bool on_lattice(const PhaseSeries& x);
/// The series with the deterministic terms of `det` removed: floating phase.
PhaseSeries cleaned(const PhaseSeries& x, const NoiseModel& det);

}  // namespace rwcalc::diag
