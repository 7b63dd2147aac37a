#pragma once
#ifndef RWCALC_USES_IO
#error "rwcalc/saved_results.hpp belongs to the io layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file saved_results.hpp
/// Reading back rwcalc's JSON (`analyze`, `batch`, `diagnose --json`, `batch --jsonl`) for
/// `report` and `merge`: every value read is checked (InputError naming file, line and key path).
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

/// Shown: only keys present are checked (report); Combined: the keys merge reads are required.
enum class RunKeys { Shown, Combined };

/// One saved result (an analyze, batch or diagnose object) named `file`.
void parse_saved_result(std::string_view text, const std::string& file, SavedResults& into);

/// JSON lines, one analyze object per non-blank line.
std::vector<SavedRun> parse_json_lines(std::string_view text, const std::string& file, RunKeys keys);

/// Reads a saved-result file: `.jsonl` as JSON lines, anything else as one JSON object.
void load_saved_result(const std::string& path, SavedResults& into);

std::vector<SavedRun> load_json_lines(const std::string& path, RunKeys keys);

/// The runs `merge` combines, in input order. A repeated "source" is refused (with `dedupe`, a
/// line equal to an earlier one is dropped), as are runs judged against other class tables.
std::vector<nlohmann::json> merge_runs(std::vector<SavedRun> runs, bool dedupe);

}  // namespace rwcalc
