// 'rwcalc batch FILES…': analyse many runs in parallel and print the paper's Tables 1 and 2, the
// overall verdict over the temperature range and the trends; or one JSON line per run (--jsonl)
// for 'rwcalc merge'.
#include <fmt/format.h>

#include <memory>
#include <ostream>
#include <utility>

#include "analyze_args.hpp"
#include "batch_format.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "plot_args.hpp"
#include "rwcalc/batch.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc::cli {

namespace {

struct BatchCmd {
  std::vector<std::string> files;
  InputArgs input;
  AnalyzeArgs analysis;
  std::optional<double> temperature;
  TableFormat format;
  std::string output = "-";
  bool force = false;
  PlotArgs plot;
};

}  // namespace

void register_batch(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<BatchCmd>();
  auto* sub =
      app.add_subcommand("batch", tr("Analyse many runs (in parallel): Table 1 (N and B by each method per "
                                     "temperature), Table 2 (classes), overall verdict and temperature trends"));
  sub->add_option("FILES", cmd->files, tr("Recordings"))->required();
  cmd->input.add_to(*sub);
  cmd->analysis.add_to(*sub);
  add_temperature_option(*sub, cmd->temperature, tr("Temperature, °C (only with a single file)"));
  cmd->format.add_to(*sub);
  add_output_options(*sub, cmd->output, cmd->force);
  cmd->plot.add_to(*sub, N_("the paper's Fig. 1 (the Allan deviations of all runs overlaid) above Fig. 2 (the direct "
                            "method's angle variance against t with its regression line per run)"));
  sub->callback([cmd, &runner] {
    runner = [cmd](Io& io) -> int {
      AnalysisOptions opt = cmd->analysis.options();
      opt.progress = io.progress;
      if (cmd->temperature) {
        if (cmd->files.size() != 1)
          throw UsageError(tr("--temperature applies to a single file; name the temperature in each file instead"));
        opt.temperature_c = cmd->temperature;
      }
      cmd->plot.check(cmd->force, {{"-o", cmd->output}});
      ReadOptions read = cmd->input.options();
      read.progress = io.progress;
      auto runs = analyze_files(cmd->files, read, opt);
      for (const auto& run : runs) require_finite(run, run.value("source", std::string("batch")));
      for (const auto& run : runs) print_input_notes(io.err, run);
      if (cmd->plot.any()) cmd->plot.draw_batch(nlohmann::json{{"runs", runs}}, cmd->force, io);
      emit(io, cmd->format.render(std::move(runs)), cmd->output, cmd->force);
      return 0;
    };
  });
}

}  // namespace rwcalc::cli
