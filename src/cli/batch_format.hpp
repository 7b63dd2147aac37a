#pragma once
// Output shared by the commands: the table formats of 'rwcalc batch' and 'rwcalc merge' (same
// tables from the same objects), and where a command's text goes (emit).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "rwcalc/batch.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc::cli {

/// A file name that is not UTF-8 is written with U+FFFD for its invalid bytes, not refused.
inline constexpr auto kInvalidUtf8 = nlohmann::json::error_handler_t::replace;

struct TableFormat {
  bool json = false, csv = false, markdown = false, jsonl = false;
  inline void add_to(CLI::App& app) {
    auto* g = app.add_option_group(tr("Output format"), tr("default: the readable tables"));
    g->add_flag("--json", json, "{\"runs\": [analyze objects], \"overall\": {...}, \"trends\": {...}}");
    g->add_flag("--csv", csv, tr("One CSV row per run, then the overall row"));
    g->add_flag("--markdown", markdown, tr("The table in Markdown"));
    g->add_flag("--jsonl", jsonl, tr("One analyze JSON object per line (input of 'rwcalc merge')"));
    g->require_option(0, 1);
  }
  /// The runs are taken over (moved in): the summary holds them without a deep copy.
  [[nodiscard]] inline std::string render(std::vector<nlohmann::json> runs) const {
    if (jsonl) {
      std::string s;
      for (const auto& r : runs) s += r.dump(-1, ' ', false, kInvalidUtf8) + "\n";
      return s;
    }
    const nlohmann::json summary = summarize_runs(std::move(runs));
    if (json) return summary.dump(2, ' ', false, kInvalidUtf8) + "\n";
    if (csv) return format_batch_csv(summary);
    // The readable formats in the chosen language's number style; JSON and CSV keep the point.
    if (markdown) return localize_numbers(format_batch_markdown(summary));
    return localize_numbers(format_batch_text(summary));
  }
};

/// -o,--output FILE (default "-": standard output) and --force.
inline void add_output_options(CLI::App& app, std::string& output, bool& force,
                               const char* force_help = N_("Overwrite existing output, figure and script files")) {
  app.add_option("-o,--output", output, tr("Write to FILE instead of standard output"))
      ->check(output_name())
      ->capture_default_str();
  app.add_flag("--force", force, tr(force_help));
}

/// The command's text to standard output ("-") or to the file, atomically.
inline void emit(Io& io, const std::string& text, const std::string& output, bool force) {
  if (output == "-")
    io.out << text;
  else
    write_file_atomic(output, text, force);
}

}  // namespace rwcalc::cli
