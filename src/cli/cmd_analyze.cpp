// Placeholder registration for 'rwcalc analyze' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_analyze(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("analyze", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc analyze' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
