#include "plot_args.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <ostream>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/plot.hpp"

namespace rwcalc::cli {

namespace {

/// The figure of `j` drawn by `plot`, when asked for; notes and the files written go to io.err.
void draw(const PlotArgs& a, PlotResult (*plot)(const nlohmann::json&, const PlotOptions&), const nlohmann::json& j,
          bool force, Io& io) {
  if (!a.any()) return;
  PlotOptions o;
  o.output = a.plot;
  o.script = a.script;
  o.force = force;
  const PlotResult r = plot(j, o);
  for (const auto& note : r.notes) print_message(io.err, trf("note: {}", note));
  if (!a.plot.empty()) print_message(io.err, trf("figure written to {} ({} data series)", as_typed(a.plot), r.series));
  if (!a.script.empty()) print_message(io.err, trf("gnuplot script written to {}", as_typed(a.script)));
}

}  // namespace

void PlotArgs::add_to(CLI::App& app, const std::string& what) {
  app.add_option("--plot", plot,
                 trf("Draw {} into FILE with gnuplot; the format follows the extension: .svg, .png or .pdf", tr(what)))
      ->check(output_name())
      ->group(tr("Figures"));
  app.add_option("--plot-script", script,
                 tr("Write the gnuplot script of the figure (data inline) to FILE; alone it needs no gnuplot"))
      ->check(output_name())
      ->group(tr("Figures"));
}

void PlotArgs::check(bool force, const std::vector<OutputTarget>& others) const {
  if (!plot.empty()) plot_format_for(plot);  // UsageError for an unknown extension
  std::vector<OutputTarget> all = others;
  all.push_back({"--plot", plot});
  all.push_back({"--plot-script", script});
  check_output_targets(all, force);
  if (!plot.empty()) require_gnuplot();
}

void PlotArgs::draw_analysis(const nlohmann::json& analysis, bool force, Io& io) const {
  draw(*this, plot_analysis, analysis, force, io);
}

void PlotArgs::draw_batch(const nlohmann::json& batch, bool force, Io& io) const {
  draw(*this, plot_batch, batch, force, io);
}

void PlotArgs::draw_imu(const nlohmann::json& imu, bool force, Io& io) const { draw(*this, plot_imu, imu, force, io); }

void PlotArgs::draw_diagnosis(const nlohmann::json& diagnosis, bool force, Io& io) const {
  draw(*this, plot_diagnosis, diagnosis, force, io);
}

}  // namespace rwcalc::cli
