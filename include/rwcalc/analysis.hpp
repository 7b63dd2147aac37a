#pragma once
/// @file analysis.hpp
/// The `rwcalc analyze` pipeline (Allan variance, fit, cross-checks, bias, verdict) and its outputs.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "rwcalc/allan.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/methods.hpp"
#include "rwcalc/outlier_screen.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/verdict.hpp"

namespace rwcalc {

struct AnalysisOptions {
  AllanOptions allan;  ///< default: overlapping AVAR on the octave grid
  FitOptions fit;
  MethodOptions methods;
  VerdictOptions verdict;
  double latitude_deg = 55.75;                          ///< for the vertical Earth rate Ω_E·sin(lat)
  std::optional<double> earth_rate_deg_per_h;           ///< overrides the latitude
  std::optional<double> temperature_c;                  ///< overrides the recording's temperature
  OutlierAction outlier_action = OutlierAction::Keep;   ///< outliers are always reported
  double outlier_threshold = kDefaultOutlierThreshold;  ///< robust z (see outliers.hpp)
};

struct AnalysisResult {
  std::string source;
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
  double bias_deg_per_h = 0;  ///< mean − expected Earth rate
  AllanResult allan;
  FitResult fit;
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
};

/// Throws UsageError for clock data, AnalysisError for a record too short or without noise.
AnalysisResult analyze(const Recording& rec, const AnalysisOptions& options = {});

/// What was read and how (the `input` object of analyze and allan JSON): column, kind, unit, rate
/// and its source, the time column and its unit, the jitter, and the reader's notes and warnings.
nlohmann::json input_json(const Recording& rec);

/// The JSON object of `rwcalc analyze --json` (keys in docs/analysis.md).
nlohmann::json to_json(const AnalysisResult& r);

/// The readable report.
std::string format_report(const AnalysisResult& r);

/// Temperature from a file name: m50C → −50, p25C → 25, -50C, +25C, _0C (°C). Empty if none.
std::optional<double> temperature_from_name(std::string_view path);

/// Vertical Earth rate at a latitude, °/h.
double vertical_earth_rate(double latitude_deg);

/// JSON of an Allan result (the object `rwcalc allan --json` prints).
nlohmann::json allan_json(const AllanResult& a);

}  // namespace rwcalc
