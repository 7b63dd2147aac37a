#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/batch.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file batch.hpp
/// Many runs at once (analysed here or merged from JSON lines) in the seed paper's Table 1/Table 2
/// layout, with the overall verdict and trends with temperature; built from analyze JSON objects.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

/// The analyze JSON objects of `files` in file order; throws the first failing file's error.
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
