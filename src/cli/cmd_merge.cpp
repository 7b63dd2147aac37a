// Placeholder registration for 'rwcalc merge' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_merge(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("merge", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc merge' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
