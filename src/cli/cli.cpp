#include "rwcalc/cli.hpp"

#include <fmt/args.h>
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <exception>
#include <memory>
#include <optional>
#include <ostream>
#include <regex>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/version.hpp"

namespace rwcalc::cli {

namespace {

/// CLI11's parse errors in the chosen language: its fixed English phrases, matched whole, with
/// the option names and values they carry kept as written (English text is unchanged).
std::string parse_error_text(const std::string& what) {
  struct Phrase {
    std::regex pattern;
    const char* message;  // msgid with one {} per group
  };
  static const std::vector<Phrase> phrases{
      {std::regex("The following arguments were not expected: (.*)"),
       N_("The following arguments were not expected: {}")},
      {std::regex("The following argument was not expected: (.*)"), N_("The following argument was not expected: {}")},
      {std::regex("A subcommand is required"), N_("A subcommand is required")},
      {std::regex("(.+) is required"), N_("{} is required")},
      {std::regex("The value (.+) is not an allowed value for (.+)"),
       N_("The value {} is not an allowed value for {}")},
      {std::regex("Could not convert: (.+) = (.*)"), N_("Could not convert: {} = {}")},
      {std::regex("(.+) requires (.+)"), N_("{} requires {}")},
      {std::regex("(.+) excludes (.+)"), N_("{} excludes {}")},
      {std::regex("Expected exactly (\\d+) arguments to (.+), got (\\d+)"),
       N_("Expected exactly {} arguments to {}, got {}")},
  };
  std::smatch m;
  for (const auto& p : phrases) {
    if (!std::regex_match(what, m, p.pattern)) continue;
    fmt::dynamic_format_arg_store<fmt::format_context> args;
    for (std::size_t i = 1; i < m.size(); ++i) args.push_back(m[i].str());
    return fmt::vformat(tr(p.message), args);
  }
  return what;
}
constexpr const char* kDescription =
    N_("rwcalc: Allan-variance noise analysis of gyro recordings (GL-2D ring laser gyro and others),\n"
       "noise coefficients with uncertainties, navigation accuracy class verdicts (GOST RV 52339),\n"
       "simulation of gyro records and diagnosis of what the noise model misses.");

struct Command {
  const char* name;
  void (*add)(CLI::App&, Runner&);
  const char* alias = nullptr;  ///< another spelling the command answers to (set by its register_*)
};
constexpr Command kCommands[] = {
    {"allan", register_allan},       {"analyze", register_analyze, "analyse"},
    {"batch", register_batch},       {"merge", register_merge},
    {"simulate", register_simulate}, {"diagnose", register_diagnose},
    {"imu", register_imu},           {"report", register_report},
    {"man", register_man},           {"completion", register_completion},
};

/// --lang and --quiet on every command that writes results or messages (not man and completion,
/// which describe the options themselves).
void add_common_options(CLI::App& sub) {
  const std::string name = sub.get_name();
  if (name == "man" || name == "completion") return;
  const std::string help =
      tr("Language of the text, tables, report and messages: en (default) or ru; default from RWCALC_LANG");
  sub.add_option("--lang", help)->check(CLI::IsMember({"en", "ru"}))->option_text("en|ru");
  sub.add_flag("-q,--quiet")->description(tr("No progress lines (shown on standard error only when it is a terminal)"));
}

/// Where the command's progress lines go: `terminal` (standard error when it is one), unless the
/// command was given --quiet.
std::FILE* progress_sink(const CLI::App& app, std::FILE* terminal) {
  for (const auto* sub : app.get_subcommands())
    if (const auto* opt = sub->get_option_no_throw("--quiet"); opt && opt->count() > 0) return nullptr;
  return terminal;
}

/// The language of the command line before it is parsed (the options' help texts are translated
/// when they are declared): the last "--lang X" or "--lang=X", else RWCALC_LANG, else English.
/// An unknown name counts as none here; the parse then refuses it.
Language prescanned_language(int argc, const char* const* argv) {
  std::optional<Language> lang;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--") break;
    if (a == "--lang" && i + 1 < argc)
      lang = parse_language(argv[++i]);
    else if (a.starts_with("--lang="))
      lang = parse_language(a.substr(7));
  }
  if (lang) return *lang;
  if (const char* env = std::getenv("RWCALC_LANG")) return parse_language(env).value_or(Language::English);
  return Language::English;
}

/// CLI11's help with the words it writes itself for an option group (its title, "at most one")
/// translated.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_expanded(const CLI::App* sub) const override {
    std::string e = CLI::Formatter::make_expanded(sub);
    const std::string_view title = "[Option Group: ";
    if (e.starts_with(title)) e.replace(0, title.size(), tr("[Option Group: "));
    return e;
  }
  std::string make_description(const CLI::App* app) const override {
    std::string d = CLI::Formatter::make_description(app);
    const std::string_view at_most = "[At most 1 of the following options are allowed]";
    if (const auto at = d.find(at_most); at != std::string::npos)
      d.replace(at, at_most.size(), tr("[At most 1 of the following options are allowed]"));
    return d;
  }
};

/// CLI11's own words in the help (its labels, the default option group, the help flag), in the
/// current language; set on the top-level app before the commands, which inherit them.
void translate_help_words(CLI::App& app) {
  app.option_defaults()->group(tr("Options"));  // before the flags, which take it when made
  app.set_help_flag("-h,--help", tr("Print this help message and exit"));
  auto f = std::make_shared<HelpFormatter>();
  app.formatter(f);
  for (const char* label : {N_("Usage"), N_("OPTIONS"), N_("SUBCOMMAND"), N_("SUBCOMMANDS"), N_("Positionals"),
                            N_("REQUIRED"), N_("Env"), N_("Needs"), N_("Excludes")})
    f->label(label, tr(label));
}

/// The language asked for: --lang, else RWCALC_LANG when it names one, else English.
Language chosen_language(const CLI::App& app) {
  for (const auto* sub : app.get_subcommands())
    if (const auto* opt = sub->get_option_no_throw("--lang"); opt && opt->count() > 0)
      return parse_language(opt->as<std::string>()).value_or(Language::English);
  if (const char* env = std::getenv("RWCALC_LANG")) return parse_language(env).value_or(Language::English);
  return Language::English;
}

/// The commands, in the order of `rwcalc --help`. When the first argument names one, only that one
/// is built (the parse is the same, without setting up the others' options); otherwise all, so
/// that the overall help and the unknown-command message list every command.
void build_app(CLI::App& app, Runner& runner, int argc, const char* const* argv) {
  translate_help_words(app);
  app.set_version_flag("-V,--version", version_line(), tr("Display program version information and exit"));
  app.require_subcommand(1);
  app.fallthrough(false);
  const auto translate_groups = [&app] {
    // A command takes its help flag before the parent's option defaults, and its group is
    // CLI11's English "Subcommands": both named in the current language here.
    for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      if (CLI::Option* help = sub->get_help_ptr()) help->group(app.option_defaults()->get_group());
      if (sub->get_group() == "Subcommands") sub->group(tr("Subcommands"));
    }
  };
  if (argc > 1)
    for (const auto& c : kCommands)
      if (std::string_view(argv[1]) == c.name || (c.alias && std::string_view(argv[1]) == c.alias)) {
        c.add(app, runner);
        add_common_options(*app.get_subcommand(c.name));
        translate_groups();
        return;
      }
  add_all_commands(app, runner);
  translate_groups();
}

/// Parse argv into `app`. Returns the exit status to stop with (help, version, a parse error),
/// or nothing when a command should run.
std::optional<int> parse_args(CLI::App& app, int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
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
    out << version_line() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    // Help requested on a subcommand comes through here as a Success-coded error.
    if (e.get_exit_code() == 0) {
      for (const auto* sub : app.get_subcommands()) out << sub->help();
      if (app.get_subcommands().empty()) out << app.help();
      return 0;
    }
    print_message(err, parse_error_text(e.what()));
    if (app.get_subcommands().empty())
      err << tr("Run 'rwcalc --help' for the list of commands.\n");
    else
      err << trf("Run 'rwcalc {} --help' for its options.\n", app.get_subcommands().front()->get_name());
    return static_cast<int>(ExitCode::BadInput);
  }
  return std::nullopt;
}

/// Parse argv and, when `execute`, run the command; the exit status. Without `execute`, anything
/// but an rwcalc error escapes: the argument-parsing fuzzer treats it as a finding.
int parse_and_run(int argc, const char* const* argv, std::ostream& out, std::ostream& err, bool execute,
                  std::FILE* progress) {
  const LanguageScope restore(language());  // the command sets its language; the caller's comes back after
  try {
    set_language(prescanned_language(argc, argv));
    CLI::App app{tr(app_description()), "rwcalc"};
    Runner runner;
    build_app(app, runner, argc, argv);
    if (const auto status = parse_args(app, argc, argv, out, err)) return *status;
    set_language(chosen_language(app));
    if (!runner) {
      print_message(err, tr("no command given; run 'rwcalc --help'"));
      return static_cast<int>(ExitCode::BadInput);
    }
    Io io{out, err, progress_sink(app, progress)};
    return execute ? runner(io) : 0;
  } catch (const InputError& e) {  // the file named as typed, the message in the language asked for
    const std::string where = as_typed(e.file()) + (e.line() > 0 ? fmt::format(":{}", e.line()) : "");
    print_message(err, trf("error: {}", fmt::format("{}: {}", where, e.message())));
    return static_cast<int>(e.code());
  } catch (const Error& e) {
    print_message(err, trf("error: {}", e.what()));
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    if (!execute) throw;
    print_message(err, tr("error: out of memory"));
    return static_cast<int>(ExitCode::AnalysisFailed);
  } catch (const std::exception& e) {
    if (!execute) throw;
    print_message(err, trf("internal error: {}", e.what()));
    return static_cast<int>(ExitCode::AnalysisFailed);
  }
}

}  // namespace

const char* app_description() { return kDescription; }

void add_all_commands(CLI::App& app, Runner& runner) {
  for (const auto& c : kCommands) {
    c.add(app, runner);
    add_common_options(*app.get_subcommand(c.name));
  }
}

CLI::Validator output_name() {
  return CLI::Validator(
      [](std::string& name) { return name.empty() ? std::string(tr("an empty name names no file")) : std::string(); },
      "");
}

void print_message(std::ostream& err, std::string_view text) { err << "rwcalc: " << localize_message(text) << "\n"; }

int parse_only(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  return parse_and_run(argc, argv, out, err, false, nullptr);
}

int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err, std::FILE* progress) {
  const int status = parse_and_run(argc, argv, out, err, true, progress);
  // The one place where every command's standard output (reports, tables, help) is flushed and
  // checked: a full disk or a closed descriptor must not end in status 0.
  try {
    flush_standard_output(out);
  } catch (const OutputError& e) {
    if (status != 0) return status;  // the command failed first and has said why
    print_message(err, fmt::format("error: {}", e.what()));
    return static_cast<int>(ExitCode::OutputFailed);
  }
  return status;
}

}  // namespace rwcalc::cli
