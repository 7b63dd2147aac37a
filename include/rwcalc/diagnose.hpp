#pragma once
/// @file diagnose.hpp
/// `rwcalc diagnose`: fit the five-term model, simulate an ensemble of records from it, compare
/// the measurement with the ensemble (the band of σ per τ, one detector per effect calibrated on
/// the ensemble), estimate the detected effects, and measure the extended model's gain in and out
/// of sample (docs/diagnosis.md).
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc {

class Progress;

struct DiagnoseOptions {
  AnalysisOptions analysis;      ///< the base fit (as `rwcalc analyze`)
  std::size_t runs = 50;         ///< ensemble size K of each simulated band
  /// Records of the base model whose statistics set the detectors' thresholds (0: 4K); the band
  /// and the mid-τ reference take the first K of them.
  std::size_t calibration_runs = 0;
  std::size_t holdout_runs = 0;  ///< ensemble size of the out-of-sample check (0: K)
  std::uint64_t seed = 1;        ///< base seed of every ensemble
  double band_level = 0.95;      ///< central probability of the band (2.5–97.5 %)
  double alpha = 0.01;           ///< false-alarm level of each detector
  Progress* progress = nullptr;  ///< advanced once per simulated record (may be null)
};

/// The records diagnose() simulates with `opt` when it names nothing: the pilot and the calibration
/// ensembles, the total its progress counts to. What it finds decides how many more it simulates
/// (recalibration, the extended model, the out-of-sample check; often several times as many), so
/// its progress line shows the count alone beyond this total.
[[nodiscard]] std::uint64_t simulated_records(const DiagnoseOptions& opt);

/// The effects the diagnosis can name, in the order they are named and estimated.
enum class Effect { Sinusoid, Line, BiasStep, Warmup, GaussMarkov, Lowpass };
inline constexpr std::size_t kEffectCount = 6;
/// The detector's name in the output ("sinusoid", "sinusoid_hf", "bias_step", …).
std::string_view detector_name(Effect e);
/// The finding's name in the output: the detector's, except "sinusoid" for a high-frequency line.
std::string_view finding_name(Effect e);

/// One τ of a band: the measured deviation against the ensemble's quantiles.
struct BandPoint {
  double tau_s = 0;
  double dev = 0;       ///< measured σ(τ), °/h
  double edf = 0;       ///< EDF of the measured point
  double low = 0;       ///< ensemble (1 − level)/2 quantile of σ, °/h
  double high = 0;      ///< ensemble (1 + level)/2 quantile of σ, °/h
  double median = 0;    ///< ensemble median of σ, °/h
  double mean_var = 0;  ///< ensemble mean of σ², (°/h)²
};

/// One detector's verdict: its statistic on the measurement against the ensemble calibration.
struct DetectorResult {
  Effect effect = Effect::Sinusoid;
  double statistic = 0;  ///< on the measurement
  double threshold = 0;  ///< the ensemble's (1 − α) quantile (never below the maximum of fewer than 1/α)
  /// Monte-Carlo standard error of the threshold (the ensemble is finite) and its upper 95 %
  /// confidence limit: an effect is named only above it, so that another seed names it too.
  double threshold_sigma = 0, threshold_upper = 0;
  double ensemble_max = 0;
  double ensemble_median = 0;
  bool fired = false;   ///< statistic > threshold
  bool excess = false;  ///< fired, but not above the threshold's upper limit: "excess, not named"
  bool named = false;   ///< kept as a finding (a competing explanation may win)
  std::string note;    ///< why it was not named although it fired, or not tested
};

/// A named effect: parameters (JSON keys as simulate's model reads them), 1σ uncertainties and
/// evidence.
struct Finding {
  Effect effect = Effect::Sinusoid;
  nlohmann::json params;       ///< e.g. {"frequency_hz": …, "amplitude_deg_per_h": …}
  nlohmann::json uncertainty;  ///< same keys, standard errors
  nlohmann::json evidence;     ///< statistic, threshold, where it shows
};

struct Gain {
  double misfit_base = 0, misfit_extended = 0;      ///< EDF-weighted AV misfit (≈ 1 when the model fits)
  double coverage_base = 0, coverage_extended = 0;  ///< share of measured τ inside the band
  /// Out of sample (fit on one block, predict a neighbour); NaN (JSON null) when nothing was
  /// named, the extended model then being the base.
  double holdout_misfit_base = 0, holdout_misfit_extended = 0;
};

struct DiagnoseResult {
  AnalysisResult analysis;      ///< the base fit
  SimulationSettings settings;  ///< length, rate, pulse weight of the simulations
  NoiseModel base;
  NoiseModel extended;
  std::vector<BandPoint> base_band;
  std::vector<BandPoint> extended_band;
  std::vector<DetectorResult> detectors;
  std::vector<Finding> findings;
  /// Candidates that fired but whose extended model did not predict the held-out blocks better
  /// than the base (their parameters and figures; not in the extended model).
  std::vector<Finding> rejected;
  Gain gain;
  std::size_t runs = 0;
  std::size_t holdout_runs = 0;
  std::size_t calibration_runs = 0;
  std::uint64_t seed = 0;
  double band_level = 0.95;
  double alpha = 0.01;
  double seconds = 0;  ///< wall time of the diagnosis, s
};

/// Run the diagnosis. Throws UsageError for clock data, AnalysisError when the record is too
/// short (the detectors need at least 20 min of data) or cannot be fitted.
DiagnoseResult diagnose(const Recording& rec, const DiagnoseOptions& options = {});

/// The JSON object of `rwcalc diagnose --json` (docs/diagnosis.md).
nlohmann::json to_json(const DiagnoseResult& r);

/// The readable report (units on every number).
std::string format_report(const DiagnoseResult& r);

/// Measured-versus-ensemble misfit on a band: mean over τ of ν·(r − 1 − ln r), r = σ̂²/E σ², with
/// ν the measured EDF combined with the ensemble's own sampling error and a 1000-EDF model floor.
/// About 1 per point when the model is right.
double band_misfit(const std::vector<BandPoint>& band, std::size_t runs);

/// Share of the band's τ whose measured σ lies inside [low, high].
double band_coverage(const std::vector<BandPoint>& band);

}  // namespace rwcalc
