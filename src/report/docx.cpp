// The report as an editable DOCX: converted from the HTML by pandoc, when it is installed (optional).
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "process.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/report.hpp"

namespace rwcalc {

bool convert_to_docx(const std::string& html_path, const std::string& docx_path, bool force) {
  const std::string pandoc = detail::find_program("RWCALC_PANDOC", {"pandoc"});
  if (pandoc.empty()) return false;
  check_output_targets({{"--docx", docx_path}}, force);
  const detail::ScratchDir dir("rwcalc-docx-", N_("cannot create a temporary directory for the DOCX: {}"));
  const auto docx = dir.path() / "report.docx";
  // The page's figures are inline data; a relative reference (there is none) would resolve only in
  // the empty scratch directory. (pandoc 2.17's --sandbox also locks out its own data files.)
  const auto r = detail::run_process(pandoc,
                                     {"--from=html", "--to=docx", "--resource-path=" + dir.path().string(),
                                      "--output=" + docx.string(), "--", std::filesystem::absolute(html_path).string()},
                                     dir.path() / "log", dir.path());
  if (r.timed_out)
    throw OutputError(
        trf("{}: converting the report to DOCX did not finish within {} s and was stopped "
            "(RWCALC_HELPER_TIMEOUT sets the limit)",
            printable(pandoc), detail::helper_timeout_s()));
  std::error_code ec;
  if (!r.started || r.status != 0 || !std::filesystem::exists(docx, ec))
    throw OutputError(trf("{}: converting the report to DOCX failed (exit status {}): {}", printable(pandoc), r.status,
                          printable(r.err.substr(0, 300))));
  std::ifstream in(docx, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_file_atomic(docx_path, bytes, force);
  return true;
}

}  // namespace rwcalc
