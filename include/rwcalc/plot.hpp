#pragma once
/// @file plot.hpp
/// Figures of an analysis, a temperature batch and a diagnosis, drawn by gnuplot.
///
/// Each figure is a generated gnuplot script that carries its own data (inline `$name << EOD`
/// blocks) and its coefficients as named gnuplot variables, so the script written with
/// `--plot-script` reproduces the figure on its own and can be restyled by hand. Rendering runs
/// gnuplot as a subprocess (the binary named by the environment variable RWCALC_GNUPLOT, else
/// `gnuplot` on PATH) into a private temporary file, which is then moved into place atomically.
///
/// The figures read the JSON objects that `rwcalc analyze --json`, `rwcalc batch --json` and
/// `rwcalc diagnose --json` print; docs/plots-and-reports.md lists every key they consume. All
/// figures share one look: log-log axes with 10^n tick labels, τ in s, deviations in °/h, the
/// key outside the plot area, one colour per temperature (see temperature_colour).
#include <cstddef>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

/// Output format of a figure, chosen by the output file's extension.
enum class PlotFormat {
  Svg,  ///< ".svg": gnuplot's svg terminal
  Png,  ///< ".png": pngcairo (png when cairo is not built in)
  Pdf,  ///< ".pdf": pdfcairo
};

/// The format for a path's extension (case-insensitive). Throws UsageError for anything else.
PlotFormat plot_format_for(std::string_view path);

/// What to draw and where.
struct PlotOptions {
  /// Figure file (.svg, .png or .pdf). Empty: draw nothing (a script may still be written).
  std::string output;
  /// Where to write the gnuplot script with its data inline. Empty: no script. The script's
  /// `set output` names `output` (or, when that is empty, the script path with ".svg").
  std::string script;
  /// Title above the figure; empty: a title built from the data (file, temperature).
  std::string title;
  int width_px = 960;   ///< canvas width, pixels (PDF: converted at 96 px per inch)
  int height_px = 720;  ///< canvas height of one panel, pixels (the key sits below the plot)
  bool force = false;   ///< overwrite existing output files
};

/// What a plot call did, for the caller to tell the user.
struct PlotResult {
  /// Messages about parts left out (e.g. "no direct-method curve in the JSON: Fig. 2 skipped").
  std::vector<std::string> notes;
  /// Number of plotted data series (gnuplot plot elements) over all panels.
  int series = 0;
};

/// Allan deviation of one analysis (`rwcalc analyze --json`): the measured deviations with their
/// confidence bars, the fitted 5-term model, each term's own line (an unresolved term is drawn
/// dashed at its 95 % upper bound), and the GOST class limits for B as the AV floor levels
/// 0.6643·B_limit. Throws AnalysisError when the JSON lacks the Allan points, OutputError when
/// a file cannot be written or gnuplot is missing or fails.
PlotResult plot_analysis(const nlohmann::json& analysis, const PlotOptions& options);

/// A temperature batch (`rwcalc batch --json`): panel 1 overlays the Allan deviations of all runs
/// (the seed paper's Fig. 1); panel 2 shows the direct-method angle variance against interval
/// length with its regression line per run (Fig. 2). Panel 2 is skipped, with a note, when no run
/// carries `methods.N_direct_deg_per_sqrt_h.curve`.
PlotResult plot_batch(const nlohmann::json& batch, const PlotOptions& options);

/// A diagnosis (`rwcalc diagnose --json`): the measured Allan deviation against the simulated
/// ensemble band of the base model and of the extended model (`base_model.band`,
/// `extended_model.band`).
PlotResult plot_diagnosis(const nlohmann::json& diagnosis, const PlotOptions& options);

/// A figure as a self-contained gnuplot script body (no terminal or output lines).
struct Figure {
  std::string name;    ///< short identifier, e.g. "allan", "batch-allan", "batch-direct"
  std::string script;  ///< data blocks, settings and plot command(s)
  int series = 0;      ///< number of plot elements
  int height_px = 720; ///< suggested canvas height, pixels
};

/// The figure scripts behind the plot_* calls (used by the HTML report and the tests).
Figure analysis_figure(const nlohmann::json& analysis, const PlotOptions& options);
/// Fig. 1 of a batch: the Allan deviations overlaid. `runs` are analysis objects.
Figure batch_allan_figure(const nlohmann::json& runs, const PlotOptions& options);
/// Fig. 2 of a batch: the direct-method angle variance against interval length. Returns a figure
/// with an empty script and series == 0 when no run carries a curve.
Figure batch_direct_figure(const nlohmann::json& runs, const PlotOptions& options);
Figure diagnosis_figure(const nlohmann::json& diagnosis, const PlotOptions& options);

/// Render one or more figures (stacked panels when more than one) to bytes in `format`, at
/// width_px × (sum of panel heights). Throws OutputError when gnuplot is missing or fails.
std::string render_figures(const std::vector<Figure>& figures, PlotFormat format, int width_px);

/// The complete script (terminal, output, panels) that render_figures runs, with `set output`
/// naming `output_path`.
std::string full_script(const std::vector<Figure>& figures, PlotFormat format, int width_px,
                        const std::string& output_path);

/// `text` as a gnuplot string literal: single-quoted (gnuplot expands no escape, backquote or
/// macro there; a quote is doubled) with every control character and invalid byte made visible
/// by printable(), so the literal stays on its line and runs nothing. Every string that enters a
/// generated script goes through this one function. The figures set all their texts (titles,
/// labels, key) noenhanced, so enhanced-text markup (^ _ @ & { } \) shows as typed.
std::string gnuplot_string(std::string_view text);

/// The gnuplot command: $RWCALC_GNUPLOT when set and non-empty, else "gnuplot".
std::string gnuplot_command();

/// True when the gnuplot command can be run (it answers `--version`).
bool gnuplot_available();

/// Throws OutputError, saying how to install gnuplot or name it in RWCALC_GNUPLOT, when the
/// gnuplot command cannot be run: lets a command fail before its analysis rather than after.
void require_gnuplot();

/// Colour of a run at `temperature_c` as "#rrggbb": a fixed cold-to-hot scale (blue at −50 °C,
/// red at +50 °C), so the same temperature has the same colour in every figure. Runs without a
/// temperature get a categorical colour by `index`.
std::string temperature_colour(const nlohmann::json& temperature_c, std::size_t index);

}  // namespace rwcalc
