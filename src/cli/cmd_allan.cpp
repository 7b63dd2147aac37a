// Placeholder registration for 'rwcalc allan' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_allan(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("allan", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc allan' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
