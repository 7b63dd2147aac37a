// The first page of a report filed with a lab profile, as a test protocol (html.hpp,
// protocol_block): approval, number and date, what was tested, how, with which instruments and under
// which conditions, the results in brief, the conclusion and the signature lines.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "html.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/lab_profile.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/report.hpp"
#include "rwcalc/units.hpp"
#include "rwcalc/version.hpp"
#include "shown_results.hpp"

namespace rwcalc {

namespace {

using shown::Analysis;
namespace lbl = units::label;

/// A person's signature line: the role, the position, a line to sign on, the name.
std::string signature_row(const char* role, const ProtocolPerson& p) {
  return fmt::format("<tr><th>{}</th><td>{}</td><td class=\"sign\">&nbsp;</td><td>{}</td></tr>\n", tr(role),
                     html::typed(p.position), html::typed(p.name));
}

/// The approval block at the top right of a protocol: approved by whom, signed and dated by hand.
std::string approval_block(const LabProfile& p) {
  return fmt::format(
      "<div class=\"approval\" id=\"approval\">\n<p class=\"approved\">{}</p>\n<p>{}</p>\n<p>{}</p>\n"
      "<p class=\"sign-line\"><span class=\"sign\">&nbsp;</span> {}</p>\n<p>{}</p>\n</div>\n",
      tr("APPROVED"), html::typed(p.approver.position), html::typed(p.laboratory), html::typed(p.approver.name),
      tr("date ____________"));
}

std::string instruments_table(const LabProfile& p) {
  std::string h = fmt::format("<table id=\"instruments\" class=\"protocol\">\n<caption>{}</caption>\n",
                              tr("Measuring instruments"));
  h +=
      tr("<tr><th>No.</th><th>type</th><th>serial number</th><th>verified on</th><th>verification valid until</th>"
         "<th>certificate</th></tr>\n");
  std::size_t k = 0;
  for (const auto& m : p.instruments)
    h += fmt::format(
        "<tr><td class=\"num\">{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
        "<td>{}</td></tr>\n",
        ++k, html::typed(m.type), html::typed(m.serial), date_text(m.verified),
        m.valid_until ? date_text(*m.valid_until) : html::not_available(),
        m.certificate.empty() ? html::not_available() : html::typed(m.certificate));
  if (p.instruments.empty())
    h += fmt::format("<tr><td colspan=\"6\">{}</td></tr>\n", tr("none listed in the lab profile"));
  return h + "</table>\n";
}

std::string conditions_table(const LabProfile& p) {
  std::string h =
      fmt::format("<table id=\"conditions\" class=\"protocol\">\n<caption>{}</caption>\n", tr("Ambient conditions"));
  h += tr("<tr><th>quantity</th><th>value ± standard uncertainty</th><th>unit</th></tr>\n");
  for (const auto& c : p.conditions)
    h += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n", html::typed(c.quantity),
                     c.uncertainty ? value_with_uncertainty(c.value, *c.uncertainty) : number_text(c.value, 6),
                     html::typed(c.unit));
  if (p.conditions.empty())
    h += fmt::format("<tr><td colspan=\"3\">{}</td></tr>\n", tr("none listed in the lab profile"));
  return h + "</table>\n";
}

/// The protocol's results in brief: per run N and B with their uncertainty and the class.
std::string protocol_results(const std::vector<Analysis>& a, const std::vector<std::size_t>& order) {
  std::string h = fmt::format("<table id=\"protocol-results\" class=\"protocol\">\n<caption>{}</caption>\n",
                              tr("Results (in full: Tables 1 and 2 and the sections below)"));
  h += trf("<tr><th>run</th><th>temperature</th><th>N ({0})</th><th>B ({1})</th><th>class</th></tr>\n",
           "<span class=\"unit\">" + std::string(tr(lbl::arw)) + "</span>",
           "<span class=\"unit\">" + std::string(tr(lbl::rate)) + "</span>");
  for (auto i : order)
    h += html::run_row(a[i], {html::coefficient_cell(a[i].fit[shown::Term::N]),
                              html::coefficient_cell(a[i].fit[shown::Term::B]),
                              html::verdict_class(a[i].verdict, a[i].verdict.cls)});
  return h + "</table>\n";
}

/// The conclusion of a protocol: the verdict in words, or why there is none.
std::string protocol_conclusion(const std::vector<Analysis>& a, const std::vector<std::size_t>& order,
                                const shown::Verdict& overall) {
  std::string text;
  if (overall.withheld) {
    text = tr("no verdict: the noise model does not describe every record (see section 1)");
  } else {
    const auto& v0 = a[order.front()].verdict;
    const auto& classes = overall.classes ? overall.classes : v0.classes;
    std::string words = html::verdict_in_words(overall, classes);
    if (words.empty()) words = trf("class {}", html::class_text(overall.cls));
    text = trf("by GOST RV 52339-2005 the gyro is of {}.", words);
  }
  return fmt::format("<p id=\"conclusion\"><b>{}</b> {}</p>\n", tr("Conclusion:"), html::text(text));
}

/// The first page as a test protocol: approval, number and date, what was tested, how, with which
/// instruments and under which conditions, the results and the conclusion, the signature lines.
}  // namespace

std::string html::protocol_block(const std::vector<Analysis>& a, const std::vector<std::size_t>& order,
                                 const shown::Verdict& overall, const ReportOptions& options,
                                 const std::string& title) {
  const LabProfile& p = *options.profile;
  std::string h = "<section class=\"protocol\" id=\"protocol\">\n" + approval_block(p);
  h += fmt::format(
      "<h1 id=\"protocol-number\">{}</h1>\n<p class=\"protocol-date\">{}</p>\n<p class=\"subject\">{}</p>\n",
      trf("Test protocol No. {}",
          options.protocol_number.empty() ? std::string("________") : html::typed(options.protocol_number)),
      trf("of {}", date_text(options.protocol_date)), html::typed(title));
  h += "<table id=\"protocol-block\">\n";
  auto row = [&](const char* name, const std::string& value_html) {
    h += html::kv_row(tr(name), value_html.empty() ? html::not_available() : value_html);
  };
  row(N_("laboratory"), html::typed(p.laboratory));
  row(N_("address"), html::typed(p.address));
  if (!p.accreditation.empty()) row(N_("accreditation"), html::typed(p.accreditation));
  row(N_("customer"), html::typed(p.customer));
  const auto serials = html::identification_values(a, shown::Id::Serial);
  row(N_("object of the test"), (options.gyro.empty() ? std::string(tr("gyro")) : html::typed(options.gyro)) +
                                    (serials.empty() ? std::string() : trf(", serial No. {}", serials)));
  row(N_("test method"), html::typed(p.method));
  row(N_("test date"), html::identification_values(a, shown::Id::TestDate));
  row(N_("runs"), trnf("{} recording (its size and SHA-256 under “Runs”)",
                       "{} recordings (each one's size and SHA-256 under “Runs”)", a.size(), a.size()));
  row(N_("report generated"), html::text(options.generated) + " · " + html::text(version_line()));
  h += "</table>\n" + instruments_table(p) + conditions_table(p) + protocol_results(a, order) +
       protocol_conclusion(a, order, overall);
  h += fmt::format("<table id=\"signatures\" class=\"signatures\">\n{}{}</table>\n",
                   signature_row(N_("Tests performed by"), p.performer), signature_row(N_("Checked by"), p.checker));
  return h + "</section>\n";
}

}  // namespace rwcalc
