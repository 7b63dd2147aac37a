// Placeholder registration for 'rwcalc simulate' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_simulate(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("simulate", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc simulate' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
