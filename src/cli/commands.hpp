#pragma once
// Internal to the command-line layer: each sub-command registers itself on the CLI11 app and
// returns a callable that runs it once parsing succeeded.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "rwcalc/memory.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {
struct DiagnoseOptions;
struct DiagnoseResult;
}  // namespace rwcalc

namespace rwcalc::cli {

/// Streams a command writes to.
struct Io {
  std::ostream& out;
  std::ostream& err;
  /// Where progress lines go (progress.hpp): standard error when it is a terminal and --quiet was
  /// not given; nullptr (none) otherwise.
  std::FILE* progress = nullptr;
};

using Runner = std::function<int(Io&)>;

/// diagnose() with its progress line on `sink` (Io::progress): the simulated records done.
DiagnoseResult diagnose_showing_progress(const Recording& rec, DiagnoseOptions opt, std::FILE* sink);

/// Print one message line, "rwcalc: TEXT", to `err`. TEXT goes through printable(): a newline,
/// an escape sequence or an invalid byte in a file name (or anywhere else in the text) shows as
/// \n, \x1b, \xff and cannot forge a line or drive the terminal. Every message goes through here.
void print_message(std::ostream& err, std::string_view text);

/// `--gaps refuse|segments` (ReadOptions::gaps_as_segments).
void add_gaps_option(CLI::App& app, std::string& gaps);

/// `--max-memory SIZE` (rwcalc/memory.hpp), checked as it is parsed; `size` stays empty when not given.
CLI::Option* add_memory_option(CLI::App& app, std::string& size);
/// The ceiling `--max-memory` names, or the default when it was not given.
MemoryCeiling memory_ceiling_of(const std::string& size);

/// The check every option naming an output file or directory carries: an empty name names none
/// (it would otherwise fail only when the finished file is moved into place).
CLI::Validator output_name();

/// Input options shared by every command that reads a recording (allan, analyze, batch, diagnose).
/// --time-column NAME, --time stamp|receive and --topic TOPIC: which stamps of a ROS export or bag
/// and which Imu topic of a bag are read.
struct SourceArgs {
  std::string time_column, time, topic;
  void add_to(CLI::App& app);
  void apply(ReadOptions& o) const;  ///< throws UsageError for --time with --time-column
};

struct InputArgs {
  SourceArgs source;
  std::string input;  ///< empty: not given (the column name may imply it; else pulses)
  std::string column;
  std::optional<double> rate_hz;
  std::optional<double> scale_arcsec;
  int counter_bits = 32;
  std::string angle_unit;  ///< empty: not given (the column name's suffix, else arcsec)
  std::string rate_unit;   ///< empty: not given (the column name's suffix, else deg/h)
  double time_tolerance = 0.01;
  std::string gaps = "refuse";                               ///< --gaps refuse|segments
  std::string max_memory;                                    ///< --max-memory; empty: the default ceiling
  std::string serial, operator_name, test_date, conditions;  ///< empty: the file's metadata, if any
  void add_to(CLI::App& app);
  [[nodiscard]] ReadOptions options() const;  ///< throws UsageError on bad names
};

/// The reader's warnings and notes on a recording (Recording::warnings, notes), one line each:
/// "rwcalc: warning: FILE: …", "rwcalc: note: FILE: …".
void print_input_notes(std::ostream& err, const Recording& rec);
/// The same from the `input` object of an analysis' JSON (batch).
void print_input_notes(std::ostream& err, const nlohmann::json& analysis);

// One per sub-command (src/cli/cmd_*.cpp). Each adds its subcommand to `app` and sets `runner`.
void register_allan(CLI::App& app, Runner& runner);
void register_analyze(CLI::App& app, Runner& runner);
void register_batch(CLI::App& app, Runner& runner);
void register_merge(CLI::App& app, Runner& runner);
void register_simulate(CLI::App& app, Runner& runner);
void register_diagnose(CLI::App& app, Runner& runner);
void register_imu(CLI::App& app, Runner& runner);
void register_report(CLI::App& app, Runner& runner);
void register_man(CLI::App& app, Runner& runner);         // src/cli/cmd_docs.cpp
void register_completion(CLI::App& app, Runner& runner);  // src/cli/cmd_docs.cpp

/// rwcalc's one-paragraph description (the top of --help and of the manual).
const char* app_description();
/// Every command on `app`, in the order of `rwcalc --help`.
void add_all_commands(CLI::App& app, Runner& runner);

}  // namespace rwcalc::cli
