#pragma once
/// @file batch.hpp
/// Many runs at once: analyse files in parallel, or merge the JSON lines of runs analysed
/// elsewhere, into the seed paper's layout (Table 1: N by AV, N direct, B by AV, B by 100-s
/// averaging per temperature; Table 2: class per parameter) with the overall verdict over the
/// temperature range and the trend of each coefficient with temperature.
///
/// Both paths build the table from the analyze JSON objects (to_json(AnalysisResult)), so
/// `rwcalc batch` and `rwcalc merge` of its `--jsonl` lines print the same table.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

/// Analyse `files`, several at once (parallel.hpp). Each file's temperature comes from its
/// column/metadata, else its name. Returns the analyze JSON objects in file order. On failure
/// throws the error of the first failing file (in file order), naming it.
std::vector<nlohmann::json> analyze_files(const std::vector<std::string>& files, const ReadOptions& read,
                                          const AnalysisOptions& options);

/// {"runs": [...sorted by temperature...], "overall": {class_B, class_N, class, p_class,
/// statement, …}, "trends": {...}}. Throws InputError (naming `source`) on objects without the
/// analyze keys.
nlohmann::json summarize_runs(std::vector<nlohmann::json> runs, const std::string& source = "batch");

/// Tables for people (text), Markdown, CSV (one row per run, then the overall row).
std::string format_batch_text(const nlohmann::json& summary);
std::string format_batch_markdown(const nlohmann::json& summary);
std::string format_batch_csv(const nlohmann::json& summary);

}  // namespace rwcalc
