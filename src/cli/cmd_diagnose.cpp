// 'rwcalc diagnose FILE': compare the measurement with simulations of its fitted five-term model,
// name what the model misses, extend the model and measure the gain (docs/diagnosis.md).
#include <cstdio>
#include <memory>
#include <ostream>

#include "analyze_args.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "plot_args.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"

namespace rwcalc::cli {

namespace {

struct DiagnoseCmd {
  std::string file;
  InputArgs input;
  AnalyzeArgs analysis;
  std::optional<double> temperature;
  bool json = false;
  std::size_t runs = 50;
  std::uint64_t seed = 1;
  double alpha = 0.01;
  std::string output = "-";
  PlotArgs plot;
  bool force = false;
};

}  // namespace

DiagnoseResult diagnose_showing_progress(const Recording& rec, DiagnoseOptions opt, std::FILE* sink) {
  Progress progress(trf("diagnosing {} (likelihood tests)", printable(rec.source)), 5, sink);
  opt.progress = &progress;
  return diagnose(rec, opt);
}

void register_diagnose(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<DiagnoseCmd>();
  auto* sub = app.add_subcommand(
      "diagnose",
      tr("Where simulations of the fitted five-term model depart from the measurement, the named cause "
         "(sinusoid, Gauss–Markov, bias step, warm-up transient, low-pass), the extended model and its gain"));
  sub->add_option("FILE", cmd->file, tr("Recording to diagnose ('-' for standard input)"))->required();
  cmd->input.add_to(*sub);
  cmd->analysis.add_to(*sub);
  sub->add_option("--temperature", cmd->temperature, tr("Temperature of the run, °C (overrides the file)"))
      ->check(real_in(kMinTemperatureC, kMaxTemperatureC, "deg C"));
  sub->add_flag("--json", cmd->json, tr("Print the JSON object instead of the report"));
  sub->add_option("--runs", cmd->runs,
                  tr("Accepted for earlier scripts (at least 10); the diagnosis simulates no records"))
      ->check(whole_in(10, 100000))
      ->capture_default_str();
  sub->add_option("--seed", cmd->seed, tr("Recorded in the output only: no finding depends on a seed"))
      ->check(whole_in(0, UINT64_MAX))
      ->capture_default_str();
  sub->add_option("--false-alarm", cmd->alpha, tr("False-alarm probability of each of the five detectors"))
      ->check(real_in(1e-6, 0.2, ""))
      ->capture_default_str();
  sub->add_option("-o,--output", cmd->output, tr("Write to FILE instead of standard output"))
      ->check(output_name())
      ->capture_default_str();
  sub->add_flag("--force", cmd->force, tr("Overwrite existing output, figure and script files"));
  cmd->plot.add_to(*sub,
                   N_("the measured Allan deviation against the simulated bands of the base and the extended model"));
  sub->callback([cmd, &runner] {
    runner = [cmd](Io& io) -> int {
      // Refuse bad figure names and existing outputs before the simulations rather than after them.
      cmd->plot.check(cmd->force, {{"-o", cmd->output}});
      DiagnoseOptions opt;
      opt.analysis = cmd->analysis.options();
      opt.analysis.temperature_c = cmd->temperature;
      opt.runs = cmd->runs;
      opt.seed = cmd->seed;
      opt.alpha = cmd->alpha;
      ReadOptions read = cmd->input.options();
      read.progress = io.progress;
      const Recording rec = read_recording(cmd->file, read);
      print_input_notes(io.err, rec);
      const DiagnoseResult res = diagnose_showing_progress(rec, opt, io.progress);
      const nlohmann::json j = to_json(res);
      // A file name that is not UTF-8 is written with U+FFFD for its invalid bytes, not refused.
      const std::string text = cmd->json ? j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"
                                         : localize_numbers(format_report(res));
      if (cmd->output == "-")
        io.out << text;
      else
        write_file_atomic(cmd->output, text, cmd->force);
      cmd->plot.draw_diagnosis(j, cmd->force, io);
      return 0;
    };
  });
}

}  // namespace rwcalc::cli
