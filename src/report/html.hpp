#pragma once
// The HTML test report's look and cells (report.cpp), for the other pages and sections that share
// it (`imu --report`, imu_report.cpp; the test protocol, protocol.cpp).
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/report.hpp"
#include "shown_results.hpp"

namespace rwcalc::html {

/// The report's stylesheet (the contents of its <style>): screen and A4 print layout with the page
/// number, in the current language; `page_prefix` (CSS string text) goes before "Page N of M".
[[nodiscard]] std::string stylesheet(const std::string& page_prefix = "");
/// Outside text escaped for HTML content and quoted attributes, control characters made visible.
[[nodiscard]] std::string text(std::string_view s);
/// The same, shown as typed (no decimal comma put into it).
[[nodiscard]] std::string typed(std::string_view s);
/// A coefficient cell: "value ± σ" with the 95 % interval below, or "< bound" when unresolved.
[[nodiscard]] std::string coefficient_cell(const shown::CoefficientValues& c);
/// The mark of a value that is not available ("—").
[[nodiscard]] std::string not_available();
/// A key–value row: the key as text, the value as HTML.
[[nodiscard]] std::string kv_row(std::string_view key, const std::string& value_html);
/// A table row of a run: its file name and temperature, then the cells (HTML).
[[nodiscard]] std::string run_row(const shown::Analysis& run, const std::vector<std::string>& cells);
/// A verdict's class cell: "no verdict" when it is withheld, else the class `c` (one of its own).
[[nodiscard]] std::string verdict_class(const shown::Verdict& verdict, const shown::ClassValue& c);
/// A verdict in words: the class, its probability and, below 90 %, the runner-up (empty when the
/// verdict has no probabilities).
[[nodiscard]] std::string verdict_in_words(const shown::Verdict& verdict,
                                           const std::optional<std::vector<int>>& classes);
/// A class number as text, "outside" for a class beyond the table.
[[nodiscard]] std::string class_text(const shown::ClassValue& c);
/// The distinct values of an input identification over the runs, joined by "; " (HTML).
[[nodiscard]] std::string identification_values(const std::vector<shown::Analysis>& runs, shown::Id id);
/// The first page as a test protocol (options.profile must be set): approval, number and date, the
/// test, instruments, conditions, results in brief, conclusion and signature lines.
[[nodiscard]] std::string protocol_block(const std::vector<shown::Analysis>& runs,
                                         const std::vector<std::size_t>& order, const shown::Verdict& overall,
                                         const ReportOptions& options, const std::string& title);

}  // namespace rwcalc::html
