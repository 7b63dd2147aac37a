// The report as PDF: printed by a headless Chromium, when one is installed (optional).
#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "process.hpp"
#include "rwcalc/encode.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/report.hpp"

namespace rwcalc {

namespace {

namespace fs = std::filesystem;

/// RWCALC_CHROMIUM, else the first of the usual names found in PATH; empty when none.
std::string find_chromium() {
  return detail::find_program("RWCALC_CHROMIUM",
                              {"chromium", "chromium-browser", "google-chrome", "google-chrome-stable"});
}

}  // namespace

bool print_to_pdf(const std::string& html_path, const std::string& pdf_path, bool force) {
  const std::string chromium = find_chromium();
  if (chromium.empty()) return false;
  check_output_targets({{"--pdf", pdf_path}}, force);
  // A private profile and output: Chromium writes into its profile, and the PDF is moved into
  // place only when complete. The directory goes with everything in it, on a signal too.
  const detail::ScratchDir dir("rwcalc-pdf-", N_("cannot create a temporary directory for the PDF: {}"));
  const fs::path& scratch = dir.path();
  const fs::path pdf = scratch / "report.pdf";
  const auto r = detail::run_process(chromium,
                                     {"--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                                      "--no-pdf-header-footer", "--user-data-dir=" + (scratch / "profile").string(),
                                      "--print-to-pdf=" + pdf.string(), file_url(fs::absolute(html_path).string())},
                                     scratch / "log");
  if (r.timed_out)
    throw OutputError(
        trf("{}: printing the report to PDF did not finish within {:g} s and was stopped "
            "(RWCALC_HELPER_TIMEOUT sets the limit)",
            printable(chromium), detail::helper_timeout_s()));
  std::error_code ec;
  if (!r.started || r.status != 0 || !fs::exists(pdf, ec)) {
    throw OutputError(trf("{}: printing the report to PDF failed (exit status {}): {}", printable(chromium), r.status,
                          printable(r.err.substr(0, 300))));
  }
  std::string bytes(static_cast<std::size_t>(fs::file_size(pdf)), '\0');
  if (FILE* f = std::fopen(pdf.c_str(), "rb")) {
    bytes.resize(std::fread(bytes.data(), 1, bytes.size(), f));
    std::fclose(f);
  }
  write_file_atomic(pdf_path, bytes, force);
  return true;
}

}  // namespace rwcalc
