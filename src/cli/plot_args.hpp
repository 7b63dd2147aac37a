#pragma once
// '--plot FILE' and '--plot-script FILE', shared by 'rwcalc analyze', 'batch' and 'diagnose': the
// checks made before any analysis (format by extension, existing files without --force, gnuplot
// present) and the drawing from the command's JSON object.
#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc::cli {

struct PlotArgs {
  std::string plot;    ///< figure file (.svg, .png, .pdf); empty: none
  std::string script;  ///< gnuplot script with the data inline; empty: none

  /// Adds --plot and --plot-script; `what` describes the figure in the help text.
  void add_to(CLI::App& app, const std::string& what);
  [[nodiscard]] bool any() const { return !plot.empty() || !script.empty(); }
  /// Fails before the work: UsageError for an unknown extension or when two outputs of the
  /// command (--plot, --plot-script and the command's `others`, e.g. -o) name the same file,
  /// OutputError for a file that cannot be written (existing without `force`…) or (for --plot)
  /// when gnuplot cannot be run.
  void check(bool force, const std::vector<OutputTarget>& others) const;
  /// Draw the figure of a `rwcalc analyze --json` object; notes and the files written go to io.err.
  void draw_analysis(const nlohmann::json& analysis, bool force, Io& io) const;
  /// Draw Figs. 1 and 2 of a batch ({"runs": [...]}).
  void draw_batch(const nlohmann::json& batch, bool force, Io& io) const;
  /// Draw one panel per sensor kind of a `rwcalc imu --json` object.
  void draw_imu(const nlohmann::json& imu, bool force, Io& io) const;
  /// Draw the measurement against the base and extended bands of a `rwcalc diagnose --json` object.
  void draw_diagnosis(const nlohmann::json& diagnosis, bool force, Io& io) const;
};

}  // namespace rwcalc::cli
