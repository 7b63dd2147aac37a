// 'rwcalc report FILES… -o DIR' end to end: the five shipped GL-2D runs give one self-contained
// HTML file with the verdict, Tables 1 and 2, every figure inline as valid SVG, the run
// summaries, the settings and the version; saved JSON results give the same tables; error paths.
// Tests that draw figures skip with a message when gnuplot is not installed.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "rwcalc/plot.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::CliResult;
using rwcalc::test::concat;
using rwcalc::test::fixture_analysis;
using rwcalc::test::fixture_diagnosis;
using rwcalc::test::FixtureCoefficients;
using rwcalc::test::inline_figures;
using rwcalc::test::run_cli;
using rwcalc::test::ScopedEnv;
using rwcalc::test::slurp;
using rwcalc::test::source_path;
using rwcalc::test::svg_series;
using rwcalc::test::TempDir;
using rwcalc::test::xml_problem;

namespace {

std::vector<std::string> gl2d_all() {
  std::vector<std::string> f;
  for (const char* t : {"p50C", "m25C", "0C", "m50C", "p25C"})  // not in temperature order
    f.push_back(source_path(std::string("data/gl2d/gl2d_") + t + ".csv.gz").string());
  return f;
}

/// The element `<tag id="ID" …>…</tag>` (first closing tag of the same name).
std::string element(const std::string& html, const std::string& tag, const std::string& id) {
  const auto p = html.find("<" + tag + " id=\"" + id + "\"");
  if (p == std::string::npos) return {};
  const auto e = html.find("</" + tag + ">", p);
  return html.substr(p, e == std::string::npos ? std::string::npos : e + tag.size() + 3 - p);
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

/// One report of the five GL-2D runs (with figures) and the batch JSON of the same runs, made
/// once for the tests that read them.
class ReportOfGl2d : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!rwcalc::gnuplot_available()) return;
    dir_ = std::make_unique<TempDir>();
    report_ = run_cli(concat({"report"}, concat(gl2d_all(), {"-o", (dir_->path() / "out").string(), "--tolerance", "50",
                                                             "--title", "GL-2D <temperature> test"})));
    batch_ = run_cli(concat({"batch"}, concat(gl2d_all(), {"--json", "--tolerance", "50", "-o",
                                                           (dir_->path() / "batch.json").string()})));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override {
    if (!rwcalc::gnuplot_available())
      GTEST_SKIP() << "gnuplot not found ('" << rwcalc::gnuplot_command()
                   << "'): install gnuplot-nox to run the report tests with figures";
    ASSERT_EQ(report_.status, 0) << report_.err;
    ASSERT_EQ(batch_.status, 0) << batch_.err;
    html_ = slurp(dir_->path() / "out" / "report.html");
  }
  static fs::path dir() { return dir_->path(); }
  static inline std::unique_ptr<TempDir> dir_;
  static inline CliResult report_, batch_;
  std::string html_;
};

}  // namespace

TEST_F(ReportOfGl2d, IsOneWellFormedPageWithEverySection) {
  EXPECT_NE(report_.out.find("report written to " + (dir() / "out" / "report.html").string() + " (5 runs)"),
            std::string::npos)
      << report_.out;
  ASSERT_NE(html_.find("<html"), std::string::npos);
  EXPECT_EQ(xml_problem(html_.substr(html_.find("<html"))), "");
  // Self-contained: nothing fetched from elsewhere.
  for (const char* ext : {"src=\"http", "href=\"http", "src=\"file", "<link ", "<script src"})
    EXPECT_EQ(html_.find(ext), std::string::npos) << ext;
  for (const char* id :
       {"id=\"verdict\"", "id=\"table1\"", "id=\"table2\"", "id=\"figures\"", "id=\"runs\"", "id=\"settings-table\""})
    EXPECT_NE(html_.find(id), std::string::npos) << id;
  // The title is escaped.
  EXPECT_NE(html_.find("GL-2D &lt;temperature&gt; test"), std::string::npos);
  for (const char* bad : {"nan", "NaN", ">inf", ">null<"}) EXPECT_EQ(html_.find(bad), std::string::npos) << bad;
}

TEST_F(ReportOfGl2d, TablesHaveOneRowPerRunInTemperatureOrderWithEveryMethod) {
  const auto t1 = element(html_, "table", "table1");
  const auto t2 = element(html_, "table", "table2");
  ASSERT_FALSE(t1.empty());
  ASSERT_FALSE(t2.empty());
  std::size_t last = 0;
  for (const char* t : {">−50 °C<", ">−25 °C<", ">0 °C<", ">+25 °C<", ">+50 °C<"}) {
    const auto p = t1.find(t);
    ASSERT_NE(p, std::string::npos) << t;
    EXPECT_GT(p, last) << t << " out of order";
    last = p;
    EXPECT_NE(t2.find(t), std::string::npos) << t;
  }
  // Every run has both N and both B estimates: no "could not run" cell.
  EXPECT_EQ(t1.find("—"), std::string::npos) << t1;
  EXPECT_GE(count(t1, "±"), 5u * 4u);
}

TEST_F(ReportOfGl2d, VerdictCarriesItsProbabilityAndTheToleranceRule) {
  const auto v = html_.substr(html_.find("id=\"verdict\""), html_.find("id=\"tables\"") - html_.find("id=\"verdict\""));
  EXPECT_NE(v.find("P="), std::string::npos) << v;
  EXPECT_NE(v.find("heading-gyro rule is applied: a B up to 50 %"), std::string::npos);
  // The report's overall verdict is the batch's overall verdict.
  const json b = json::parse(slurp(dir() / "batch.json"));
  const auto cls = b["overall"]["class"];
  EXPECT_NE(html_.find(cls.is_null() ? std::string("outside") : fmt::format("class {}", cls.get<int>())),
            std::string::npos);
  // …with the probability of the combined verdict.
  const std::string st = b["overall"]["statement"];
  EXPECT_NE(st.find("P="), std::string::npos) << st;
  EXPECT_NE(element(html_, "p", "verdict-probability").find(st), std::string::npos) << st;
}

TEST_F(ReportOfGl2d, EveryFigureIsInlineValidSvgWithItsSeries) {
  const auto figs = inline_figures(html_);
  ASSERT_EQ(figs.size(), 2u + 5u) << "Fig. 1, Fig. 2 and one Allan figure per run";
  EXPECT_EQ(count(html_, "<img "), figs.size()) << "one image per figure";
  for (const auto& [id, svg] : figs) EXPECT_EQ(xml_problem(svg), "") << id;
  const json b = json::parse(slurp(dir() / "batch.json"));
  const std::size_t limits = b["runs"][0]["verdict"]["B"]["limits"].size();
  ASSERT_TRUE(figs.count("fig-batch-allan") && figs.count("fig-batch-direct"));
  EXPECT_EQ(svg_series(figs.at("fig-batch-allan")).size(), 5u + limits);
  EXPECT_EQ(svg_series(figs.at("fig-batch-direct")).size(), 10u);
  for (int i = 1; i <= 5; ++i) {
    const auto id = fmt::format("fig-run{}-allan", i);
    ASSERT_TRUE(figs.count(id)) << id;
    EXPECT_GE(svg_series(figs.at(id)).size(), 2u + 3u + limits) << id;  // measured, model, Q N B, floors
  }
  for (int n = 1; n <= 7; ++n) EXPECT_NE(html_.find(fmt::format("<b>Figure {}.</b>", n)), std::string::npos) << n;
}

TEST_F(ReportOfGl2d, SettingsAndVersionAreStated) {
  const auto s = element(html_, "table", "settings-table");
  ASSERT_FALSE(s.empty());
  EXPECT_NE(s.find(std::string("<tr><th>rwcalc version</th><td>rwcalc ") + RWCALC_VERSION + " (commit "),
            std::string::npos);
  std::size_t b_rows = 0;  // the B estimate is stated once
  for (auto at = s.find("<th>B estimate"); at != std::string::npos; at = s.find("<th>B estimate", at + 1)) ++b_rows;
  EXPECT_EQ(b_rows, 1u) << s;
  EXPECT_NE(s.find("<tr><th>tolerance on B (%)</th><td>50</td></tr>"), std::string::npos) << s;
  EXPECT_NE(s.find("<tr><th>input</th><td>pulse increments</td></tr>"), std::string::npos) << s;
  EXPECT_NE(s.find("<tr><th>latitude (°)</th><td>55.75</td></tr>"), std::string::npos) << s;
  EXPECT_NE(s.find("<tr><th>B estimate</th><td>the five-term fit</td></tr>"), std::string::npos) << s;
  EXPECT_NE(s.find("gl2d_m50C.csv.gz"), std::string::npos) << s;
  EXPECT_NE(html_.find(" UTC"), std::string::npos) << "the generated time stamp";
}

// Each run names its gyro (here by option) and its file by size and SHA-256, as the analysis JSON does.
TEST_F(ReportOfGl2d, EachRunNamesItsGyroAndItsFileDigest) {
  const auto out = dir() / "identified";
  const auto r = run_cli({"report", gl2d_all().front(), "-o", out.string(), "--no-figures", "--serial", "GL2D-0421",
                          "--operator", "A. Ivanov"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(out / "report.html");
  EXPECT_NE(html.find("<tr><th>gyro serial</th><td>GL2D-0421</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>operator</th><td>A. Ivanov</td></tr>"), std::string::npos);
  const auto a = run_cli({"analyze", gl2d_all().front(), "--json"});
  const auto sha = nlohmann::json::parse(a.out).at("input").at("sha256").get<std::string>();
  EXPECT_NE(html.find("<code>" + sha + "</code>"), std::string::npos) << sha;
}

TEST_F(ReportOfGl2d, SavedBatchJsonGivesTheSameTablesAndVerdict) {
  const auto out = dir() / "from-json";
  const auto r = run_cli({"report", (dir() / "batch.json").string(), "-o", out.string(), "--no-figures"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(out / "report.html");
  for (const char* id : {"table1", "table2"}) EXPECT_EQ(element(html, "table", id), element(html_, "table", id)) << id;
  const auto verdict = [](const std::string& h) {
    return h.substr(h.find("id=\"verdict\""), h.find("id=\"tables\"") - h.find("id=\"verdict\""));
  };
  EXPECT_EQ(verdict(html), verdict(html_));
  EXPECT_NE(html.find("Figures were left out"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>saved results</th>"), std::string::npos);
  // The same runs as JSON lines ('rwcalc batch --jsonl'): the verdict is computed again, equal.
  std::string lines;
  const json batch = json::parse(slurp(dir() / "batch.json"));
  for (const auto& run : batch["runs"]) lines += run.dump() + "\n";
  TempDir tmp;
  const auto jsonl = tmp.write("runs.jsonl", lines);
  const auto r2 = run_cli({"report", jsonl.string(), "-o", (tmp.path() / "out").string(), "--no-figures"});
  ASSERT_EQ(r2.status, 0) << r2.err;
  const auto html2 = slurp(tmp.path() / "out" / "report.html");
  for (const char* id : {"table1", "table2"}) EXPECT_EQ(element(html2, "table", id), element(html_, "table", id)) << id;
  EXPECT_EQ(verdict(html2), verdict(html_));
}

// ---- saved analysis and diagnosis JSON (no analysis, no gnuplot) ------------------------------------

TEST(ReportCli, SavedAnalysisAndDiagnosisJsonAreCombined) {
  TempDir dir;
  FixtureCoefficients c;  // source "gl2d_25C.csv", as the fixture diagnosis
  const auto a = dir.write("a.json", fixture_analysis(c).dump());
  const auto d = dir.write("d.json", fixture_diagnosis().dump());
  const auto out = dir.path() / "out";
  auto r = run_cli({"report", a.string(), d.string(), "-o", out.string(), "--no-figures"});
  ASSERT_EQ(r.status, 0) << r.err;
  // The fixture's verdict has no class probabilities per class: no combined verdict, said so.
  EXPECT_NE(r.err.find("no combined verdict over the runs"), std::string::npos) << r.err;
  const auto html = slurp(out / "report.html");
  for (const char* id : {"id=\"table1\"", "id=\"table2\"", "id=\"run1-diagnosis\"", "id=\"run1-findings\""})
    EXPECT_NE(html.find(id), std::string::npos) << id;
  EXPECT_EQ(html.find("<figure"), std::string::npos);
  // Two runs: the diagnosis goes to the run with its source; with no such run it is an error.
  c.temperature_c = -50;  // source "gl2d_-50C.csv"
  const auto a2 = dir.write("a2.json", fixture_analysis(c).dump());
  r = run_cli({"report", a2.string(), a.string(), d.string(), "-o", out.string(), "--no-figures", "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(out / "report.html").find("id=\"run2-diagnosis\""), std::string::npos);
  r = run_cli({"report", a2.string(), a2.string(), d.string(), "-o", out.string(), "--no-figures", "--force"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(d.string() + ": the diagnosis of 'gl2d_25C.csv' matches no run"), std::string::npos) << r.err;
}

// ---- error paths ------------------------------------------------------------------------------------

TEST(ReportCli, DiagnoseAddsEachRecordingsDiagnosisWithItsFigure) {
  TempDir dir;
  const auto out = dir.path() / "out";
  const auto rec = source_path("data/gl2d/gl2d_p25C.csv.gz").string();
  const bool figures = rwcalc::gnuplot_available();
  std::vector<std::string> args = {"report", rec, "-o", out.string(), "--diagnose", "--diagnose-runs", "10"};
  if (!figures) args.emplace_back("--no-figures");
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(out / "report.html");
  EXPECT_NE(html.find("id=\"run1-diagnosis\""), std::string::npos);
  EXPECT_NE(html.find("id=\"run1-gain\""), std::string::npos);
  // The same diagnosis as `rwcalc diagnose` with the same ensemble: its findings are the page's.
  const auto d = run_cli({"diagnose", rec, "--json", "--runs", "10"});
  ASSERT_EQ(d.status, 0) << d.err;
  const auto j = nlohmann::json::parse(d.out);
  if (j["findings"].empty()) {
    EXPECT_NE(html.find("No finding"), std::string::npos);
  } else {
    EXPECT_NE(html.find("id=\"run1-findings\""), std::string::npos);
    for (const auto& f : j["findings"])
      EXPECT_NE(html.find("<td>" + f["effect"].get<std::string>() + "</td>"), std::string::npos) << f.dump();
  }
  if (figures) {
    EXPECT_NE(html.find("fig-run1-diagnosis"), std::string::npos);
  } else {
    GTEST_LOG_(INFO) << "gnuplot not installed: the diagnosis figure is not checked";
  }
}

TEST(ReportCli, DiagnoseNeedsRecordingsAndEnoughRuns) {
  TempDir dir;
  const auto out = dir.path() / "out";
  auto r = run_cli({"report", source_path("data/gl2d/gl2d_p25C.csv.gz").string(), "-o", out.string(), "--diagnose",
                    "--diagnose-runs", "5", "--no-figures"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--diagnose-runs"), std::string::npos) << r.err;
  const auto a = dir.write("a.json", fixture_analysis({}).dump());
  r = run_cli({"report", a.string(), "-o", out.string(), "--diagnose", "--no-figures"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--diagnose needs recordings"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "report.html"));
}

TEST(ReportCli, MissingOutputDirectoryOptionIsAUsageError) {
  const auto r = run_cli(concat({"report"}, gl2d_all()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("-o DIR is required"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(ReportCli, ExistingReportIsKeptWithoutForce) {
  TempDir dir;
  const auto out = dir.path() / "out";
  fs::create_directories(out);
  std::ofstream(out / "report.html") << "old";
  const auto a = dir.write("a.json", fixture_analysis({}).dump());
  auto r = run_cli({"report", a.string(), "-o", out.string(), "--no-figures"});
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("report.html: exists; use --force to overwrite it"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(out / "report.html"), "old");
  r = run_cli({"report", a.string(), "-o", out.string(), "--no-figures", "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(out / "report.html").find("id=\"table1\""), std::string::npos);
}

TEST(ReportCli, MissingGnuplotFailsBeforeTheAnalysisAndNoFiguresNeedsNone) {
  TempDir dir;
  ScopedEnv env("RWCALC_GNUPLOT", "/nonexistent/gnuplot");
  const auto out = dir.path() / "out";
  auto r = run_cli(concat({"report"}, concat(gl2d_all(), {"-o", out.string()})));
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("cannot run gnuplot ('/nonexistent/gnuplot'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gnuplot-nox"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "report.html"));
  const auto a = dir.write("a.json", fixture_analysis({}).dump());
  r = run_cli({"report", a.string(), "-o", out.string(), "--no-figures"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(out / "report.html").find("Figures were left out"), std::string::npos);
}

TEST(ReportCli, BadSavedResultsNameTheFileAndLine) {
  TempDir dir;
  const auto out = dir.path() / "out";
  const auto bad = dir.write("bad.json", "{\n  \"runs\": [\n    1,\n");
  auto r = run_cli({"report", bad.string(), "-o", out.string(), "--no-figures"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(bad.string() + ":4: not valid JSON"), std::string::npos) << r.err;
  const auto other = dir.write("other.json", "{\"hello\": 1}");
  r = run_cli({"report", other.string(), "-o", out.string(), "--no-figures"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(other.string() + ":1: not an rwcalc result"), std::string::npos) << r.err;
  const auto diag_only = dir.write("d.json", fixture_diagnosis().dump());
  r = run_cli({"report", diag_only.string(), "-o", out.string(), "--no-figures"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no run to report"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "report.html"));
}

TEST(ReportCli, GapsSegmentsAreNamedInTheReport) {
  // A record in two stretches of 2000 s at 10 Hz with 10 s missing between them, read with
  // --gaps segments: the report names the segments, the gap and its line, as analyze does.
  TempDir dir;
  std::string text = "time_s,gyro_dph\n";
  std::uint64_t state = 12345;
  for (int k = 0; k < 40000; ++k) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double white = static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
    const double t = 0.1 * k + (k >= 20000 ? 10.0 : 0.0);
    text += fmt::format("{:.1f},{:.6f}\n", t, 15.0 + white);
  }
  const auto rec = dir.write("gap.csv", text).string();
  const auto out = dir.path() / "out";
  auto r = run_cli({"report", rec, "-o", out.string(), "--no-figures", "--gaps", "segments"});
  ASSERT_EQ(r.status, 0) << r.err;
  // Sample 20000, the first after the gap, is on line 20002 (the header is line 1).
  const auto segments = [](const std::string& html) {
    const auto at = html.find("<th>segments</th>");
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</tr>", at) - at);
  };
  const std::string row = segments(slurp(out / "report.html"));
  EXPECT_NE(row.find("2 segments"), std::string::npos) << row;
  EXPECT_NE(row.find("10 s missing before line 20002"), std::string::npos) << row;
  EXPECT_NE(row.find("2000"), std::string::npos) << row;
  // The same from the saved analysis.
  const auto saved = run_cli({"analyze", rec, "--gaps", "segments", "--json"});
  ASSERT_EQ(saved.status, 0) << saved.err;
  const auto a = dir.write("a.json", saved.out).string();
  r = run_cli({"report", a, "-o", out.string(), "--no-figures", "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(segments(slurp(out / "report.html")), row);
}
