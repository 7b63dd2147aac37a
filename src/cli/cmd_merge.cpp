// 'rwcalc merge LINES.jsonl…': the batch tables and overall verdict from JSON lines written by
// 'rwcalc batch --jsonl', e.g. on many machines (GNU parallel, a Slurm job array).
#include <memory>
#include <utility>

#include "batch_format.hpp"
#include "commands.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/saved_results.hpp"

namespace rwcalc::cli {

namespace {

struct MergeCmd {
  std::vector<std::string> files;
  TableFormat format;
  std::string output = "-";
  bool force = false;
  bool dedupe = false;
};

}  // namespace

void register_merge(CLI::App& app, Runner& runner) {
  auto cmd = std::make_shared<MergeCmd>();
  auto* sub = app.add_subcommand("merge", tr("Build the batch tables and overall verdict from JSON lines written by "
                                             "'rwcalc batch --jsonl' (runs analysed on many machines)"));
  sub->add_option("LINES", cmd->files, tr("JSON-lines files"))->required();
  cmd->format.add_to(*sub);
  add_output_options(*sub, cmd->output, cmd->force, N_("Overwrite an existing output file"));
  sub->add_flag("--dedupe", cmd->dedupe,
                tr("Keep one of repeated identical lines of a run (a re-queued job); lines of the same run "
                   "(same \"source\") that differ are refused all the same"));
  sub->callback([cmd, &runner] {
    runner = [cmd](Io& io) -> int {
      check_output_targets({{"-o", cmd->output}}, cmd->force);  // before the reading
      std::vector<SavedRun> lines;
      for (const auto& f : cmd->files)
        for (auto& r : load_json_lines(f, RunKeys::Combined)) lines.push_back(std::move(r));
      emit(io, cmd->format.render(merge_runs(std::move(lines), cmd->dedupe)), cmd->output, cmd->force);
      return 0;
    };
  });
}

}  // namespace rwcalc::cli
