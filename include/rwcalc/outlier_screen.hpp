#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/outlier_screen.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file outlier_screen.hpp
/// Outlier screening as every command that analyses a record does it: detection, report of
/// where in the input, and the action chosen (--outliers keep|remove|replace).
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/outliers.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

/// One detected outlier, located in the input.
struct OutlierPosition {
  std::size_t index = 0;  ///< rate sample index (0-based; see Recording::rates)
  double time_s = 0;      ///< time of its data line from the first sample, s (index of that line × τ0)
  std::size_t line = 0;   ///< 1-based input line
  double value = 0;       ///< the rate sample, °/h
  double robust_z = 0;    ///< residual from the neighbour median over the robust scale
};

/// What outlier detection found and what was done about it.
struct OutlierReport {
  OutlierAction action = OutlierAction::Keep;
  double threshold = kDefaultOutlierThreshold;
  double scale_deg_per_h = 0;              ///< robust scale of the neighbour-median residuals, °/h
  std::size_t count = 0;                   ///< outliers found
  std::size_t removed = 0;                 ///< rate samples dropped (Remove)
  std::size_t replaced = 0;                ///< rate samples replaced by their local median (Replace)
  std::vector<OutlierPosition> positions;  ///< the first kMaxOutlierPositions, in input order
};
inline constexpr std::size_t kMaxOutlierPositions = 1000;

/// Detects and reports the outliers of `read`, then applies the action: returns `read` when the
/// data stay as read, else `edited`. Throws UsageError for a threshold that is not positive.
const Recording& screen_outliers(const Recording& read, OutlierAction action, double threshold, OutlierReport& report,
                                 Recording& edited);

/// The "Outliers" section of the readable reports, and the JSON "outliers" object. The scale and
/// the rates are in °/h, or, given a unit label (an accelerometer's "µg"), in it: the report's
/// values (phase unit per second) times `factor`.
std::string format_outliers(const OutlierReport& report, std::string_view unit = {}, double factor = 1);
/// The outlier summary; the rates (the scale, each position's value) `rate_factor` times the report's.
nlohmann::json to_json(const OutlierReport& report, double rate_factor = 1);

/// Parse "keep", "remove" or "replace" (UsageError otherwise).
OutlierAction parse_outlier_action(std::string_view s);
std::string_view to_string(OutlierAction a);

}  // namespace rwcalc
