// Outlier screening of a record: detection, its report and the chosen action (outlier_screen.hpp).
#include "rwcalc/outlier_screen.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <cmath>

#include "rwcalc/error.hpp"

namespace rwcalc {

OutlierAction parse_outlier_action(std::string_view s) {
  if (s == "keep") return OutlierAction::Keep;
  if (s == "remove") return OutlierAction::Remove;
  if (s == "replace") return OutlierAction::Replace;
  throw UsageError(trf("--outliers: '{}' is not one of keep, remove, replace", s));
}

std::string_view to_string(OutlierAction a) {
  switch (a) {
    case OutlierAction::Keep: return "keep";
    case OutlierAction::Remove: return "remove";
    case OutlierAction::Replace: return "replace";
  }
  return "?";
}

namespace {

void check_outlier_threshold(double threshold) {
  if (!(threshold >= kMinOutlierThreshold) || !std::isfinite(threshold))
    throw UsageError(
        trf("--outlier-threshold must be a finite number >= {:g} robust sigma (below it the "
            "noise's own tails are flagged), got {}",
            kMinOutlierThreshold, threshold));
}

/// Refuse to remove or replace more than kMaxOutlierShare of the rate samples (outliers.hpp).
void check_outlier_share(const Recording& rec, OutlierAction action, double threshold, std::size_t found) {
  const std::size_t rates = rec.phase.points() - 1;
  if (action == OutlierAction::Keep || static_cast<double>(found) <= kMaxOutlierShare * static_cast<double>(rates))
    return;
  throw UsageError(
      trf("{}: --outliers {} would change {} of {} rate samples ({:.3g} %, more than {:g} %) at --outlier-threshold "
          "{:g}: so many are not isolated outliers but the noise itself, a burst or a step; nothing was analysed. "
          "Raise --outlier-threshold (default {:g}) or use --outliers keep to see where they are",
          rec.source, action == OutlierAction::Remove ? "remove" : "replace", found, rates,
          100.0 * static_cast<double>(found) / static_cast<double>(rates), 100.0 * kMaxOutlierShare, threshold,
          kDefaultOutlierThreshold));
}

/// The rest of the report (action and threshold are set) of a finished scan, located in the input.
void report_outliers(const Recording& rec, OutlierAction action, const OutlierScale& scale,
                     const std::vector<Outlier>& found, OutlierReport& rep) {
  rep.scale_deg_per_h = scale.scale;
  rep.count = found.size();
  // Rate sample i comes from data sample i (pulses, rate) or i+1 (counter, angle: the later reading).
  const std::size_t shift = rec.samples > rec.phase.points() - 1 ? 1 : 0;
  for (std::size_t k = 0; k < found.size() && k < kMaxOutlierPositions; ++k) {
    const auto& o = found[k];
    rep.positions.push_back({o.index, static_cast<double>(o.index + shift) * rec.phase.tau0_s,
                             rec.line_of_rate(o.index), o.value, o.robust_z});
  }
  if (action == OutlierAction::Remove) rep.removed = found.size();
  if (action == OutlierAction::Replace) rep.replaced = found.size();
}

}  // namespace

const Recording& screen_outliers(const Recording& read, OutlierAction action, double threshold, OutlierReport& report,
                                 Recording& edited) {
  check_outlier_threshold(threshold);
  report = OutlierReport{};
  report.action = action;
  report.threshold = threshold;
  if (read.phase.points() < 3) return read;  // too short to screen; the caller says so
  const OutlierScale scale = outlier_scale(read.phase);
  const std::vector<Outlier> found = find_outliers(read.phase, threshold, scale);
  check_outlier_share(read, action, threshold, found.size());
  report_outliers(read, action, scale, found, report);
  if (action == OutlierAction::Keep || found.empty()) return read;
  edited = Recording{};
  edited.source = read.source;
  edited.phase = apply_outliers(read.phase, found, action);
  edited.rate_hz = read.rate_hz;
  edited.rate_source = read.rate_source;
  edited.samples = read.samples - report.removed;
  edited.metadata = read.metadata;
  edited.temperature_c = read.temperature_c;
  edited.column_name = read.column_name;
  edited.time_column = read.time_column;
  edited.mode = read.mode;
  edited.counter_wraps = read.counter_wraps;
  return edited;
}

nlohmann::json to_json(const OutlierReport& o, double rate_factor) {
  nlohmann::json pos = nlohmann::json::array();
  for (const auto& p : o.positions)
    pos.push_back({{"index", p.index},
                   {"time_s", p.time_s},
                   {"line", p.line},
                   {"value", p.value * rate_factor},
                   {"robust_z", p.robust_z}});
  return {{"action", std::string(to_string(o.action))},
          {"threshold_robust_z", o.threshold},
          {"scale", o.scale_deg_per_h * rate_factor},
          {"count", o.count},
          {"removed", o.removed},
          {"replaced", o.replaced},
          {"positions_listed", o.positions.size()},
          {"positions", pos}};
}

namespace {
constexpr std::size_t kReportOutliers = 20;  // rows of the readable list; the JSON has up to kMaxOutlierPositions
}  // namespace

std::string format_outliers(const OutlierReport& o, std::string_view unit, double factor) {
  std::string s =
      unit.empty()
          ? trf("Outliers (rate samples more than {:g} robust sigma from the median of their 6 neighbours; scale {} "
                "°/h)\n",
                o.threshold, fmt::format("{:.3g}", o.scale_deg_per_h))
          : trf("Outliers (samples more than {:g} robust sigma from the median of their 6 neighbours; scale {} {})\n",
                o.threshold, fmt::format("{:.3g}", o.scale_deg_per_h * factor), unit);
  if (o.count == 0) return s + tr("  none found\n\n");
  switch (o.action) {
    case OutlierAction::Keep:
      s += trf("  {} found; KEPT in the analysis below (--outliers remove or replace to leave them out)\n", o.count);
      break;
    case OutlierAction::Remove:
      s += trf("  {} found; {} REMOVED: the samples after each one move one period earlier (a splice)\n", o.count,
               o.removed);
      break;
    case OutlierAction::Replace:
      s += trf("  {} found; {} REPLACED by the median of their four nearest good neighbours\n", o.count, o.replaced);
      break;
  }
  const std::string value = unit.empty() ? tr("rate (°/h)") : trf("value ({})", unit);
  s += fmt::format("  {:>10} {:>12} {:>10} {:>14} {:>9}\n", tr("sample"), tr("time (s)"), tr("line"), value, "z");
  for (std::size_t k = 0; k < o.positions.size() && k < kReportOutliers; ++k) {
    const auto& p = o.positions[k];
    s += fmt::format("  {:>10} {:>12.6g} {:>10} {:>14.6g} {:>+9.1f}\n", p.index, p.time_s, p.line, p.value * factor,
                     p.robust_z);
  }
  if (o.count > kReportOutliers)
    s += trf("  … and {} more (the first {} are listed in --json)\n", o.count - kReportOutliers, o.positions.size());
  return s + "\n";
}

}  // namespace rwcalc
