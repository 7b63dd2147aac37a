#include "rwcalc/cli.hpp"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <optional>
#include <ostream>
#include <vector>

#include "cli/commands.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

namespace {
constexpr const char* kDescription =
    "rwcalc: Allan-variance noise analysis of gyro recordings (GL-2D ring laser gyro and others),\n"
    "noise coefficients with uncertainties, navigation accuracy class verdicts (GOST RV 52339),\n"
    "simulation of gyro records and diagnosis of what the noise model misses.";
}

namespace {

void build_app(CLI::App& app, Runner& runner) {
  app.set_version_flag("-V,--version", std::string("rwcalc ") + RWCALC_VERSION);
  app.require_subcommand(1);
  app.fallthrough(false);
  register_allan(app, runner);
  register_analyze(app, runner);
  register_batch(app, runner);
  register_merge(app, runner);
  register_simulate(app, runner);
  register_diagnose(app, runner);
  register_report(app, runner);
}

/// Parse argv into `app`. Returns the exit status to stop with (help, version, a parse error),
/// or nothing when a command should run.
std::optional<int> parse_args(CLI::App& app, int argc, const char* const* argv, std::ostream& out,
                              std::ostream& err) {
  try {
    std::vector<std::string> args;
    for (int i = argc - 1; i > 0; --i) args.emplace_back(argv[i]);
    app.parse(args);
  } catch (const CLI::CallForHelp&) {
    out << app.help();
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::CallForVersion&) {
    out << "rwcalc " << RWCALC_VERSION << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    // Help requested on a subcommand comes through here as a Success-coded error.
    if (e.get_exit_code() == 0) {
      for (const auto* sub : app.get_subcommands()) out << sub->help();
      if (app.get_subcommands().empty()) out << app.help();
      return 0;
    }
    err << "rwcalc: " << e.what() << "\n";
    if (app.get_subcommands().empty())
      err << "Run 'rwcalc --help' for the list of commands.\n";
    else
      err << "Run 'rwcalc " << app.get_subcommands().front()->get_name() << " --help' for its options.\n";
    return static_cast<int>(ExitCode::BadInput);
  }
  return std::nullopt;
}

}  // namespace

int parse_only(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    CLI::App app{kDescription, "rwcalc"};
    Runner runner;
    build_app(app, runner);
    if (const auto status = parse_args(app, argc, argv, out, err)) return *status;
    if (!runner) {
      err << "rwcalc: no command given; run 'rwcalc --help'\n";
      return static_cast<int>(ExitCode::BadInput);
    }
    return 0;
  } catch (const Error& e) {
    err << "rwcalc: error: " << e.what() << "\n";
    return static_cast<int>(e.code());
  }
}

int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{kDescription, "rwcalc"};
  Runner runner;
  build_app(app, runner);
  Io io{out, err};
  if (const auto status = parse_args(app, argc, argv, out, err)) return *status;

  try {
    if (!runner) {
      err << "rwcalc: no command given; run 'rwcalc --help'\n";
      return static_cast<int>(ExitCode::BadInput);
    }
    return runner(io);
  } catch (const Error& e) {
    err << "rwcalc: error: " << e.what() << "\n";
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    err << "rwcalc: error: out of memory\n";
    return static_cast<int>(ExitCode::AnalysisFailed);
  } catch (const std::exception& e) {
    err << "rwcalc: internal error: " << e.what() << "\n";
    return static_cast<int>(ExitCode::AnalysisFailed);
  }
}

}  // namespace rwcalc::cli
