#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/plot.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file plot.hpp
/// Figures of an analysis, a temperature batch and a diagnosis, drawn by gnuplot.
///
/// A figure is a gnuplot script that carries its data inline (`$name << EOD` blocks) and its
/// coefficients as named variables, so the script written with `--plot-script` reproduces the
/// figure on its own. gnuplot ($RWCALC_GNUPLOT, else `gnuplot` on PATH) renders into a private
/// temporary file that is then moved into place. The figures read the JSON of `analyze`, `batch`
/// and `diagnose --json` (keys in docs/plots-and-reports.md).
#include <cstddef>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/validate.hpp"

namespace rwcalc {

/// Output format of a figure, by the output file's extension (.svg, .png, .pdf).
enum class PlotFormat { Svg, Png, Pdf };

/// The format for a path's extension (case-insensitive). Throws UsageError for anything else.
PlotFormat plot_format_for(std::string_view path);

struct PlotOptions {
  std::string output;  ///< figure file (.svg, .png or .pdf); empty: none
  /// gnuplot script with the data inline; empty: none. Its `set output` names `output`, else the
  /// script path with ".svg".
  std::string script;
  std::string title;    ///< empty: a title built from the data
  int width_px = 960;   ///< canvas width (PDF: 96 px per inch)
  int height_px = 720;  ///< canvas height of one panel
  bool force = false;   ///< overwrite existing output files

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

struct PlotResult {
  std::vector<std::string> notes;  ///< parts left out, for the user
  int series = 0;                  ///< plotted data series over all panels
};

/// Allan deviation of one analysis with confidence bars, the fitted model, each term's line (an
/// unresolved term dashed at its 95 % bound) and the class limits for B as floors 0.6643·B.
/// Throws AnalysisError without Allan points, OutputError when writing or gnuplot fails.
PlotResult plot_analysis(const nlohmann::json& analysis, const PlotOptions& options);

/// A batch ({"runs": [...]}): the Allan deviations overlaid (the paper's Fig. 1) above the
/// direct-method angle variance per run (Fig. 2; left out, with a note, without curves).
PlotResult plot_batch(const nlohmann::json& batch, const PlotOptions& options);

/// A diagnosis: the measured Allan deviation against the simulated bands of the base and the
/// extended model.
PlotResult plot_diagnosis(const nlohmann::json& diagnosis, const PlotOptions& options);

/// An IMU (`rwcalc imu --json`): one panel per sensor kind with every axis' Allan deviation.
PlotResult plot_imu(const nlohmann::json& imu, const PlotOptions& options);

/// A figure as a gnuplot script body (no terminal or output lines).
struct Figure {
  std::string name;     ///< e.g. "allan", "batch-allan", "batch-direct"
  std::string script;   ///< data blocks, settings and plot command
  int series = 0;       ///< number of plot elements
  int height_px = 720;  ///< canvas height asked for
};

/// The figures behind the plot_* calls (also used by the HTML report). `runs` are analyses.
Figure analysis_figure(const nlohmann::json& analysis, const PlotOptions& options);
Figure batch_allan_figure(const nlohmann::json& runs, const PlotOptions& options);
/// Empty script and series == 0 when no run carries a direct-method curve.
Figure batch_direct_figure(const nlohmann::json& runs, const PlotOptions& options);
Figure diagnosis_figure(const nlohmann::json& diagnosis, const PlotOptions& options);
/// One sensor kind of an IMU: every axis' Allan deviation (`channels`, each an `imu --json` channel)
/// with its confidence bars and, in the same colour, its fitted model (from the fit's SI
/// coefficients and allan.unit_per_si).
Figure imu_axes_figure(const nlohmann::json& channels, const PlotOptions& options);

/// Render figures (stacked panels) to bytes in `format`. Throws OutputError when gnuplot is
/// missing or fails.
std::string render_figures(const std::vector<Figure>& figures, PlotFormat format, int width_px);

/// The complete script that render_figures runs, with `set output` naming `output_path`.
std::string full_script(const std::vector<Figure>& figures, PlotFormat format, int width_px,
                        const std::string& output_path);

/// `text` as a gnuplot string literal: single-quoted (no escapes, backquotes or macros expand
/// there; a quote is doubled), control characters and invalid bytes made visible by printable().
/// Every string that enters a script goes through here; figure texts are set noenhanced.
std::string gnuplot_string(std::string_view text);

/// $RWCALC_GNUPLOT when set and non-empty, else "gnuplot".
std::string gnuplot_command();

/// True when the gnuplot command answers `--version`.
bool gnuplot_available();

/// Throws OutputError, saying how to install gnuplot, when it cannot be run: lets a command fail
/// before its analysis rather than after.
void require_gnuplot();

/// "#rrggbb" of a run at `temperature_c` on a fixed cold-to-hot scale (blue at −50 °C, red at
/// +50 °C); runs without a temperature get a categorical colour by `index`.
std::string temperature_colour(const nlohmann::json& temperature_c, std::size_t index);

}  // namespace rwcalc
