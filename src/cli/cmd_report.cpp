// Placeholder registration for 'rwcalc report' (replaced by the command's implementation).
#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void register_report(CLI::App& app, Runner& runner) {
  auto* sub = app.add_subcommand("report", "(not yet available)");
  sub->callback([&runner] {
    runner = [](Io&) -> int { throw AnalysisError("'rwcalc report' is not available in this build"); };
  });
}

}  // namespace rwcalc::cli
