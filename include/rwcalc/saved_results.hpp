#pragma once
/// @file saved_results.hpp
/// Reading back the JSON that rwcalc writes — `analyze --json`, `batch --json`, `diagnose --json`
/// and the lines of `batch --jsonl` / `merge --jsonl` — as input of `report` and `merge`.
///
/// Such files travel between machines, so every value that rwcalc reads from them is checked
/// against its type and domain (finite numbers, probabilities in [0, 1], integer class numbers
/// listed in "classes", positive limits, …). Any violation is an InputError naming the file, the
/// line of the offending value (for JSON lines, the line's number) and its key path. Keys rwcalc
/// does not read are left alone.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

/// One run (an analyze object) read back, with where it came from.
struct SavedRun {
  nlohmann::json run;
  std::string file;
  std::size_t line = 0;  ///< line of the JSON line, or of the object in a JSON document
};

/// What saved results hold.
struct SavedResults {
  std::vector<SavedRun> analyses;
  std::vector<SavedRun> diagnoses;        ///< objects of `diagnose --json`
  std::vector<nlohmann::json> overalls;  ///< the verdicts of `batch --json` files, one per file
};

/// How much of an analyze object the reader needs: the report shows what it finds (hand-made or
/// older results may lack the class probabilities); merge combines the verdicts, so every key
/// the combination reads must be there.
enum class RunKeys { Shown, Combined };

/// Parses the text of one saved result named `file`: an analyze, batch or diagnose JSON object.
/// Throws InputError (file, line, key path) on anything else or on a value outside its domain.
void parse_saved_result(std::string_view text, const std::string& file, SavedResults& into);

/// Parses JSON lines (one analyze object per non-blank line) named `file`. Throws InputError
/// naming the file and the line.
std::vector<SavedRun> parse_json_lines(std::string_view text, const std::string& file, RunKeys keys);

/// Reads a saved-result file: `.jsonl` as JSON lines, anything else as one JSON object.
void load_saved_result(const std::string& path, SavedResults& into);

/// Reads a JSON-lines file.
std::vector<SavedRun> load_json_lines(const std::string& path, RunKeys keys);

/// The runs that `merge` combines, in input order. A run is identified by its "source" (the
/// recording's path as `batch` was given it): two lines with the same source are the same run, and
/// counting it twice would multiply its class probabilities into the verdict twice. Such a pair is
/// refused, naming both places (FILE:LINE); with `dedupe` a line that equals an earlier one (the
/// same JSON value: a re-queued job's output) is dropped, and two lines with the same source
/// that differ are still refused. Runs judged against different class tables (class numbers or
/// limits) are refused too, naming the line that differs from the first.
std::vector<nlohmann::json> merge_runs(std::vector<SavedRun> runs, bool dedupe);

}  // namespace rwcalc
