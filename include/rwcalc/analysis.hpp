#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/analysis.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file analysis.hpp
/// The `rwcalc analyze` pipeline (Allan variance, fit, cross-checks, bias, verdict) and its outputs.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/methods.hpp"
#include "rwcalc/outlier_screen.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/sensor.hpp"
#include "rwcalc/validate.hpp"
#include "rwcalc/verdict.hpp"

namespace rwcalc {

struct AnalysisOptions {
  AllanOptions allan;  ///< default: overlapping AVAR on the octave grid
  FitOptions fit;
  MethodOptions methods;
  VerdictOptions verdict;
  /// The Earth-rate removal and the class verdict: unset, on for pulse or counter input (a
  /// ring-laser gyro on the test stand's vertical axis) and off for other input, a MEMS or other
  /// gyro whose orientation and class table nobody gave; true asks for them (--vertical,
  /// --earth-rate, --latitude; --limits). Never for an accelerometer.
  std::optional<bool> earth_rate, verdict_wanted;
  double latitude_deg = 55.75;                          ///< for the vertical Earth rate Ω_E·sin(lat)
  std::optional<double> earth_rate_deg_per_h;           ///< overrides the latitude
  std::optional<double> temperature_c;                  ///< overrides the recording's temperature
  OutlierAction outlier_action = OutlierAction::Keep;   ///< outliers are always reported
  double outlier_threshold = kDefaultOutlierThreshold;  ///< robust z (see outliers.hpp)
  /// The user chose the fit range (`--fit-range`): it is kept as given. Otherwise, with the
  /// default range, an output filter seen in the short-τ points moves the fit's lower end.
  bool fit_range_given = false;
  /// The checks of the fit (short-τ range, scaling of a rejected fit, warnings) and the per-τ bounds
  /// from the fitted model. Off: the plain five-term fit over the range given and Stable32's bounds
  /// (diagnose's base model, whose departures its detectors explain).
  bool fit_checks = true;
  /// The paper's cross-checks and the class verdict; off for a fit that only feeds a model (the
  /// diagnosis's base fits), where the direct-N bootstrap would be spent for nothing.
  bool cross_checks = true;
  /// Where progress lines go (progress.hpp): analyze() shows how far the analysis is, analyze_files
  /// and analyze_imu how many runs or channels are done; nullptr: none.
  std::FILE* progress = nullptr;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// Something the reader must know about a result: a stable code, a sentence, and a command that
/// helps (may be empty).
struct AnalysisWarning {
  std::string code;     ///< "fit_rejected", "output_filter"
  std::string message;  ///< one or two sentences, with the numbers
  std::string command;  ///< a suggested command line ("" when none)
};

/// How the fit's τ range was chosen.
struct FitRangeChoice {
  enum class Source { All, Option, ShortTau } source = Source::All;
  double tau_min_s = 0;  ///< as applied, s
  double tau_max_s = 0;  ///< as applied, s (infinite: no upper limit)
  /// ShortTau: the short-τ points depart from the extrapolation of the model fitted from
  /// reference_tau_s: an output filter (the AV at τ0 is shortest_ratio of it; equivalent first-order
  /// time constant filter_tc_s, 0: none) and/or a departure up to departure_tau_s (AV ratio there).
  double shortest_ratio = 1;
  double filter_tc_s = 0;
  double departure_tau_s = 0;
  double departure_ratio = 1;
  double reference_tau_s = 0;
  /// Spectral lines of the rate (peaks 10× the local level of its Welch spectrum) whose Allan
  /// variance, computed from the spectrum's excess, was taken off the octave points before the fit:
  /// each with its frequency, rms (phase unit/s), peak over the local level, and the largest share
  /// of an octave point's AV it carried (and that point's τ). Lines below 1 % everywhere are ignored.
  struct Line {
    double f_hz = 0;
    double rms = 0;
    double peak_ratio = 0;
    double max_share = 0;
    double tau_at_max_s = 0;
  };
  std::vector<Line> lines;
  /// Octave points left out of the fit because the lines carry more than 90 % of their AV.
  int line_points_left_out = 0;
  /// The fit from the short-τ check's range was rejected (χ²/dof rejected_chi2) and the lower τ moved
  /// up an octave at a time (to at most 32 τ0) until it was accepted: short-τ structure (a line or
  /// a filter) whose tail also bends the check's reference points. 0: no such move.
  double rejected_chi2 = 0;
  double rejected_from_tau_s = 0;  ///< the lower τ of that rejected fit, s
  /// The fit was rejected (p < 0.001) and its intervals scaled by √(χ²/dof) (FitOptions::dispersion).
  bool intervals_scaled = false;
  double interval_scale = 1;                 ///< √(χ²/dof) of the unscaled fit, when scaled
  [[nodiscard]] std::string reason() const;  ///< why the range is what it is, one sentence
};

/// Where a rejected fit departs most from its points: the run of neighbouring points on one side of
/// the model (each beyond 2 standard errors) with the largest Gamma deviance, and what structure that is.
struct FitMisfit {
  double tau_from_s = 0, tau_to_s = 0;  ///< the departing points' range, s
  double worst_tau_s = 0;               ///< the point of the largest departure, s
  double ratio = 1;                     ///< measured / model AV there
  double sigmas = 0;                    ///< the departure there in standard errors of the point
  std::string structure;                ///< what it is, one phrase ("" when the fit is accepted)
};

/// A fit whose goodness-of-fit p-value is below this is rejected: its intervals are scaled by
/// √(χ²/dof) and the class verdict is withheld (docs/analysis.md, "When the fit fails").
inline constexpr double kFitRejectedP = 0.001;

struct AnalysisResult {
  std::string source;
  /// Gyro or accelerometer: the fit's coefficients are in the kind's fit-scale units (sensor.hpp);
  /// accelerometers have no Earth rate and no class verdict.
  SensorKind sensor = SensorKind::Gyro;
  std::size_t samples = 0;
  double rate_hz = 0;
  double duration_s = 0;
  std::string column;
  nlohmann::json input;         ///< input_json() of the recording as read
  double arcsec_per_count = 0;  ///< pulse weight (0 when the input was not pulses/counter)
  std::optional<double> temperature_c;
  std::string temperature_source;  ///< "option", "column or metadata", "file name", or ""
  double mean_rate_deg_per_h = 0;
  double earth_rate_deg_per_h = 0;
  double latitude_deg = 0;  ///< NaN-free: the latitude used (0 when the rate was given)
  bool earth_rate_given = false;
  /// Whether the Earth rate was subtracted and the class verdict applies (AnalysisOptions), and why
  /// not when they are off (one sentence; empty when both are on).
  bool earth_rate_applied = true;
  bool verdict_applies = true;
  std::string not_applied_reason;
  double bias_deg_per_h = 0;  ///< mean − expected Earth rate
  /// Allan deviation; for the overlapping estimator its EDF, bounds and α come from the fitted
  /// model (EDF = 2σ⁴/Var(σ̂²) under the fit, α of the dominant term), not Stable32's noise id.
  AllanResult allan;
  bool model_bounds = false;  ///< allan's EDF and bounds are the fitted model's
  FitResult fit;
  FitRangeChoice fit_range;
  SlopeReadout slope;
  double slope_B_sigma = 0;               ///< standard error of σ_min/0.6643 (from b_min)
  AvBEstimate b_min;                      ///< σ_min/0.6643 with its model-EDF interval and bias factor
  DirectNResult direct;                   ///< unbiased direct N and the paper's straight line
  AvBEstimate b100;                       ///< B from the 100-s averages (unbiased in B²)
  BlockSpreadResult avg100;               ///< raw spread of 100-s mean rates (≈ 1.5 B), beside its expectation
  double N_direct_discrepancy_sigma = 0;  ///< (N_direct − N_fit)/σ
  double B_100s_discrepancy_sigma = 0;    ///< (B from 100-s averages − B_fit)/σ
  double B_100s_vs_model_sigma = 0;       ///< (spread − its expectation under the fit)/σ
  OutlierReport outliers;
  Verdict verdict;
  std::vector<AnalysisWarning> warnings;
  /// `--gaps segments`: the segments the record was split into at its gaps (empty: no gap).
  std::vector<Recording::Segment> segments;
  /// The goodness of fit rejects the fit (p < kFitRejectedP).
  [[nodiscard]] bool fit_rejected() const { return fit.p_value < kFitRejectedP; }
};

/// Gyro or accelerometer data. Throws UsageError for clock data, AnalysisError for a record too short
/// or without noise.
AnalysisResult analyze(const Recording& rec, const AnalysisOptions& options = {});

/// The class verdict of an analysed gyro record under other verdict options (another B estimate,
/// class table or tolerance in `options.verdict`), as analyze would have decided it, without
/// analysing again: withheld, as there, when the fit is rejected. analyze's own verdict is this.
[[nodiscard]] Verdict verdict_under(const AnalysisResult& r, const AnalysisOptions& options);

/// What was read and how (the `input` object of analyze and allan JSON): column, kind, unit, rate
/// and its source, the time column and its unit, the jitter, and the reader's notes and warnings.
nlohmann::json input_json(const Recording& rec);

/// The JSON object of an analysis (`rwcalc analyze --json`, each run of `batch`, each channel of
/// `imu`), its numbers in the `shown` units: one schema for every sensor kind and unit
/// (docs/result-json.md, docs/result.schema.json).
nlohmann::json to_json(const AnalysisResult& r, const UnitSet& shown);
/// The same in the sensor's usual units (output_units(r.sensor)).
nlohmann::json to_json(const AnalysisResult& r);

/// The readable report.
std::string format_report(const AnalysisResult& r);

/// "WARNINGS" block of the readable report (empty when there are none).
std::string format_warnings(const std::vector<AnalysisWarning>& warnings);

/// "  segments: 2 (…)": how a record with gaps was split (`--gaps segments`), one line; "" without.
std::string format_segments(const AnalysisResult& r);
/// {count, samples, durations_s, gaps: [{line, missing_s}]}, or null without gaps.
nlohmann::json segments_json(const AnalysisResult& r);

/// Temperature from a file name: m50C → −50, p25C → 25, -50C, +25C, _0C (°C). Empty if none.
std::optional<double> temperature_from_name(std::string_view path);

/// Vertical Earth rate at a latitude, °/h.
double vertical_earth_rate(double latitude_deg);

/// JSON of an Allan result (the object `rwcalc allan --json` prints).
nlohmann::json allan_json(const AllanResult& a);
/// The same with the deviations in `unit`, `factor` times the result's.
nlohmann::json allan_json(const AllanResult& a, double factor, const std::string& unit);

}  // namespace rwcalc
