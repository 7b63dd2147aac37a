#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/report.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file report.hpp
/// A test report a lab can file: one self-contained HTML page (figures inline) with the run
/// summaries, the seed paper's Tables 1 and 2, the verdict with its probability, the diagnoses,
/// the settings and the version. It prints to PDF. It renders the JSON of `analyze --json` and
/// `diagnose --json` (keys in docs/plots-and-reports.md).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rwcalc/i18n.hpp"
#include "rwcalc/lab_profile.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

struct ReportInput {
  std::vector<nlohmann::json> analyses;   ///< one analyze object per run, any order
  std::vector<nlohmann::json> diagnoses;  ///< empty, or one per analysis (null where none)
  nlohmann::json overall;                 ///< a batch's overall verdict; null: the worst class
};

struct ReportOptions {
  std::string title = N_("Gyro noise test report");    ///< the default is shown translated
  std::string lab;                                     ///< the testing laboratory, for the title block
  std::string gyro;                                    ///< the gyro's type or name, for the title block
  nlohmann::json settings = nlohmann::json::object();  ///< option name → value, shown as is
  bool figures = true;                                 ///< embed figures (needs gnuplot)
  std::string generated;                               ///< time stamp; empty: left out
  /// Given: the first page is a test protocol (approval block, number and date, object, method,
  /// instruments, conditions, results, conclusion, signature lines); without, the title block.
  std::optional<LabProfile> profile;
  std::string protocol_number;  ///< "17/2026"; shown as typed
  CalendarDate protocol_date;   ///< the protocol's date (the day the report is made)

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// The HTML page. Throws AnalysisError without analyses, OutputError when a figure fails.
std::string report_html(const ReportInput& input, const ReportOptions& options);

/// Writes report_html to DIR/report.html (DIR created when missing) atomically; an existing
/// report is replaced only with `force`. Returns the path.
std::string write_report(const std::string& dir, const ReportInput& input, const ReportOptions& options, bool force);

/// Prints the HTML report at `html_path` to `pdf_path` with a headless Chromium (RWCALC_CHROMIUM,
/// else chromium, chromium-browser or google-chrome in PATH), run without a shell. Returns false
/// when none is installed; throws OutputError when it fails or the PDF exists without `force`.
bool print_to_pdf(const std::string& html_path, const std::string& pdf_path, bool force);

/// Converts the HTML report at `html_path` to an editable DOCX at `docx_path` with pandoc
/// (RWCALC_PANDOC, else pandoc in PATH), run without a shell and sandboxed to its input. Returns
/// false when pandoc is not installed; throws OutputError when it fails or the DOCX exists
/// without `force`.
bool convert_to_docx(const std::string& html_path, const std::string& docx_path, bool force);

/// Standard base64 (RFC 4648, padded), for inline figures.
std::string base64_encode(std::string_view bytes);

}  // namespace rwcalc
