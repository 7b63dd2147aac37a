// '--plot' and '--plot-script' of 'rwcalc analyze' and 'rwcalc batch', end to end on the shipped
// GL-2D runs: the figures are drawn, are well-formed SVG with the expected series, PNG and PDF
// follow the extension, and every error path fails cleanly before the analysis. Also the
// direct-method curve the batch's Fig. 2 reads from the analysis JSON.
// Rendering tests skip with a message when gnuplot is not installed.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "rwcalc/plot.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::concat;
using rwcalc::test::gl2d_runs;
using rwcalc::test::run_cli;
using rwcalc::test::ScopedEnv;
using rwcalc::test::slurp;
using rwcalc::test::source_path;
using rwcalc::test::svg_series;
using rwcalc::test::TempDir;
using rwcalc::test::xml_problem;

namespace {

std::string gl2d(const std::string& name) { return source_path("data/gl2d/" + name).string(); }

/// Series the analysis figure must hold, from its JSON: the measurement, the model, one line per
/// term that is resolved or has a 95 % bound, one floor per class limit of B.
std::size_t expected_analysis_series(const json& a) {
  std::size_t n = 2;
  for (const char* k : {"Q", "N", "B", "K", "R"}) {
    const auto& c = a["fit"][k];
    const bool resolved = c["resolved"].get<bool>();
    const double v = c["value"].get<double>();
    const double bound = c.contains("high95") ? c["high95"].get<double>() : v;
    n += (resolved ? v > 0 : bound > 0) ? 1 : 0;
  }
  return n + a["verdict"]["B"]["limits"].size();
}

}  // namespace

// ---- the direct-method curve in the analysis JSON ---------------------------------------------

TEST(AnalyzeJson, CarriesTheDirectMethodCurveAndItsRegression) {
  const auto r = run_cli({"analyze", gl2d("gl2d_p50C.csv.gz"), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  const auto& d = j["methods"]["N_direct"];
  ASSERT_TRUE(d.contains("curve"));
  const auto& curve = d["curve"];
  ASSERT_GE(curve.size(), 3u);
  const double duration = j["duration_s"];
  double t_prev = 0;
  for (const auto& p : curve) {
    const double t = p["t_s"], v = p["var"];
    const auto k = p["intervals"].get<std::size_t>();
    EXPECT_GT(t, t_prev);
    t_prev = t;
    EXPECT_GT(v, 0);
    // Overlapping increments of length t, one per sample: M = n − t/τ0 + 1.
    const double tau0 = 1.0 / j["rate_hz"].get<double>();
    EXPECT_NEAR(static_cast<double>(k) * tau0 + t, duration + tau0, 1e-6);
    // The regression (exact Q, N, B expectations) passes through every point within 10 %.
    EXPECT_NEAR(p["model"].get<double>() / v, 1.0, 0.1) << "t = " << t;
  }
  // Within the requested range (default 1..100 s).
  EXPECT_NEAR(curve.front()["t_s"].get<double>(), d["t_min_s"].get<double>(), 1e-12);
  EXPECT_NEAR(curve.back()["t_s"].get<double>(), d["t_max_s"].get<double>(), 1e-12);
  EXPECT_LE(curve.back()["t_s"].get<double>(), 100.0 + 1e-9);
  // N″² in ″²/s of the regression: N = √N″² / 60 (N in °/√h), the value the tables print.
  ASSERT_TRUE(d["resolved"].get<bool>());
  EXPECT_NEAR(std::sqrt(d["N2"].get<double>()) / 60.0, d["value"].get<double>(), 1e-12);
  // The line drawn with the points is the paper's straight line, whose N is √slope / 60.
  const auto& paper = j["methods"]["N_straight_line_paper"];
  const double slope = d["slope"];
  EXPECT_NEAR(std::sqrt(slope) / 60.0, paper["value"].get<double>(), 1e-12);
  EXPECT_GT(paper["bias_factor"].get<double>(), 1.0);
}

// ---- analyze --plot ---------------------------------------------------------------------------

TEST(AnalyzePlot, SvgHasTheMeasurementModelTermsAndClassLimits) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  const auto svg_path = dir.path() / "allan.svg";
  const auto json_path = dir.path() / "a.json";
  const auto r =
      run_cli({"analyze", gl2d("gl2d_p25C.csv.gz"), "--json", "-o", json_path.string(), "--plot", svg_path.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("figure written to " + svg_path.string()), std::string::npos) << r.err;
  const json a = json::parse(slurp(json_path));
  const auto svg = slurp(svg_path);
  ASSERT_EQ(xml_problem(svg), "");
  const auto n = expected_analysis_series(a);
  EXPECT_GE(n, 2u + 3u + 3u) << "Q, N and B are resolved on this run";
  EXPECT_EQ(svg_series(svg).size(), n);
  EXPECT_NE(r.err.find(fmt::format("({} data series)", n)), std::string::npos) << r.err;
  for (const char* s : {"τ (s)", "Allan deviation σ(τ) (°/h)", "fitted model", "class 1 limit B", "angle random walk N",
                        "bias instability B", "quantization Q", "68.3 % bounds", "gl2d_p25C.csv.gz at +25 °C"})
    EXPECT_NE(svg.find(s), std::string::npos) << s;
}

TEST(AnalyzePlot, PngAndPdfByExtensionAndTheScriptRedrawsTheFigure) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  const auto png = dir.path() / "allan.PNG", pdf = dir.path() / "allan.pdf", gp = dir.path() / "allan.gp";
  auto r = run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--plot", png.string(), "--plot-script", gp.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  // The readable report still goes to standard output.
  EXPECT_NE(r.out.find("rwcalc analyze:"), std::string::npos);
  EXPECT_EQ(slurp(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const auto script = slurp(gp);
  EXPECT_NE(script.find("$allan << EOD"), std::string::npos);
  EXPECT_NE(script.find("set output '" + png.string() + "'"), std::string::npos);
  r = run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--plot", pdf.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(pdf).substr(0, 5), "%PDF-");
  // The written script, run by gnuplot, draws the same PNG again.
  fs::remove(png);
  ASSERT_EQ(std::system((rwcalc::gnuplot_command() + " '" + gp.string() + "' 2>/dev/null").c_str()), 0);
  EXPECT_EQ(slurp(png).substr(0, 4), "\x89PNG");
}

TEST(AnalyzePlot, ScriptAloneNeedsNoGnuplot) {
  TempDir dir;
  ScopedEnv env("RWCALC_GNUPLOT", "/nonexistent/gnuplot");
  const auto gp = dir.path() / "allan.gp";
  const auto r = run_cli({"analyze", gl2d("gl2d_m25C.csv.gz"), "--plot-script", gp.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto script = slurp(gp);
  EXPECT_NE(script.find("set output '" + (dir.path() / "allan.svg").string() + "'"), std::string::npos);
  EXPECT_NE(script.find("model(t) = sqrt(0"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir.path() / "allan.svg"));
}

// ---- batch --plot: the paper's Figs. 1 and 2 ------------------------------------------------------

TEST(BatchPlot, FiveTemperaturesOverlaidAndTheDirectMethodPanel) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  const auto svg_path = dir.path() / "batch.svg";
  const auto json_path = dir.path() / "batch.json";
  const auto r = run_cli(
      concat({"batch"}, concat(gl2d_runs(), {"--json", "-o", json_path.string(), "--plot", svg_path.string()})));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("note:"), std::string::npos) << "Fig. 2 must not be left out: " << r.err;
  const json b = json::parse(slurp(json_path));
  ASSERT_EQ(b["runs"].size(), 5u);
  for (const auto& run : b["runs"]) EXPECT_GE(run["methods"]["N_direct"]["curve"].size(), 3u);
  const auto svg = slurp(svg_path);
  ASSERT_EQ(xml_problem(svg), "");
  const auto ids = svg_series(svg);
  const std::size_t limits = b["runs"][0]["verdict"]["B"]["limits"].size();
  // Panel a: five runs and the class floors; panel b: points and regression line per run.
  EXPECT_EQ(ids.size(), 5 + limits + 10) << svg.size();
  EXPECT_TRUE(ids.count(std::to_string(5 + limits) + "a") && !ids.count(std::to_string(6 + limits) + "a"));
  EXPECT_TRUE(ids.count("10b") && !ids.count("11b"));
  for (const char* s : {"−50 °C", "−25 °C", "0 °C", "+25 °C", "+50 °C", "interval length t (s)",
                        "angle variance D(t) (″²)", "Allan deviation at each test temperature"})
    EXPECT_NE(svg.find(s), std::string::npos) << s;
}

// ---- error paths --------------------------------------------------------------------------------

TEST(PlotCliErrors, MissingGnuplotFailsBeforeTheAnalysisWithAClearMessage) {
  TempDir dir;
  ScopedEnv env("RWCALC_GNUPLOT", "/nonexistent/gnuplot");
  const auto svg = dir.path() / "a.svg";
  for (const auto& args : {std::vector<std::string>{"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot", svg.string()},
                           concat({"batch"}, concat(gl2d_runs(), {"--plot", svg.string()}))}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 3) << args[0];
    EXPECT_NE(r.err.find("cannot run gnuplot ('/nonexistent/gnuplot'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("apt-get install gnuplot-nox"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("RWCALC_GNUPLOT"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "nothing is printed: the command stops before the analysis";
    EXPECT_FALSE(fs::exists(svg));
  }
  // The separate executable behaves the same.
  const auto e = rwcalc::test::run_exe({"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot", svg.string()});
  EXPECT_EQ(e.status, 3) << e.err;
  EXPECT_NE(e.err.find("gnuplot-nox"), std::string::npos) << e.err;
}

TEST(PlotCliErrors, UnknownExtensionIsAUsageError) {
  TempDir dir;
  for (const char* name : {"a.jpg", "noext"}) {
    const auto path = dir.path() / name;
    for (const auto& args : {std::vector<std::string>{"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot", path.string()},
                             std::vector<std::string>{"batch", gl2d("gl2d_p25C.csv.gz"), "--plot", path.string()}}) {
      const auto r = run_cli(args);
      EXPECT_EQ(r.status, 2) << args[0] << " " << name;
      EXPECT_NE(r.err.find("name the file .svg, .png or .pdf"), std::string::npos) << r.err;
      EXPECT_EQ(r.out, "");
      EXPECT_FALSE(fs::exists(path));
    }
  }
  // The same file for the figure and the script.
  const auto same = (dir.path() / "x.svg").string();
  const auto r = run_cli({"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot", same, "--plot-script", same});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("name the same file"), std::string::npos) << r.err;
}

TEST(PlotCliErrors, ExistingFilesAreKeptWithoutForce) {
  TempDir dir;
  const auto svg = dir.write("a.svg", "old figure");
  const auto gp = dir.write("a.gp", "old script");
  for (const auto& args : {std::vector<std::string>{"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot", svg.string()},
                           std::vector<std::string>{"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot-script", gp.string()},
                           std::vector<std::string>{"batch", gl2d("gl2d_p25C.csv.gz"), "--plot", svg.string()}}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 3) << args[2] << args[3];
    EXPECT_NE(r.err.find("exists; use --force to overwrite it"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
  EXPECT_EQ(slurp(svg), "old figure");
  EXPECT_EQ(slurp(gp), "old script");
  // --force replaces them.
  const auto r = run_cli({"analyze", gl2d("gl2d_p25C.csv.gz"), "--plot-script", gp.string(), "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(gp).find("$allan << EOD"), std::string::npos);
  if (rwcalc::gnuplot_available()) {
    const auto f = run_cli({"batch", gl2d("gl2d_p25C.csv.gz"), "--plot", svg.string(), "--force"});
    ASSERT_EQ(f.status, 0) << f.err;
    EXPECT_EQ(xml_problem(slurp(svg)), "");
  }
}
