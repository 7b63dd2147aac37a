// The figures of `rwcalc imu`: one panel per sensor kind, every axis' Allan deviation and fitted model in it,
// from the result as the report shows it (shown_results.hpp).
#include <fmt/format.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/quantity_text.hpp"
#include "shown_figures.hpp"

namespace rwcalc {

PlotResult plot_imu(const nlohmann::json& imu, const PlotOptions& options) {
  require_valid(options);
  const auto shown_imu = shown::read_imu(imu);
  std::vector<Figure> figures;
  constexpr std::string_view kGyro = "gyro";
  for (const std::string_view kind : {kGyro, std::string_view("accelerometer")}) {
    std::vector<shown::Analysis> runs;
    for (const auto& c : shown_imu.channels) {
      if (c.sensor != kind) continue;
      shown::Analysis run = c;
      // The axis label in the unit's printed form, in the current language; as a non-gyro unit it
      // also keeps the class limits (a ring-laser table) out of a figure of several axes.
      run.allan.unit = unit_text(c.allan.unit);
      runs.push_back(std::move(run));
    }
    if (runs.empty()) continue;
    PlotOptions o = options;
    if (o.title.empty())
      o.title = trf_either(kind == kGyro, N_("Gyro axes of {}"), N_("Accelerometer axes of {}"),
                           std::filesystem::path(shown_imu.source).filename().string());
    Figure f = shown::imu_axes_figure(runs, o);
    f.name = fmt::format("imu-{}", kind);
    figures.push_back(std::move(f));
  }
  if (figures.empty()) throw AnalysisError(tr("the imu result has no channels: nothing to plot"));
  PlotResult result;
  for (const auto& f : figures) result.series += f.series;
  check_output_targets({{"--plot", options.output}, {"--plot-script", options.script}}, options.force);
  const PlotFormat format = options.output.empty() ? PlotFormat::Svg : plot_format_for(options.output);
  if (!options.script.empty()) {
    const std::string target = options.output.empty()
                                   ? std::filesystem::path(options.script).replace_extension(".svg").string()
                                   : options.output;
    write_file_atomic(options.script, full_script(figures, format, options.width_px, target), options.force);
  }
  if (!options.output.empty())
    write_file_atomic(options.output, render_figures(figures, format, options.width_px), options.force);
  return result;
}

}  // namespace rwcalc
