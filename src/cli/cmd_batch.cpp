// Placeholder registration for 'rwcalc batch' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_batch(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("batch", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc batch' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
