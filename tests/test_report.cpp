// The HTML report: tables, verdict, figures, diagnosis, settings; files and error paths.
// Built from JSON fixtures shaped like `rwcalc analyze --json` / `rwcalc diagnose --json`.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rwcalc/error.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/report.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::base64_decode;
using rwcalc::test::fixture_batch;
using rwcalc::test::fixture_diagnosis;
using rwcalc::test::inline_figures;
using rwcalc::test::svg_series;
using rwcalc::test::TempDir;
using rwcalc::test::xml_problem;

namespace {

rwcalc::ReportInput batch_input(bool with_direct_curve = true) {
  const auto b = fixture_batch(with_direct_curve);
  rwcalc::ReportInput in;
  for (const auto& r : b["runs"]) in.analyses.push_back(r);
  in.overall = b["overall"];
  return in;
}

rwcalc::ReportOptions no_figures() {
  rwcalc::ReportOptions o;
  o.figures = false;
  o.settings = {{"input", "pulses"}, {"latitude_deg", 55.75}, {"files", {"a.csv", "b.csv"}}};
  o.generated = "2026-01-01 00:00 UTC";
  return o;
}

std::string row_of(const std::string& html, const std::string& table_id, const std::string& run) {
  const auto t0 = html.find("<table id=\"" + table_id + "\">");
  const auto t1 = html.find("</table>", t0);
  const auto table = html.substr(t0, t1 - t0);
  const auto p = table.find("<tr><td>" + run + "</td>");
  if (p == std::string::npos) return {};
  return table.substr(p, table.find("</tr>", p) - p);
}

}  // namespace

TEST(Base64, Rfc4648Vectors) {
  EXPECT_EQ(rwcalc::base64_encode(""), "");
  EXPECT_EQ(rwcalc::base64_encode("f"), "Zg==");
  EXPECT_EQ(rwcalc::base64_encode("fo"), "Zm8=");
  EXPECT_EQ(rwcalc::base64_encode("foo"), "Zm9v");
  EXPECT_EQ(rwcalc::base64_encode("foob"), "Zm9vYg==");
  EXPECT_EQ(rwcalc::base64_encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(rwcalc::base64_encode("foobar"), "Zm9vYmFy");
  const std::string bytes("\x00\xff\x10\x80\x7f", 5);
  EXPECT_EQ(base64_decode(rwcalc::base64_encode(bytes)), bytes);
}

TEST(Report, IsWellFormedAndHasEveryTableAndSection) {
  const auto html = rwcalc::report_html(batch_input(), no_figures());
  EXPECT_EQ(xml_problem(html.substr(html.find("<html"))), "");
  for (const char* id : {"id=\"verdict\"", "id=\"table1\"", "id=\"table2\"", "id=\"runs\"", "id=\"settings-table\""})
    EXPECT_NE(html.find(id), std::string::npos) << id;
  for (int i = 1; i <= 5; ++i) {
    EXPECT_NE(html.find(fmt::format("id=\"run{}-data\"", i)), std::string::npos);
    EXPECT_NE(html.find(fmt::format("id=\"run{}-fit\"", i)), std::string::npos);
  }
  EXPECT_NE(html.find(std::string("rwcalc ") + RWCALC_VERSION), std::string::npos);
  EXPECT_NE(html.find("@media print"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>report generated</th><td>2026-01-01 00:00 UTC · rwcalc "), std::string::npos);
  EXPECT_NE(html.find("<tr><th>latitude_deg</th><td>55.75</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>files</th><td>a.csv, b.csv</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("Figures were left out"), std::string::npos);
  EXPECT_EQ(html.find("<figure"), std::string::npos);
  // Never a NaN or a bare JSON null in the page.
  for (const char* bad : {"nan", "NaN", "inf", ">null<"}) EXPECT_EQ(html.find(bad), std::string::npos) << bad;
}

TEST(Report, TablesFollowTemperatureOrderAndCarryTheJsonNumbers) {
  auto in = batch_input();
  const auto html = rwcalc::report_html(in, no_figures());
  const auto t1 = html.substr(html.find("id=\"table1\""), html.find("id=\"table2\"") - html.find("id=\"table1\""));
  std::size_t last = 0;
  for (const char* t : {"−50 °C", "−20 °C", "0 °C", "+25 °C", "+50 °C"}) {
    const auto p = t1.find(std::string("<td class=\"num\">") + t + "</td>");
    ASSERT_NE(p, std::string::npos) << t;
    EXPECT_GT(p, last) << t;
    last = p;
  }
  // The +50 °C run: N = 0.00098 °/√h by the AV fit, B = 0.0083 °/h; class 1 by N, outside class 2 by B.
  const auto r1 = row_of(html, "table1", "gl2d_50C.csv");
  EXPECT_NE(r1.find("0.00098 ± 0.00015"), std::string::npos) << r1;
  EXPECT_NE(r1.find("0.0083 ± 0.0017"), std::string::npos) << r1;
  const auto r2 = row_of(html, "table2", "gl2d_50C.csv");
  EXPECT_NE(r2.find("<td class=\"num\">1</td><td class=\"num\">1</td><td class=\"num\">3</td>"), std::string::npos)
      << r2;
  EXPECT_NE(r2.find("class 3 (P=0.83)"), std::string::npos) << r2;
  // The batch's overall verdict is shown as given.
  EXPECT_NE(html.find("Overall class over the temperature range: <b>2</b> (by B: 2, by N: 1)"), std::string::npos);
}

TEST(Report, UnresolvedAndMissingValuesAreStatedNotZero) {
  auto in = batch_input();
  in.analyses.resize(1);
  in.overall = nullptr;
  auto& run = in.analyses[0];
  run["methods"]["B_100s"] = nullptr;  // too short for 100-s blocks
  run["fit"]["N"] = {{"value", 0.0012}, {"sigma", 0.0003}, {"low95", 0.0}, {"high95", 0.0012}, {"resolved", false}};
  const auto html = rwcalc::report_html(in, no_figures());
  const auto row = row_of(html, "table1", "gl2d_25C.csv");
  EXPECT_NE(row.find("&lt; 0.0012 <span class=\"ci\">95 % upper bound</span>"), std::string::npos) << row;
  EXPECT_NE(row.find("<span class=\"na\">—</span>"), std::string::npos) << row;
  // Without a batch verdict the report states the worst class over the runs (here the one run).
  EXPECT_NE(html.find("Overall class over the run: <b>2</b> (by B: 2, by N: 1)"), std::string::npos);
}

TEST(Report, WorstClassOverRunsAndOutsideTheTable) {
  auto in = batch_input();
  in.overall = nullptr;
  auto html = rwcalc::report_html(in, no_figures());
  EXPECT_NE(html.find("Overall class over the temperature range: <b>3</b> (by B: 3, by N: 1)"), std::string::npos);
  in.analyses[2]["verdict"]["class_B"] = nullptr;
  in.analyses[2]["verdict"]["class"] = nullptr;
  html = rwcalc::report_html(in, no_figures());
  EXPECT_NE(html.find("Overall class over the temperature range: <b>outside</b> (by B: outside, by N: 1)"),
            std::string::npos);
}

TEST(Report, ToleranceRuleIsMarked) {
  auto in = batch_input();
  for (auto& r : in.analyses) r["verdict"]["tolerance_pct"] = 50;
  in.analyses[0]["verdict"]["tolerance_changed"] = true;
  const auto html = rwcalc::report_html(in, no_figures());
  EXPECT_NE(html.find("heading-gyro rule is applied: a B up to 50 %"), std::string::npos);
  EXPECT_NE(html.find("changed by the +50 % B tolerance"), std::string::npos);
}

TEST(Report, HtmlSpecialCharactersInNamesAreEscaped) {
  auto in = batch_input();
  in.analyses.resize(1);
  in.analyses[0]["source"] = "runs/<b>&\"x\".csv";
  auto o = no_figures();
  o.title = "Lab <A> & B";
  const auto html = rwcalc::report_html(in, o);
  EXPECT_EQ(xml_problem(html.substr(html.find("<html"))), "");
  EXPECT_NE(html.find("&lt;b&gt;&amp;&quot;x&quot;.csv"), std::string::npos);
  EXPECT_NE(html.find("<h1>Lab &lt;A&gt; &amp; B</h1>"), std::string::npos);
}

TEST(Report, NoAnalysisIsAnAnalysisError) {
  EXPECT_THROW(rwcalc::report_html({}, no_figures()), rwcalc::AnalysisError);
}

TEST(ReportFigures, EveryFigureIsInlineValidSvgWithItsSeries) {
  REQUIRE_GNUPLOT();
  auto in = batch_input();
  in.diagnoses.resize(in.analyses.size());
  in.diagnoses[1] = fixture_diagnosis();
  rwcalc::ReportOptions o;
  const auto html = rwcalc::report_html(in, o);
  EXPECT_EQ(xml_problem(html.substr(html.find("<html"))), "");
  const auto figs = inline_figures(html);
  ASSERT_EQ(figs.size(), 2u + 5u + 1u) << "Fig. 1, Fig. 2, one Allan figure per run, one diagnosis";
  ASSERT_TRUE(figs.count("fig-batch-allan") && figs.count("fig-batch-direct") && figs.count("fig-run2-diagnosis"));
  for (const auto& [id, svg] : figs) EXPECT_EQ(xml_problem(svg), "") << id;
  EXPECT_EQ(svg_series(figs.at("fig-batch-allan")).size(), 8u);
  EXPECT_EQ(svg_series(figs.at("fig-batch-direct")).size(), 10u);
  EXPECT_EQ(svg_series(figs.at("fig-run2-diagnosis")).size(), 5u);
  for (int i = 1; i <= 5; ++i) {
    const auto id = fmt::format("fig-run{}-allan", i);
    ASSERT_TRUE(figs.count(id)) << id;
    // measured, model, Q, N, B, K (resolved or bound), three class floors
    EXPECT_EQ(svg_series(figs.at(id)).size(), 9u) << id;
  }
  // Figures are numbered in order and the diagnosis tables are there.
  for (int n = 1; n <= 8; ++n) EXPECT_NE(html.find(fmt::format("<b>Figure {}.</b>", n)), std::string::npos) << n;
  for (const char* id : {"id=\"run2-diagnosis\"", "id=\"run2-findings\"", "id=\"run2-gain\""})
    EXPECT_NE(html.find(id), std::string::npos) << id;
  // A finding's parameters with their uncertainties and the units their "unit" fields name.
  EXPECT_NE(html.find("amplitude = 0.0300 ± 0.0021 °/h; frequency = 0.0125 Hz"), std::string::npos);
}

TEST(ReportFigures, SingleRunHasNoOverlayAndMissingCurvesAreSaid) {
  REQUIRE_GNUPLOT();
  auto in = batch_input(/*with_direct_curve=*/false);
  auto html = rwcalc::report_html(in, {});
  auto figs = inline_figures(html);
  EXPECT_EQ(figs.size(), 1u + 5u);
  EXPECT_NE(html.find("direct-method curves are not in the analysis results"), std::string::npos);
  in.analyses.resize(1);
  html = rwcalc::report_html(in, {});
  figs = inline_figures(html);
  EXPECT_EQ(figs.size(), 1u);
}

TEST(ReportFiles, WrittenIntoTheDirectoryAtomicallyAndNeedForce) {
  TempDir dir;
  const auto out = (dir.path() / "new" / "sub").string();
  const auto path = rwcalc::write_report(out, batch_input(), no_figures(), false);
  EXPECT_EQ(path, (fs::path(out) / "report.html").string());
  EXPECT_TRUE(fs::exists(path));
  EXPECT_THROW(rwcalc::write_report(out, batch_input(), no_figures(), false), rwcalc::OutputError);
  EXPECT_NO_THROW(rwcalc::write_report(out, batch_input(), no_figures(), true));
  // A file where the directory should be.
  const auto file = dir.write("plain", "x");
  EXPECT_THROW(rwcalc::write_report(file.string(), batch_input(), no_figures(), true), rwcalc::OutputError);
}

TEST(ReportFiles, MissingGnuplotFailsWithoutWritingAReport) {
  TempDir dir;
  setenv("RWCALC_GNUPLOT", "/nonexistent/gnuplot", 1);
  EXPECT_THROW(rwcalc::write_report(dir.path().string(), batch_input(), {}, false), rwcalc::OutputError);
  unsetenv("RWCALC_GNUPLOT");
  EXPECT_FALSE(fs::exists(dir.path() / "report.html"));
}
