#pragma once
#ifndef RWCALC_USES_DIAGNOSE
#error "rwcalc/diagnose.hpp belongs to the diagnose layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file diagnose.hpp
/// `rwcalc diagnose`: fit the five-term model, test each candidate effect by a likelihood ratio of
/// the record's block means under the noise model (levels profiled, thresholds from the test's
/// null law), estimate the named effects with profile intervals, and measure the extended model's
/// gain in and out of sample (docs/diagnosis.md). No decision reads a random number.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/termination.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

class Progress;

struct DiagnoseOptions {
  AnalysisOptions analysis;      ///< the base fit (as `rwcalc analyze`)
  std::size_t runs = 50;         ///< kept for the command line's stability; no stage reads it
  std::uint64_t seed = 1;        ///< recorded only: no decision and no band depends on a seed
  double band_level = 0.95;      ///< central probability of the band (2.5–97.5 %)
  double alpha = 0.01;           ///< false-alarm level of each detector family
  Progress* progress = nullptr;  ///< unused: the diagnosis takes about a second

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// The effects the diagnosis can name, in the order they are named and estimated.
enum class Effect { Sinusoid, Line, BiasStep, Warmup, GaussMarkov, Lowpass };
inline constexpr std::size_t kEffectCount = 6;
/// The detector's name in the output ("sinusoid", "sinusoid_hf", "bias_step", …).
std::string_view detector_name(Effect e);
/// The finding's name in the output: the detector's, except "sinusoid" for a high-frequency line.
std::string_view finding_name(Effect e);

/// One τ of a band: the measured deviation against the model's σ and its χ² quantiles.
struct BandPoint {
  double tau_s = 0;
  double dev = 0;       ///< measured σ(τ), °/h
  double edf = 0;       ///< EDF of the measured point
  double low = 0;       ///< (1 − level)/2 quantile of the measured σ under the model, °/h
  double high = 0;      ///< (1 + level)/2 quantile, °/h
  double median = 0;    ///< the model's σ, °/h
  double mean_var = 0;  ///< the model's σ², (°/h)²
};

/// One detector family's verdict: its likelihood ratio against the model it was last tested on.
struct DetectorResult {
  Effect effect = Effect::Sinusoid;
  double statistic = 0;        ///< −2 Δ ln L, noise levels profiled under both hypotheses
  double threshold = 0;        ///< the statistic whose p-value bound is α
  double threshold_upper = 0;  ///< the same (kept for readers of the older output)
  double p_value = 1;          ///< bound on the false-alarm probability of the statistic
  std::string test;            ///< the test and its null law
  bool fired = false;          ///< p_value ≤ α
  bool excess = false;         ///< always false (kept for readers of the older output)
  bool named = false;          ///< named (a competing explanation named first may take it)
  std::string note;            ///< why it was not named although it fired, or not tested
};

/// What a finding's parameter measures; it sets the unit the parameter is shown in (a rate in °/h
/// for a gyro, in the level unit of an accelerometer, sensor.hpp).
enum class Quantity { Frequency, Rate, Time, Phase };

/// One estimated parameter of a named effect, in the fit's units (°/h for a rate, Hz, s, rad).
struct FindingParameter {
  std::string name;  ///< "frequency", "amplitude", "phase", "time", "size", "time_constant", "sigma", …
  Quantity quantity = Quantity::Rate;
  double value = 0;
  double standard_uncertainty = std::numeric_limits<double>::quiet_NaN();  ///< NaN: not estimated
  double low95 = std::numeric_limits<double>::quiet_NaN();                 ///< 95 % interval; NaN: not estimated
  double high95 = std::numeric_limits<double>::quiet_NaN();                ///<
};

/// A named effect: its parameters and the evidence (statistic, threshold, p-value, the test).
struct Finding {
  Effect effect = Effect::Sinusoid;
  std::vector<FindingParameter> parameters;
  nlohmann::json evidence;
  /// The parameter called `name`; std::out_of_range when the effect has none of that name.
  [[nodiscard]] const FindingParameter& parameter(std::string_view name) const;
};

struct Gain {
  double misfit_base = 0, misfit_extended = 0;      ///< EDF-weighted AV misfit (≈ 1 when the model fits)
  double coverage_base = 0, coverage_extended = 0;  ///< share of measured τ inside the band
  /// −2 Δ ln L of the base against the extended model over the tests that named the terms, less 2
  /// per parameter the extended model adds (Akaike): positive when the extended model is the better
  /// description. NaN (JSON null) when nothing was named, the extended model then being the base.
  double likelihood_in_sample = 0;
  /// The same on held-out data, uncharged: each half of the record scored given the other half
  /// by the models fitted on that other half, summed over the two halves.
  double likelihood_holdout = 0;
};

struct DiagnoseResult {
  AnalysisResult analysis;      ///< the base fit
  SimulationSettings settings;  ///< length, rate, pulse weight of the simulations
  NoiseModel base;
  NoiseModel extended;
  std::vector<BandPoint> base_band;  ///< the measured AV against the base model
  std::vector<BandPoint> extended_band;
  std::vector<DetectorResult> detectors;
  std::vector<Finding> findings;
  Gain gain;
  std::size_t runs = 0;
  std::uint64_t seed = 0;
  double band_level = 0.95;
  double alpha = 0.01;
  double seconds = 0;       ///< wall time of the diagnosis, s
  Termination termination;  ///< the likelihood fits of the base and the final model, both searches
};

/// Run the diagnosis. Throws UsageError for clock data, AnalysisError when the record is too
/// short (the detectors need at least 20 min of data) or cannot be fitted.
DiagnoseResult diagnose(const Recording& rec, const DiagnoseOptions& options = {});

/// The JSON object of `rwcalc diagnose --json` (docs/diagnosis.md).
nlohmann::json to_json(const DiagnoseResult& r);

/// The readable report (units on every number).
std::string format_report(const DiagnoseResult& r);

/// Measured-versus-model misfit on a band: mean over τ of ν·(r − 1 − ln r), r = σ̂²/σ², with ν the
/// measured EDF and a 1000-EDF model floor. About 1 per point when the model is right.
double band_misfit(const std::vector<BandPoint>& band);

/// Share of the band's τ whose measured σ lies inside [low, high].
double band_coverage(const std::vector<BandPoint>& band);

}  // namespace rwcalc
