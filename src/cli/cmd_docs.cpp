// `rwcalc man` and `rwcalc completion`: the manual page and the bash completion, generated from the
// same option definitions the parser uses, so that neither can fall behind the commands.
#include <fmt/format.h>

#include <algorithm>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/version.hpp"

namespace rwcalc::cli {

namespace {

/// Text for roff: backslashes doubled, minus signs escaped, and a line that would start with a
/// control character ('.' or '\'') protected by a zero-width escape.
std::string roff(std::string_view s) {
  std::string out;
  bool line_start = true;
  for (char c : s) {
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    if (c == '\\')
      out += "\\e";
    else if (c == '-')
      out += "\\-";
    else
      out += c;
    line_start = c == '\n';
  }
  return out;
}

/// "-h, --help", "--rate HZ" as the manual shows an option.
std::string option_synopsis(const CLI::Option& o) {
  std::string s;
  for (const auto& n : o.get_snames()) s += (s.empty() ? "-" : ", -") + n;
  for (const auto& n : o.get_lnames()) s += (s.empty() ? "--" : ", --") + n;
  // CLI11's type name carries the range check after a colon ("FLOAT:NUMBER in [1, 2]"); the
  // description says the range in words.
  const std::string type = o.get_type_name().substr(0, o.get_type_name().find(':'));
  if (o.get_expected_min() > 0 && !type.empty()) s += " " + type;
  return s;
}

std::vector<const CLI::App*> commands_of(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App* a) { return !a->get_name().empty(); });
}

/// A command's options, those of its option groups (CLI11's nameless subcommands) included.
std::vector<const CLI::Option*> options_of(const CLI::App& cmd, bool positional) {
  auto want = [positional](const CLI::Option* o) { return o->get_positional() == positional; };
  std::vector<const CLI::Option*> out = cmd.get_options(want);
  for (const CLI::App* group : cmd.get_subcommands([](const CLI::App* a) { return a->get_name().empty(); }))
    for (const CLI::Option* o : options_of(*group, positional)) out.push_back(o);
  return out;
}

/// The values an option takes when it names them as "a|b|c" (its option text); none otherwise.
std::vector<std::string> option_values(const CLI::Option& o) {
  const std::string& text = o.get_option_text();
  if (text.find('|') == std::string::npos) return {};
  std::vector<std::string> values;
  for (std::size_t at = 0; at <= text.size();) {
    const std::size_t end = std::min(text.find('|', at), text.size());
    values.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return values;
}

void man_command(std::ostream& out, const CLI::App& cmd) {
  std::string positional;
  for (const CLI::Option* o : options_of(cmd, true)) positional += " " + o->get_name();
  out << ".SS \"rwcalc " << roff(cmd.get_name()) << " [OPTIONS]" << roff(positional) << "\"\n";
  for (const auto& alias : cmd.get_aliases()) out << "Also spelt \\fB" << roff(alias) << "\\fR.\n.br\n";
  out << roff(cmd.get_description()) << "\n";
  for (const CLI::Option* o : options_of(cmd, false)) {
    out << ".TP\n.B " << roff(option_synopsis(*o)) << "\n" << roff(o->get_description());
    if (!o->get_default_str().empty()) out << " (default: " << roff(o->get_default_str()) << ")";
    out << "\n";
  }
}

/// Every environment variable rwcalc reads, with what it does.
constexpr std::pair<const char*, const char*> kEnvironment[] = {
    {"RWCALC_LANG",
     "Language of the text, tables, reports and messages when --lang is not given: en or ru (a locale "
     "name such as ru_RU.UTF-8 counts as ru). Default: en."},
    {"RWCALC_THREADS", "The most threads a command uses (default: every core). Results do not depend on it."},
    {"RWCALC_GNUPLOT", "The gnuplot program that draws the figures (default: gnuplot in PATH)."},
    {"RWCALC_CHROMIUM",
     "The headless Chromium that prints report --pdf (default: chromium, chromium-browser, "
     "google-chrome or google-chrome-stable in PATH)."},
    {"RWCALC_PANDOC", "The pandoc that writes report --docx (default: pandoc in PATH)."},
    {"RWCALC_HELPER_TIMEOUT",
     "Seconds a helper program (gnuplot, Chromium, pandoc) may run before it is stopped "
     "(default: 300)."},
    {"TMPDIR", "Where the private scratch directories of the helper programs are made (default: /tmp)."},
};

/// Commands a user starts from, with what each does.
constexpr std::pair<const char*, const char*> kExamples[] = {
    {"Noise coefficients, cross-checks and the class verdict of one recording:",
     "rwcalc analyze data/gl2d/gl2d_p50C.csv.gz"},
    {"The paper's Tables 1 and 2 over the temperature runs, with its figures:",
     "rwcalc batch data/gl2d/*.csv.gz --plot figs.svg"},
    {"The Allan deviation with the modified estimator on a dense grid, as CSV:",
     "rwcalc allan run.csv --estimator mdev --tau dense --csv"},
    {"A Russian test protocol of the runs as HTML, PDF and an editable DOCX:",
     "rwcalc report data/gl2d/*.csv.gz --lang ru --gyro GL-2D --lab-profile lab.yaml --protocol-number 17/2026 "
     "-o protocol --pdf --docx"},
    {"A simulated record from a noise model, then its diagnosis:",
     "rwcalc simulate -o sim.csv --arw 0.002 --bias-instability 0.004 && rwcalc diagnose sim.csv"},
    {"The noise files of a 6-axis IMU recording for a VIO package:",
     "rwcalc imu imu.csv --rate 200 --gyro gx,gy,gz --accel ax,ay,az --kalibr imu.yaml"},
};

void write_man(std::ostream& out, const CLI::App& app) {
  out << ".TH RWCALC 1 \"\" \"" << roff(version_line()) << "\" \"User Commands\"\n"
      << ".SH NAME\nrwcalc \\- Allan-variance noise analysis, noise coefficients and accuracy-class verdicts for "
         "gyro recordings\n"
      << ".SH SYNOPSIS\n.B rwcalc\n.I COMMAND\n[\\fIOPTIONS\\fR] \\fIFILE\\fR...\n.br\n.B rwcalc \\-\\-version\n"
      << ".SH DESCRIPTION\n"
      << roff(app.get_description()) << "\n";
  out << ".SH COMMANDS\n";
  for (const CLI::App* cmd : commands_of(app)) man_command(out, *cmd);
  out << ".SH ENVIRONMENT\n";
  for (const auto& [name, text] : kEnvironment) out << ".TP\n.B " << name << "\n" << roff(text) << "\n";
  out << ".SH EXAMPLES\n";
  for (const auto& [text, command] : kExamples)
    out << ".PP\n" << roff(text) << "\n.RS\n.nf\n" << roff(command) << "\n.fi\n.RE\n";
  out << ".SH EXIT STATUS\n0 success; 1 the analysis is impossible (e.g. a record too short); 2 bad input or usage; "
         "3 an output could not be written.\n"
      << ".SH SEE ALSO\n.BR gnuplot (1).\nThe documents under docs/ of the source tree: docs/analysis.md "
         "(methods), docs/input-formats.md, docs/diagnosis.md.\n";
}

/// The bash completion. Each candidate is one line of compgen's output taken whole (mapfile), never
/// split at blanks or expanded as a pattern, so that file names with blanks, '*' or '$' complete as
/// they are named.
void write_completion(std::ostream& out, const CLI::App& app) {
  std::string names;
  for (const CLI::App* cmd : commands_of(app)) {
    names += (names.empty() ? "" : " ") + cmd->get_name();
    for (const auto& alias : cmd->get_aliases()) names += " " + alias;
  }
  out << "# bash completion for rwcalc (generated by `rwcalc completion`)\n"
      << "_rwcalc() {\n"
      << "  local cur=\"${COMP_WORDS[COMP_CWORD]}\" prev=\"${COMP_WORDS[COMP_CWORD-1]}\" opts=\"\" values=\"\"\n"
      << "  if [[ $COMP_CWORD -eq 1 ]]; then\n"
      << "    mapfile -t COMPREPLY < <(compgen -W \"" << names << " --help --version\" -- \"$cur\")\n"
      << "    return\n  fi\n"
      << "  case \"${COMP_WORDS[1]}\" in\n";
  for (const CLI::App* cmd : commands_of(app)) {
    std::string opts, values;
    for (const CLI::Option* o : options_of(*cmd, false)) {
      std::string words;
      for (const auto& v : option_values(*o)) words += (words.empty() ? "" : " ") + v;
      for (const auto& n : o->get_lnames()) {
        opts += (opts.empty() ? "--" : " --") + n;
        if (!words.empty()) values += "        --" + n + ") values=\"" + words + "\" ;;\n";
      }
    }
    std::string label;  // the aliases, then the name: "analyse|analyze"
    for (const auto& alias : cmd->get_aliases()) label += alias + "|";
    label += cmd->get_name();
    out << "    " << label << ") opts=\"" << opts << "\"\n";
    if (!values.empty())
      out << "      case \"$prev\" in\n" << values << "      esac ;;\n";
    else
      out << "      ;;\n";
  }
  out << "  esac\n"
      << "  if [[ -n $values ]]; then\n"
      << "    mapfile -t COMPREPLY < <(compgen -W \"$values\" -- \"$cur\")\n"
      << "  elif [[ $cur == -* ]]; then\n"
      << "    mapfile -t COMPREPLY < <(compgen -W \"$opts\" -- \"$cur\")\n"
      << "  else\n"
      << "    mapfile -t COMPREPLY < <(compgen -f -- \"$cur\")\n"
      << "  fi\n"
      << "}\n"
      << "complete -o filenames -F _rwcalc rwcalc\n";
}

/// A documentation command: builds every command's options on a fresh app and writes `what`.
void register_doc(CLI::App& app, Runner& runner, const char* name, const char* description,
                  void (*write)(std::ostream&, const CLI::App&)) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->group(tr("Documentation"));
  sub->callback([&runner, write] {
    runner = [write](Io& io) {
      // The manual and the completion are English whatever the language: the options' texts are
      // taken from definitions made now, in English.
      const LanguageScope english(Language::English);
      CLI::App all{app_description(), "rwcalc"};
      Runner unused;
      add_all_commands(all, unused);
      write(io.out, all);
      return 0;
    };
  });
}

}  // namespace

void register_man(CLI::App& app, Runner& runner) {
  register_doc(app, runner, "man", tr("Print the manual page (roff; view with `rwcalc man | man -l -`)"), write_man);
}

void register_completion(CLI::App& app, Runner& runner) {
  register_doc(app, runner, "completion",
               tr("Print the bash completion script (`source <(rwcalc completion)`; installed by cmake --install)"),
               write_completion);
}

}  // namespace rwcalc::cli
