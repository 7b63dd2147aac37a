// Hostile strings: file names and saved-result strings that carry newlines, quotes, escape
// sequences, gnuplot commands, enhanced-text markup, HTML markup or bytes that are not UTF-8 reach
// gnuplot scripts, the HTML report and the messages only in an inert form. Every command that
// draws is run end to end with such names and such JSON; a marker file that an injected gnuplot
// `system()` or backquote would create must never appear.
// Rendering tests skip with a message when gnuplot is not installed.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::fixture_analysis;
using rwcalc::test::fixture_batch;
using rwcalc::test::fixture_diagnosis;
using rwcalc::test::inline_figures;
using rwcalc::test::run_cli;
using rwcalc::test::run_exe;
using rwcalc::test::ScopedEnv;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;
using rwcalc::test::xml_problem;

namespace {

/// The environment variable naming the marker file; the hostile strings name it, so that any
/// command they smuggle into gnuplot (or a shell) touches a file the test can look for.
constexpr const char* kMarkerVar = "RWCALC_TEST_MARKER";

/// Strings that would run `touch $RWCALC_TEST_MARKER` if they reached gnuplot unencoded: a
/// newline or CR ends the string's command line, a quote ends the string, a backquote is command
/// substitution; and markup that must show as typed (enhanced text, HTML, an escape sequence).
std::vector<std::string> hostile_strings() {
  return {
      "nl\nsystem(\"touch $RWCALC_TEST_MARKER\")\n#",
      "cr\rsystem(\"touch $RWCALC_TEST_MARKER\")\r#",
      "q'.system(\"touch $RWCALC_TEST_MARKER\").'",
      "bq`touch $RWCALC_TEST_MARKER`",
      "mk^{up}_{down}@&~{x}\\\\ \\n <img src=x onerror=alert(1)><script>alert(1) \"javascript:x\" \x1b[31m\t\x7f end",
  };
}

/// File names made of the hostile strings (a name cannot hold '/').
std::vector<std::string> hostile_file_names() {
  std::vector<std::string> names;
  for (const auto& s : hostile_strings()) names.push_back(s + ".csv");
  names.push_back(std::string("nonutf8\xff\xfe\xc3(.csv"));
  return names;
}

/// `s` as one sh word.
std::string shell_quote(std::string_view s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n;
  }
  return true;
}

/// What is wrong with the strings of a gnuplot script: a single-quoted string that holds a
/// control character or runs past the end of its line, or text that is not UTF-8. Empty: fine.
std::string script_string_problem(std::string_view script) {
  if (!valid_utf8(script)) return "the script is not valid UTF-8";
  bool in_string = false, in_block = false;
  std::size_t line = 1, start = 0;
  for (std::size_t i = 0; i < script.size(); ++i) {
    const auto c = static_cast<unsigned char>(script[i]);
    if (!in_string && i == start) {
      // Inline data blocks ($name << EOD … EOD) hold numbers only; skip them.
      const auto eol = script.find('\n', i);
      const auto text = script.substr(i, eol == std::string_view::npos ? std::string_view::npos : eol - i);
      if (in_block || text.find("<< EOD") != std::string_view::npos) {
        in_block = text != "EOD";
        if (eol == std::string_view::npos) break;
        i = eol;
        start = eol + 1;
        ++line;
        continue;
      }
    }
    if (in_string) {
      if (c == '\'') {
        if (i + 1 < script.size() && script[i + 1] == '\'')
          ++i;
        else
          in_string = false;
      } else if (c < 0x20 || c == 0x7f) {
        return fmt::format("line {}: control character 0x{:02x} inside a string", line, c);
      }
      continue;
    }
    if (c == '#') {  // a comment runs to the end of the line
      const auto eol = script.find('\n', i);
      if (eol == std::string_view::npos) break;
      i = eol - 1;
      continue;
    }
    if (c == '\'') in_string = true;
    if (c == '"') return fmt::format("line {}: a double-quoted string (backquotes run there)", line);
    if (c == '\n') {
      ++line;
      start = i + 1;
    }
  }
  return in_string ? "a string is not closed" : "";
}

/// Every command that sets a text (title, axis label, label, key) turns enhanced text off, so a
/// name shows as typed; only the tic format uses the terminal's enhanced mode (10^{n}).
std::string enhanced_text_problem(std::string_view script) {
  std::size_t p = 0;
  while (p < script.size()) {
    const auto eol = std::min(script.find('\n', p), script.size());
    const auto line = script.substr(p, eol - p);
    for (const char* cmd : {"set title", "set xlabel", "set ylabel", "set label", "set key", "set x2label"})
      if (line.rfind(cmd, 0) == 0 && line.find("noenhanced") == std::string_view::npos)
        return "enhanced text in: " + std::string(line);
    p = eol + 1;
  }
  return {};
}

/// A gnuplot-sized GL-2D-like recording (20 min at 50 Hz), long enough to be diagnosed.
class HostileNames : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    record_ = (dir_->path() / "record.csv").string();
    const auto r = run_cli({"simulate", "-o", record_, "--duration", "1200", "--rate", "50", "--arw", "0.001",
                            "--bias-instability", "0.005", "--seed", "7", "--temperature", "20"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() { delete dir_; }

  void SetUp() override {
    marker_ = work_.path() / "MARKER";
    env_ = std::make_unique<ScopedEnv>(kMarkerVar, marker_.c_str());
  }

  /// A copy of the recording under `name` inside the test's directory.
  [[nodiscard]] std::string recording_named(const std::string& name) const {
    const auto p = work_.path() / name;
    fs::copy_file(record_, p, fs::copy_options::overwrite_existing);
    return p.string();
  }
  [[nodiscard]] bool marker_exists() const { return fs::exists(marker_); }
  /// Run a gnuplot script written by --plot-script in a directory of its own: it must draw its
  /// figure and run nothing else.
  void expect_script_inert(const fs::path& script) const {
    const auto text = slurp(script);
    ASSERT_FALSE(text.empty()) << script;
    EXPECT_EQ(script_string_problem(text), "") << script;
    EXPECT_EQ(enhanced_text_problem(text), "") << script;
    TempDir run_dir;
    const auto cmd = fmt::format("cd {} && {} {} >/dev/null 2>&1", shell_quote(run_dir.path().string()),
                                 shell_quote(rwcalc::gnuplot_command()), shell_quote(script.string()));
    EXPECT_EQ(std::system(cmd.c_str()), 0) << "gnuplot failed on " << script;
    EXPECT_FALSE(marker_exists()) << "the script ran an injected command: " << script;
  }

  static TempDir* dir_;
  static std::string record_;
  TempDir work_;
  fs::path marker_;
  std::unique_ptr<ScopedEnv> env_;
};
TempDir* HostileNames::dir_ = nullptr;
std::string HostileNames::record_;

/// The figure is a well-formed SVG whose text is valid UTF-8.
void expect_good_svg(const fs::path& svg) {
  const auto text = slurp(svg);
  ASSERT_FALSE(text.empty()) << svg;
  EXPECT_EQ(xml_problem(text.substr(text.find("<svg"))), "") << svg;
  EXPECT_TRUE(valid_utf8(text)) << svg;
}

}  // namespace

// ---- the encoding functions ------------------------------------------------------------------

TEST(Printable, ControlCharactersAndInvalidBytesAreEscapedTextKept) {
  using rwcalc::printable;
  EXPECT_EQ(printable("plain name_01.csv"), "plain name_01.csv");
  EXPECT_EQ(printable("°/√h τ ″² −50 °C"), "°/√h τ ″² −50 °C");  // UTF-8 text is kept
  EXPECT_EQ(printable("a\nb\rc\td"), "a\\nb\\rc\\td");
  EXPECT_EQ(printable(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(printable("\x1b[31mred\x7f"), "\\x1b[31mred\\x7f");
  EXPECT_EQ(printable("bad\xff\xfe"), "bad\\xff\\xfe");
  EXPECT_EQ(printable("cut\xc3"), "cut\\xc3");                    // truncated sequence
  EXPECT_EQ(printable("over\xc0\xaf"), "over\\xc0\\xaf");         // overlong '/'
  EXPECT_EQ(printable("sur\xed\xa0\x80"), "sur\\xed\\xa0\\x80");  // a UTF-16 surrogate
  EXPECT_EQ(printable("c1\xc2\x9b"), "c1\\u009b");                // C1 control (CSI)
  EXPECT_EQ(printable("bidi\xe2\x80\xae"), "bidi\\u202e");        // right-to-left override
  EXPECT_EQ(printable("nc\xef\xbf\xbe\xef\xb7\x90\xf4\x8f\xbf\xbf"), "nc\\ufffe\\ufdd0\\U0010ffff");  // noncharacters
  EXPECT_EQ(printable("quote ' \" \\ kept"), "quote ' \" \\ kept");
}

TEST(GnuplotString, EveryStringBecomesOneInertSingleQuotedLiteral) {
  using rwcalc::gnuplot_string;
  EXPECT_EQ(gnuplot_string("run.csv"), "'run.csv'");
  EXPECT_EQ(gnuplot_string("it's"), "'it''s'");
  EXPECT_EQ(gnuplot_string("a\nsystem(\"touch x\")\n#"), "'a\\nsystem(\"touch x\")\\n#'");
  EXPECT_EQ(gnuplot_string("cr\rtab\t"), "'cr\\rtab\\t'");
  EXPECT_EQ(gnuplot_string("back\\slash"), "'back\\slash'");  // no escapes in '…': kept as typed
  EXPECT_EQ(gnuplot_string("`touch x`"), "'`touch x`'");      // no substitution in '…'
  EXPECT_EQ(gnuplot_string("^{x}_y@&~{}"), "'^{x}_y@&~{}'");  // shown as typed: texts are noenhanced
  EXPECT_EQ(gnuplot_string("bad\xff"), "'bad\\xff'");
  EXPECT_EQ(gnuplot_string("τ (s) °/h"), "'τ (s) °/h'");
  for (const auto& s : hostile_strings()) {
    const auto g = gnuplot_string(s);
    EXPECT_EQ(script_string_problem(g), "") << g;
    EXPECT_EQ(g.find('\n'), std::string::npos);
  }
}

TEST(PlotScriptStrings, NoControlCharacterInsideAnyStringOfAnyFigure) {
  // Every string an analysis, a batch and a diagnosis carry, hostile; the output path too.
  for (const auto& bad : hostile_strings()) {
    const std::string nonutf8 = bad + "\xff";
    auto a = fixture_analysis({});
    a["source"] = nonutf8;
    a["allan"]["unit"] = bad;
    auto b = fixture_batch();
    for (auto& r : b["runs"]) r["source"] = bad;
    auto d = fixture_diagnosis();
    d["source"] = bad;
    d["findings"][0]["effect"] = nonutf8;
    rwcalc::PlotOptions o;
    const std::vector<rwcalc::Figure> figures{rwcalc::analysis_figure(a, o), rwcalc::batch_allan_figure(b["runs"], o),
                                              rwcalc::batch_direct_figure(b["runs"], o),
                                              rwcalc::diagnosis_figure(d, o)};
    o.title = nonutf8;
    const std::vector<rwcalc::Figure> titled{rwcalc::analysis_figure(a, o), rwcalc::batch_direct_figure(b["runs"], o),
                                             rwcalc::diagnosis_figure(d, o)};
    for (const auto* set : {&figures, &titled})
      for (const auto format : {rwcalc::PlotFormat::Svg, rwcalc::PlotFormat::Png, rwcalc::PlotFormat::Pdf}) {
        const auto script = rwcalc::full_script(*set, format, 960, "out/" + nonutf8 + ".svg");
        EXPECT_EQ(script_string_problem(script), "") << bad;
        EXPECT_EQ(enhanced_text_problem(script), "") << bad;
      }
  }
}

TEST(PlotScriptStrings, RenderedTitlesAndKeysShowTheNameAsTyped) {
  REQUIRE_GNUPLOT();
  auto a = fixture_analysis({});
  a["source"] = "dir/e^{x}_y@&\\n'q'<b>\nz.csv";
  const auto svg = rwcalc::render_figures({rwcalc::analysis_figure(a, {})}, rwcalc::PlotFormat::Svg, 960);
  EXPECT_EQ(xml_problem(svg.substr(svg.find("<svg"))), "");
  // The newline shows as \n; markup is not interpreted; gnuplot escapes & and < for SVG.
  EXPECT_NE(svg.find("Allan deviation of e^{x}_y@&amp;\\n'q'&lt;b>\\nz.csv"), std::string::npos);
}

// ---- every command that draws, end to end -----------------------------------------------------

TEST_F(HostileNames, AnalyzePlotAndScriptRunNothing) {
  REQUIRE_GNUPLOT();
  for (const auto& name : hostile_file_names()) {
    SCOPED_TRACE(rwcalc::printable(name));
    const auto file = recording_named(name);
    const auto svg = work_.path() / "a.svg", gp = work_.path() / "a.gp";
    const auto r = run_exe({"analyze", file, "--plot", svg.string(), "--plot-script", gp.string(), "--force"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(marker_exists()) << "analyze --plot ran an injected command";
    expect_good_svg(svg);
    expect_script_inert(gp);
  }
}

TEST_F(HostileNames, BatchPlotAndScriptRunNothing) {
  REQUIRE_GNUPLOT();
  std::vector<std::string> args{"batch"};
  for (const auto& name : hostile_file_names()) args.push_back(recording_named(name));
  const auto svg = work_.path() / "b.svg", gp = work_.path() / "b.gp";
  const auto r = run_exe(rwcalc::test::concat(args, {"--plot", svg.string(), "--plot-script", gp.string()}));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(marker_exists()) << "batch --plot ran an injected command";
  expect_good_svg(svg);
  expect_script_inert(gp);
}

TEST_F(HostileNames, DiagnosePlotAndScriptRunNothing) {
  REQUIRE_GNUPLOT();
  for (const auto& name : hostile_file_names()) {
    SCOPED_TRACE(rwcalc::printable(name));
    const auto file = recording_named(name);
    const auto svg = work_.path() / "d.svg", gp = work_.path() / "d.gp";
    const auto r =
        run_exe({"diagnose", file, "--runs", "10", "--plot", svg.string(), "--plot-script", gp.string(), "--force"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(marker_exists()) << "diagnose --plot ran an injected command";
    expect_good_svg(svg);
    expect_script_inert(gp);
  }
}

TEST_F(HostileNames, HostileOutputPathsReachNoScript) {
  REQUIRE_GNUPLOT();
  // The figure and script paths themselves carry the injection: the figure is drawn by gnuplot
  // in a private directory, and the script's `set output` names the path in an inert form.
  const auto stem = work_.path() / "out\nsystem(\"touch $RWCALC_TEST_MARKER\")\n#";
  const auto svg = stem.string() + ".svg", gp = stem.string() + ".gp";
  const auto r = run_exe({"analyze", record_, "--plot", svg, "--plot-script", gp});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(marker_exists());
  expect_good_svg(svg);
  expect_script_inert(gp);
  // A script alone names its own path with .svg.
  const auto gp2 = work_.path() / "only'`touch $RWCALC_TEST_MARKER`\rsystem(\"touch $RWCALC_TEST_MARKER\").gp";
  const auto r2 = run_exe({"analyze", record_, "--plot-script", gp2.string()});
  EXPECT_EQ(r2.status, 0) << r2.err;
  expect_script_inert(gp2);
}

TEST_F(HostileNames, AHostileTemporaryDirectoryReachesNoScript) {
  REQUIRE_GNUPLOT();
  // gnuplot draws into a private directory under TMPDIR; its path must not enter the script.
  const auto tmp = work_.path() / "tmp\nsystem(\"touch $RWCALC_TEST_MARKER\")\n#";
  fs::create_directory(tmp);
  ScopedEnv env("TMPDIR", tmp.c_str());
  const auto svg = work_.path() / "t.svg";
  const auto r = run_exe({"analyze", record_, "--plot", svg.string()});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(marker_exists()) << "the temporary directory's name ran as a command";
  expect_good_svg(svg);
}

TEST_F(HostileNames, ReportOfHostileRecordingsRunsNothingAndEscapesEverything) {
  REQUIRE_GNUPLOT();
  std::vector<std::string> args{"report"};
  for (const auto& name : hostile_file_names()) args.push_back(recording_named(name));
  const auto out = work_.path() / "rep";
  const auto r = run_exe(rwcalc::test::concat(args, {"--diagnose", "--diagnose-runs", "10", "-o", out.string()}));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(marker_exists()) << "report ran an injected command";
  const auto html = slurp(out / "report.html");
  ASSERT_FALSE(html.empty());
  EXPECT_EQ(xml_problem(html.substr(html.find("<html"))), "");
  EXPECT_TRUE(valid_utf8(html));
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find('\x1b'), std::string::npos);
  EXPECT_EQ(html.find('\r'), std::string::npos);
  const auto figures = inline_figures(html);
  EXPECT_EQ(figures.size(), 1 + 1 + hostile_file_names().size() * 2);  // batch Figs. 1, 2; per run: Allan, diagnosis
  for (const auto& [id, svg] : figures) {
    EXPECT_EQ(xml_problem(svg.substr(svg.find("<svg"))), "") << id;
    EXPECT_TRUE(valid_utf8(svg)) << id;
  }
}

TEST_F(HostileNames, ReportOfHostileSavedJsonRunsNothingAndEscapesEverything) {
  REQUIRE_GNUPLOT();
  // Every string a saved analysis and a saved diagnosis carry, hostile.
  const auto hostile = hostile_strings();
  json batch = fixture_batch();
  std::size_t k = 0;
  auto next = [&] { return hostile[k++ % hostile.size()]; };
  for (auto& run : batch["runs"]) {
    run["source"] = next() + ".csv";
    run["allan"]["unit"] = next();
    run["allan"]["estimator"] = next();
    run["verdict"]["statement"] = next();
    run["verdict"]["statement_B"] = next();
    run["verdict"]["statement_N"] = next();
    run["verdict"]["table"] = next();
    run["verdict"]["b_estimate"] = next();
    run["verdict"]["B"]["unit"] = next();
    run["conventions"] = {{next(), next()}, {"Q", next()}};
  }
  batch["overall"]["statement"] = next();
  json diagnosis = fixture_diagnosis();
  diagnosis["source"] = batch["runs"][0]["source"];
  diagnosis["units"] = {{"dev", next()}, {"tau", next()}, {next(), next()}};
  diagnosis["findings"][0]["effect"] = next();
  diagnosis["findings"][0]["evidence"] = next();
  diagnosis["findings"][0][next()] = 1.5;
  diagnosis["findings"].push_back({{"effect", next()}, {next() + "_hz", next()}});
  // The saved files' own names are hostile too (they are listed in the settings table).
  const auto batch_file = work_.path() / ("b" + next() + ".json");
  const auto diag_file = work_.path() / ("d" + next() + ".json");
  ASSERT_TRUE(static_cast<bool>(std::ofstream(batch_file) << batch.dump(1)));
  ASSERT_TRUE(static_cast<bool>(std::ofstream(diag_file) << diagnosis.dump(1)));
  const auto out = work_.path() / "rep";
  const auto r = run_exe({"report", batch_file.string(), diag_file.string(), "-o", out.string(), "--title",
                          "<script>alert(1)</script>\n\x1b[31m"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(marker_exists()) << "report ran an injected command";
  const auto html = slurp(out / "report.html");
  ASSERT_FALSE(html.empty());
  EXPECT_EQ(xml_problem(html.substr(html.find("<html"))), "");
  EXPECT_TRUE(valid_utf8(html));
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find('\x1b'), std::string::npos);
  EXPECT_EQ(html.find('\r'), std::string::npos);
  // Attributes: only data: URIs of the inline figures, no quote breaks out of them.
  for (auto p = html.find("src=\""); p != std::string::npos; p = html.find("src=\"", p + 1))
    EXPECT_EQ(html.compare(p, 31, "src=\"data:image/svg+xml;base64,"), 0) << html.substr(p, 60);
  EXPECT_EQ(html.find("href="), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
  EXPECT_NE(html.find("&quot;javascript:x&quot;"), std::string::npos);
  const auto figures = inline_figures(html);
  EXPECT_GE(figures.size(), 3u);
  for (const auto& [id, svg] : figures) {
    EXPECT_EQ(xml_problem(svg.substr(svg.find("<svg"))), "") << id;
    EXPECT_TRUE(valid_utf8(svg)) << id;
  }
}

// ---- messages ------------------------------------------------------------------------------------

TEST(HostileMessages, AFileNameCannotForgeALineOrColourTheTerminal) {
  TempDir dir;
  const auto missing = (dir.path() / "gone\nrwcalc: forged line\n\x1b[31mred\r\xff.csv").string();
  auto r = run_exe({"analyze", missing});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_TRUE(valid_utf8(r.err)) << r.err;
  EXPECT_NE(r.err.find("gone\\nrwcalc: forged line\\n\\x1b[31mred\\r\\xff.csv"), std::string::npos) << r.err;

  // A file that exists but is bad: its error names it the same way.
  const auto bad = dir.write("bad\n\x1b[2J.csv", "# rate_hz: 400\npulses\n1\nnot a number\n");
  r = run_exe({"analyze", bad.string()});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad\\n\\x1b[2J.csv"), std::string::npos) << r.err;

  // An unknown option is a parse error: its message and the hint line, nothing more.
  r = run_exe({"analyze", "--no-such\n\x1b[31mforged"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
}

// ---- reports on standard output ------------------------------------------------------------------

/// The human-readable text of every command that names its input shows a hostile name spelled
/// out: no control character but the line ends, valid UTF-8, so no forged line or terminal escape.
TEST_F(HostileNames, TextReportsSpellOutTheNames) {
  const std::string name = "nl\nrwcalc analyze: forged\x1b[2J\r\xff.csv";
  const auto file = recording_named(name);
  const auto expect_plain = [](const rwcalc::test::CliResult& r, const std::string& what) {
    EXPECT_EQ(r.status, 0) << what << ": " << r.err;
    for (char c : r.out) {
      if (c == '\n') continue;
      EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == '\x7f') << what << ": raw control character";
    }
    EXPECT_TRUE(valid_utf8(r.out)) << what;
    EXPECT_NE(r.out.find("nl\\nrwcalc analyze: forged\\x1b[2J\\r\\xff.csv"), std::string::npos)
        << what << ": " << r.out;
  };
  expect_plain(run_exe({"analyze", file}), "analyze");
  expect_plain(run_exe({"allan", file}), "allan");
  expect_plain(run_exe({"batch", file}), "batch");
  const auto sim = (work_.path() / ("sim\n\x1b[2J.csv")).string();
  const auto r = run_exe({"simulate", "--duration", "60", "-o", sim});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sim\\n\\x1b[2J.csv"), std::string::npos) << r.out;
}
