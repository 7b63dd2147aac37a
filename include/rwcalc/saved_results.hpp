#pragma once
/// @file saved_results.hpp
/// Reading back rwcalc's JSON (`analyze`, `batch`, `diagnose --json`, the lines of `batch
/// --jsonl`) as input of `report` and `merge`. Such files travel between machines, so every value
/// read is checked against its type and domain; a violation is an InputError naming the file,
/// the line and the key path. Keys rwcalc does not read are left alone.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

/// One analyze object read back, with where it came from.
struct SavedRun {
  nlohmann::json run;
  std::string file;
  std::size_t line = 0;
};

struct SavedResults {
  std::vector<SavedRun> analyses;
  std::vector<SavedRun> diagnoses;
  std::vector<nlohmann::json> overalls;  ///< the verdicts of `batch --json` files
};

/// The report shows what it finds (hand-made or older results may lack the class
/// probabilities); merge combines the verdicts, so every key the combination reads must be there.
enum class RunKeys { Shown, Combined };

/// One saved result (an analyze, batch or diagnose object) named `file`.
void parse_saved_result(std::string_view text, const std::string& file, SavedResults& into);

/// JSON lines, one analyze object per non-blank line.
std::vector<SavedRun> parse_json_lines(std::string_view text, const std::string& file, RunKeys keys);

/// Reads a saved-result file: `.jsonl` as JSON lines, anything else as one JSON object.
void load_saved_result(const std::string& path, SavedResults& into);

std::vector<SavedRun> load_json_lines(const std::string& path, RunKeys keys);

/// The runs that `merge` combines, in input order. Two lines with the same "source" are the same
/// run, and counting it twice would count its probabilities twice: refused, naming both places;
/// with `dedupe` a line equal to an earlier one is dropped (a re-queued job). Runs judged
/// against different class tables are refused too.
std::vector<nlohmann::json> merge_runs(std::vector<SavedRun> runs, bool dedupe);

}  // namespace rwcalc
