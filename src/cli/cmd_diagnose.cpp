// Placeholder registration for 'rwcalc diagnose' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_diagnose(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("diagnose", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc diagnose' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
