// Figures: the generated gnuplot scripts, the rendered SVG/PNG/PDF files, and every error path.
// Tests that render need gnuplot and skip with a message when it is absent.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "rwcalc/error.hpp"
#include "rwcalc/plot.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::fixture_analysis;
using rwcalc::test::fixture_batch;
using rwcalc::test::fixture_diagnosis;
using rwcalc::test::FixtureCoefficients;
using rwcalc::test::ScopedEnv;
using rwcalc::test::slurp;
using rwcalc::test::svg_series;
using rwcalc::test::TempDir;
using rwcalc::test::xml_problem;

namespace {

json k_unresolved_analysis() {
  FixtureCoefficients c;
  c.K_resolved = false;  // K: 95 % bound only (drawn dashed); R: no bound (not drawn)
  return fixture_analysis(c);
}

}  // namespace

// ---- formats and scripts (no gnuplot needed) ----------------------------------------------------

TEST(PlotFormat, ChosenByExtensionCaseInsensitive) {
  EXPECT_EQ(rwcalc::plot_format_for("a/b/fig.svg"), rwcalc::PlotFormat::Svg);
  EXPECT_EQ(rwcalc::plot_format_for("FIG.PNG"), rwcalc::PlotFormat::Png);
  EXPECT_EQ(rwcalc::plot_format_for("x.Pdf"), rwcalc::PlotFormat::Pdf);
  EXPECT_THROW(rwcalc::plot_format_for("fig.jpg"), rwcalc::UsageError);
  try {
    rwcalc::plot_format_for("figure");
    FAIL() << "no extension accepted";
  } catch (const rwcalc::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find(".svg, .png or .pdf"), std::string::npos) << e.what();
  }
}

TEST(PlotScript, TheModelLineIsTheFittedCurveNotTheEstimate) {
  // B's estimate (bias taken out, averaged over K) and the fitted curve's B differ; the figure draws
  // the curve the fit put through the points. Results saved without `model_value` fall back to the estimate.
  json a = k_unresolved_analysis();
  a["fit"]["B"]["estimate"] = 0.0079;
  a["fit"]["B"]["model_value"] = 0.0071;
  EXPECT_NE(rwcalc::analysis_figure(a, {}).script.find("\nB = 0.0071   #"), std::string::npos);
  a["fit"]["B"].erase("model_value");
  EXPECT_NE(rwcalc::analysis_figure(a, {}).script.find("\nB = 0.0079   #"), std::string::npos);
}

TEST(PlotScript, AnalysisFigureHasDataModelTermsAndClassFloors) {
  const auto f = rwcalc::analysis_figure(k_unresolved_analysis(), {});
  // measured, model, Q, N, B, K bound, three class floors; R (no bound) is left out.
  EXPECT_EQ(f.series, 9);
  EXPECT_NE(f.script.find("$allan << EOD"), std::string::npos);
  EXPECT_NE(f.script.find("K_up95 = 0.0008"), std::string::npos) << f.script;
  // The model curve: an unresolved term left out of it counts 0.
  EXPECT_NE(f.script.find("\nK = 0   #"), std::string::npos);
  EXPECT_NE(f.script.find("\nN = 0.0009   #"), std::string::npos);
  EXPECT_NE(f.script.find("rate random walk K < 0.0008 °/h/√h (95 %)"), std::string::npos);
  EXPECT_EQ(f.script.find("rate ramp R"), std::string::npos);
  for (const char* s : {"class 1 limit B = 0.005 °/h (floor 0.003321 °/h)", "class 2 limit B = 0.008 °/h",
                        "class 3 limit B = 0.015 °/h", "set xlabel 'τ (s)'", "set ylabel 'Allan deviation σ(τ) (°/h)'",
                        "set format x '10^{%L}'", "set key outside below"})
    EXPECT_NE(f.script.find(s), std::string::npos) << s;
  // Every Allan point of the JSON is in the data block.
  const auto n_points = k_unresolved_analysis()["allan"]["points"].size();
  const auto block = f.script.substr(f.script.find("$allan << EOD"));
  EXPECT_EQ(static_cast<std::size_t>(std::count(block.begin(), block.begin() + block.find("EOD\n", 14), '\n')),
            n_points + 2);  // header line + comment line + one per point
}

TEST(PlotScript, ClassTableFromTheJsonReplacesTheBuiltInOne) {
  auto a = fixture_analysis({});
  a["verdict"]["classes"] = {1, 2};
  a["verdict"]["B"]["limits"] = {0.004, 0.02};
  a["verdict"]["tolerance_pct"] = 50;
  const auto f = rwcalc::analysis_figure(a, {});
  EXPECT_NE(f.script.find("class 1 limit B = 0.004 °/h (+50 % tolerance)"), std::string::npos);
  EXPECT_NE(f.script.find("class 2 limit B = 0.02 °/h"), std::string::npos);
  EXPECT_EQ(f.script.find("class 3 limit"), std::string::npos);
  EXPECT_EQ(f.series, 2 + 4 + 2);  // measured, model, Q N B K (resolved; R has no bound), two floors
}

TEST(PlotScript, MissingAllanPointsIsAnAnalysisError) {
  auto a = fixture_analysis({});
  a["allan"].erase("points");
  EXPECT_THROW(rwcalc::analysis_figure(a, {}), rwcalc::AnalysisError);
  a["allan"]["points"] = json::array({{{"tau_s", 1.0}, {"dev", nullptr}}});
  EXPECT_THROW(rwcalc::analysis_figure(a, {}), rwcalc::AnalysisError);
  EXPECT_THROW(rwcalc::plot_batch(json{{"runs", json::array()}}, {}), rwcalc::AnalysisError);
  json d = fixture_diagnosis();
  d.erase("band");
  EXPECT_THROW(rwcalc::diagnosis_figure(d, {}), rwcalc::AnalysisError);
}

TEST(PlotScript, BatchSortsRunsByTemperatureWithFixedColours) {
  const auto batch = fixture_batch();
  const auto f = rwcalc::batch_allan_figure(batch["runs"], {});
  EXPECT_EQ(f.series, 5 + 3);
  std::size_t last = 0;
  for (const char* t : {"'−50 °C", "'−20 °C", "'0 °C", "'+25 °C", "'+50 °C"}) {
    const auto p = f.script.find(t);
    ASSERT_NE(p, std::string::npos) << t;
    EXPECT_GT(p, last) << t << " out of temperature order";
    last = p;
  }
  // The colour of a temperature is the same in both batch figures.
  const auto d = rwcalc::batch_direct_figure(batch["runs"], {});
  const auto colour = rwcalc::temperature_colour(json(-20.0), 99);
  EXPECT_NE(f.script.find(colour), std::string::npos);
  EXPECT_NE(d.script.find(colour), std::string::npos);
  EXPECT_EQ(d.series, 10);  // points and regression line per run
}

TEST(PlotScript, TemperatureColoursRunColdToHotAndFallBackByIndex) {
  auto rgb = [](const std::string& c) {
    return std::array<int, 3>{std::stoi(c.substr(1, 2), nullptr, 16), std::stoi(c.substr(3, 2), nullptr, 16),
                              std::stoi(c.substr(5, 2), nullptr, 16)};
  };
  const auto cold = rgb(rwcalc::temperature_colour(json(-50.0), 0));
  const auto hot = rgb(rwcalc::temperature_colour(json(50.0), 0));
  EXPECT_GT(cold[2], cold[0]);  // blue
  EXPECT_GT(hot[0], hot[2]);    // red
  EXPECT_EQ(rwcalc::temperature_colour(json(12.5), 0), rwcalc::temperature_colour(json(12.5), 7));
  EXPECT_EQ(rwcalc::temperature_colour(json(-80.0), 0), rwcalc::temperature_colour(json(-50.0), 0));
  std::set<std::string> distinct;
  for (std::size_t i = 0; i < 5; ++i) distinct.insert(rwcalc::temperature_colour(json(nullptr), i));
  EXPECT_EQ(distinct.size(), 5u);
}

TEST(PlotScript, ScriptOnlyNeedsNoGnuplot) {
  TempDir dir;
  ScopedEnv env("RWCALC_GNUPLOT", "/nonexistent/gnuplot");
  rwcalc::PlotOptions o;
  o.script = (dir.path() / "fig.gp").string();
  const auto r = rwcalc::plot_analysis(fixture_analysis({}), o);
  EXPECT_EQ(r.series, 9);  // measured, model, Q N B K, three class floors
  const auto script = slurp(o.script);
  // Without --plot the script draws to the script's name with .svg.
  EXPECT_NE(script.find("set output '" + (dir.path() / "fig.svg").string() + "'"), std::string::npos) << script;
  EXPECT_NE(script.find("set terminal svg"), std::string::npos);
}

// ---- rendering ---------------------------------------------------------------------------------

TEST(PlotRender, AnalysisSvgIsWellFormedWithOneGroupPerSeries) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "allan.svg").string();
  const auto r = rwcalc::plot_analysis(k_unresolved_analysis(), o);
  const auto svg = slurp(o.output);
  EXPECT_EQ(xml_problem(svg), "");
  EXPECT_EQ(r.series, 9);
  EXPECT_EQ(svg_series(svg).size(), 9u);
  for (const char* s : {"τ (s)", "Allan deviation σ(τ) (°/h)", "class 1 limit B", "fitted model"})
    EXPECT_NE(svg.find(s), std::string::npos) << s;
  EXPECT_TRUE(r.notes.empty());
}

TEST(PlotRender, TheWrittenScriptReproducesTheFigure) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "fig's.svg").string();  // a quote in the path must survive quoting
  o.script = (dir.path() / "fig.gp").string();
  o.title = "Bob's gyro_x {axis} @ 50% <a> & b";
  rwcalc::plot_analysis(fixture_analysis({}), o);
  const auto first = slurp(o.output);
  ASSERT_EQ(xml_problem(first), "");
  EXPECT_NE(first.find("Bob's gyro_x {axis} @ 50% &lt;a> &amp; b"), std::string::npos);
  fs::remove(o.output);
  const auto cmd = rwcalc::gnuplot_command() + " '" + o.script + "' 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto again = slurp(o.output);
  EXPECT_EQ(xml_problem(again), "");
  EXPECT_EQ(svg_series(again), svg_series(first));
}

TEST(PlotRender, TheModelInTheScriptIsTheIeeeModelInDegPerHour) {
  REQUIRE_GNUPLOT();
  // Evaluate the script's model(τ) and term functions in gnuplot and compare with the 5-term model
  // computed independently (σ² = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2, τ in h where N, K,
  // R demand it).
  FixtureCoefficients c;
  c.K = 0.002;
  c.R = 0.0;
  const auto f = rwcalc::analysis_figure(fixture_analysis(c), {});
  TempDir dir;
  const auto out = dir.path() / "values.txt";
  const auto body = f.script.substr(0, f.script.find("\nplot ") + 1);
  const std::vector<double> taus{0.01, 1.0, 10.0, 100.0, 1000.0, 10000.0};
  std::string eval = body + "set print '" + out.string() + "'\n";
  for (double tau : taus) eval += "print sprintf('%.10g', model(" + std::to_string(tau) + "))\n";
  eval += "print sprintf('%.10g', sR(7200, 10))\n";
  dir.write("eval.gp", eval);
  const auto cmd = rwcalc::gnuplot_command() + " '" + (dir.path() / "eval.gp").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::istringstream in(slurp(out));
  for (double tau : taus) {
    double v = 0;
    ASSERT_TRUE(in >> v);
    EXPECT_NEAR(v, rwcalc::test::fixture_sigma(c, tau), 1e-6 * v) << "τ = " << tau;
  }
  // Rate ramp R = 10 °/h² after 2 h: σ² = R²τ²/2 with τ = 2 h → σ = 10·2/√2 °/h.
  double ramp = 0;
  ASSERT_TRUE(in >> ramp);
  EXPECT_NEAR(ramp, 20 / std::sqrt(2.0), 1e-8);
}

TEST(PlotRender, BatchHasBothPanelsWithTheirSeries) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "batch.svg").string();
  const auto r = rwcalc::plot_batch(fixture_batch(), o);
  const auto svg = slurp(o.output);
  EXPECT_EQ(xml_problem(svg), "");
  const auto ids = svg_series(svg);
  EXPECT_EQ(r.series, 18);
  EXPECT_EQ(ids.size(), 18u);
  EXPECT_TRUE(ids.count("8a") && ids.count("10b") && !ids.count("9a")) << "panel a: 5 runs + 3 floors, b: 5 × 2";
  EXPECT_NE(svg.find("angle variance D(t) (″²)"), std::string::npos);
  EXPECT_TRUE(r.notes.empty());
}

TEST(PlotRender, BatchWithoutDirectCurvesSkipsFigureTwoWithANote) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "batch.svg").string();
  const auto r = rwcalc::plot_batch(fixture_batch(/*with_direct_curve=*/false), o);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("methods.N_direct.curve"), std::string::npos) << r.notes[0];
  const auto svg = slurp(o.output);
  EXPECT_EQ(xml_problem(svg), "");
  EXPECT_EQ(svg_series(svg).size(), 8u);
  EXPECT_EQ(r.series, 8);
}

TEST(PlotRender, DiagnosisShowsBothBandsTheMeasurementAndWhereItLeaves) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "diag.svg").string();
  o.force = true;
  for (bool nested : {false, true}) {
    auto r = rwcalc::plot_diagnosis(fixture_diagnosis(true, nested), o);
    auto svg = slurp(o.output);
    EXPECT_EQ(xml_problem(svg), "");
    // base band, base median, extended band, measurement, the points outside the base band
    EXPECT_EQ(svg_series(svg).size(), 5u);
    EXPECT_EQ(r.series, 5);
    EXPECT_NE(svg.find("findings: sinusoid"), std::string::npos);
    // The fixture's sinusoid lifts σ out of the base band at 2 of the 20 octave τ.
    EXPECT_NE(svg.find("18 of 20 τ inside"), std::string::npos);
    EXPECT_NE(svg.find("20 of 20 τ inside"), std::string::npos);
    EXPECT_TRUE(r.notes.empty());

    r = rwcalc::plot_diagnosis(fixture_diagnosis(/*with_extended=*/false, nested), o);
    svg = slurp(o.output);
    EXPECT_EQ(svg_series(svg).size(), 4u);
    ASSERT_EQ(r.notes.size(), 1u);
    EXPECT_NE(r.notes[0].find("band_extended"), std::string::npos);
  }
}

TEST(PlotRender, PngAndPdfByExtension) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "a.png").string();
  rwcalc::plot_analysis(fixture_analysis({}), o);
  EXPECT_EQ(slurp(o.output).substr(0, 4), "\x89PNG");
  o.output = (dir.path() / "a.pdf").string();
  rwcalc::plot_batch(fixture_batch(), o);
  EXPECT_EQ(slurp(o.output).substr(0, 5), "%PDF-");
}

// ---- error paths -----------------------------------------------------------------------------

TEST(PlotErrors, MissingGnuplotIsAClearOutputError) {
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "a.svg").string();
  for (int variant = 0; variant < 2; ++variant) {
    // Named binary missing, or no gnuplot on an empty PATH.
    ScopedEnv env("RWCALC_GNUPLOT", variant == 0 ? "/nonexistent/gnuplot" : nullptr);
    ScopedEnv path("PATH", variant == 0 ? std::getenv("PATH") : (dir.path() / "empty").c_str());
    EXPECT_FALSE(rwcalc::gnuplot_available());
    try {
      rwcalc::plot_analysis(fixture_analysis({}), o);
      FAIL() << "no error without gnuplot";
    } catch (const rwcalc::OutputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("gnuplot-nox"), std::string::npos) << what;
      EXPECT_NE(what.find("RWCALC_GNUPLOT"), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(o.output));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 0)
        << "temporary files left behind";
  }
}

TEST(PlotErrors, FailingGnuplotReportsItsStatusAndLeavesNoFile) {
  TempDir dir;
  ScopedEnv env("RWCALC_GNUPLOT", "false");
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "a.svg").string();
  try {
    rwcalc::plot_analysis(fixture_analysis({}), o);
    FAIL() << "no error from a failing gnuplot";
  } catch (const rwcalc::OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("failed with status 1"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(o.output));
}

TEST(PlotErrors, ExistingOutputNeedsForce) {
  REQUIRE_GNUPLOT();
  TempDir dir;
  const auto target = dir.write("a.svg", "old");
  rwcalc::PlotOptions o;
  o.output = target.string();
  EXPECT_THROW(rwcalc::plot_analysis(fixture_analysis({}), o), rwcalc::OutputError);
  EXPECT_EQ(slurp(target), "old");
  o.force = true;
  rwcalc::plot_analysis(fixture_analysis({}), o);
  EXPECT_EQ(xml_problem(slurp(target)), "");
}

TEST(PlotErrors, UnknownExtensionFailsBeforeAnyWork) {
  TempDir dir;
  rwcalc::PlotOptions o;
  o.output = (dir.path() / "a.jpg").string();
  o.script = (dir.path() / "a.gp").string();
  EXPECT_THROW(rwcalc::plot_analysis(fixture_analysis({}), o), rwcalc::UsageError);
  EXPECT_FALSE(fs::exists(o.script));
}

TEST(XmlChecker, CatchesMalformedDocuments) {
  // The checker the SVG tests rely on must itself reject broken XML.
  EXPECT_EQ(xml_problem("<?xml version='1.0'?><svg a=\"1\"><g id='x'/><!-- c --><text>a &amp; b</text></svg>"), "");
  EXPECT_NE(xml_problem("<svg><g></svg>"), "");
  EXPECT_NE(xml_problem("<svg a=1></svg>"), "");
  EXPECT_NE(xml_problem("<svg a='1' a='2'></svg>"), "");
  EXPECT_NE(xml_problem("<svg>a & b</svg>"), "");
  EXPECT_NE(xml_problem("<svg></svg><svg></svg>"), "");
  EXPECT_NE(xml_problem("<svg><!-- open </svg>"), "");
  EXPECT_NE(xml_problem(""), "");
}
