#pragma once
/// @file report.hpp
/// A test report a lab can file: one self-contained HTML page (figures inline, no external
/// resources) with the run summaries, the seed paper's Tables 1 and 2 (per temperature: N by the
/// Allan variance and by the direct method, B by the Allan variance and by 100-s averaging; the
/// class each of them gives), the verdict with its probability, the diagnosis when there is one,
/// the settings and the rwcalc version. It prints to PDF (print style sheet: no page breaks inside
/// tables or figures).
///
/// The generator takes the JSON objects of `rwcalc analyze --json` and `rwcalc diagnose --json`
/// (keys listed in docs/plots-and-reports.md), so it renders whatever produced them.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace rwcalc {

/// What goes into a report.
struct ReportInput {
  /// One `rwcalc analyze --json` object per run (any order; the tables sort by temperature).
  std::vector<nlohmann::json> analyses;
  /// Empty, or one `rwcalc diagnose --json` object per analysis (null where none was made).
  std::vector<nlohmann::json> diagnoses;
  /// Optional overall verdict of a batch ({"class_B", "class_N", "class", …}); when null the
  /// report states the worst class over the runs.
  nlohmann::json overall;
};

struct ReportOptions {
  std::string title = "Gyro noise test report";
  /// Settings shown in the report (option name → value), e.g. the command line's options.
  nlohmann::json settings = nlohmann::json::object();
  /// Embed figures (needs gnuplot); false writes the tables only, saying that figures were left out.
  bool figures = true;
  /// Text of the "generated" line (e.g. a UTC time stamp); empty leaves it out.
  std::string generated;
};

/// The HTML page. Throws AnalysisError when there is no analysis, OutputError when a figure
/// cannot be drawn (gnuplot missing or failing).
std::string report_html(const ReportInput& input, const ReportOptions& options);

/// Write `report_html` to DIR/report.html (DIR is created when missing) atomically; returns the
/// path written. An existing report is replaced only with `force` (OutputError otherwise).
std::string write_report(const std::string& dir, const ReportInput& input, const ReportOptions& options,
                         bool force);

/// Standard base64 (RFC 4648, with padding) of bytes, for inline figures.
std::string base64_encode(std::string_view bytes);

}  // namespace rwcalc
