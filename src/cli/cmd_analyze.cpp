// 'rwcalc analyze FILE': Allan variance, noise coefficients with uncertainties, the paper's
// cross-checks, Earth rate and bias, and the class verdict, as a report or JSON.
#include <fmt/format.h>

#include <memory>
#include <ostream>

#include "cli/analyze_args.hpp"
#include "cli/commands.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "timing.hpp"

namespace rwcalc::cli {

namespace {

struct AnalyzeCmd {
  std::string file;
  InputArgs input;
  AnalyzeArgs analysis;
  std::optional<double> temperature;
  bool json = false;
  std::string output = "-";
  std::string plot;
  bool force = false;
};

}  // namespace

void register_analyze(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<AnalyzeCmd>();
  auto* sub = app.add_subcommand(
      "analyze",
      "Noise coefficients (Q, N, B, K, R) with 95 % intervals, the paper's cross-checks (direct N, "
      "100-s averages), Earth rate and bias, and the GOST RV 52339 class verdict with its probability");
  sub->add_option("FILE", cmd->file, "Recording to analyse ('-' for standard input)")->required();
  cmd->input.add_to(*sub);
  cmd->analysis.add_to(*sub);
  sub->add_option("--temperature", cmd->temperature, "Temperature of the run, °C (overrides the file)");
  sub->add_flag("--json", cmd->json, "Print the JSON object instead of the report");
  sub->add_option("-o,--output", cmd->output, "Write to FILE instead of standard output")->capture_default_str();
  sub->add_flag("--force", cmd->force, "Overwrite an existing output file");
  sub->add_option("--plot", cmd->plot, "Also draw the AV plot with the fit into FILE (where plotting is built in)");
  sub->callback([cmd, &runner] {
    runner = [cmd](Io& io) -> int {
      if (!cmd->plot.empty()) {
        // Hook for the plot command: a function taking the analyze JSON and the target file.
        throw UsageError("--plot: plotting is not available in this build");
      }
      AnalysisOptions opt = cmd->analysis.options();
      opt.temperature_c = cmd->temperature;
      detail::ScopedTimer total("analyze command");
      const Recording rec = [&] {
        detail::ScopedTimer t("read");
        return read_recording(cmd->file, cmd->input.options());
      }();
      const AnalysisResult res = analyze(rec, opt);
      const std::string text = [&] {
        detail::ScopedTimer t("format");
        return cmd->json ? to_json(res).dump(2) + "\n" : format_report(res);
      }();
      if (cmd->output == "-")
        io.out << text;
      else
        write_file_atomic(cmd->output, text, cmd->force);
      return 0;
    };
  });
}

}  // namespace rwcalc::cli
