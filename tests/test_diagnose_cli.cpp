// `rwcalc diagnose` end to end: a simulated record with a strong sinusoid is diagnosed through
// the CLI (JSON keys, the finding, the gain, the readable report), the figure is a well-formed
// SVG, `rwcalc simulate --from` takes the extended model, and every error path has its status.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rwcalc/plot.hpp"
#include "test_plot_fixtures.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::run_cli;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

namespace {

/// 30 min at 100 Hz of GL-2D-like noise with a 0.3 °/h sinusoid at 0.05 Hz.
class DiagnoseCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    record_ = (dir_->path() / "sin.csv.gz").string();
    const auto r = run_cli({"simulate", "-o", record_, "--duration", "1800", "--rate", "100", "--arw", "0.001",
                            "--bias-instability", "0.005", "--sinusoid", "0.05:0.3", "--seed", "11"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto d = run_cli({"diagnose", record_, "--json", "--runs", "12", "--seed", "5"});
    ASSERT_EQ(d.status, 0) << d.err;
    json_ = new json(json::parse(d.out));
  }
  static void TearDownTestSuite() {
    delete json_;
    delete dir_;
  }
  static TempDir* dir_;
  static std::string record_;
  static json* json_;
};
TempDir* DiagnoseCli::dir_ = nullptr;
std::string DiagnoseCli::record_;
json* DiagnoseCli::json_ = nullptr;

}  // namespace

TEST_F(DiagnoseCli, JsonHasTheDocumentedKeysAndFindsTheSinusoid) {
  const json& j = *json_;
  for (const char* k : {"base_model", "findings", "extended_model", "gain", "detectors"})
    ASSERT_TRUE(j.contains(k)) << k;
  for (const char* m : {"base_model", "extended_model"}) {
    ASSERT_TRUE(j[m]["band"].is_array());
    ASSERT_FALSE(j[m]["band"].empty());
    EXPECT_DOUBLE_EQ(j[m]["band_level"].get<double>(), 0.95);
    for (const auto& row : j[m]["band"]) {
      for (const char* k : {"tau_s", "dev", "band_low", "band_high", "median"}) ASSERT_TRUE(row.contains(k)) << k;
      EXPECT_LE(row["band_low"].get<double>(), row["median"].get<double>());
      EXPECT_LE(row["median"].get<double>(), row["band_high"].get<double>());
    }
  }
  for (const char* k : {"misfit_base", "misfit_extended", "coverage_base", "coverage_extended", "likelihood_in_sample",
                        "likelihood_holdout"})
    ASSERT_TRUE(j["gain"][k].is_number()) << k;
  ASSERT_EQ(j["findings"].size(), 1u) << j["findings"].dump();
  const auto& f = j["findings"][0];
  EXPECT_EQ(f["effect"], "sinusoid");
  const auto& fp = f["parameters"];
  EXPECT_NEAR(fp["frequency"]["value"].get<double>(), 0.05, 1e-3);
  EXPECT_EQ(fp["frequency"]["unit"], "Hz");
  const auto& amp = fp["amplitude"];
  EXPECT_NEAR(amp["value"].get<double>(), 0.3, 0.06);
  EXPECT_EQ(amp["unit"], "deg/h");
  EXPECT_GT(amp["standard_uncertainty"].get<double>(), 0.0);
  EXPECT_LT(amp["interval95"][0].get<double>(), amp["value"].get<double>());
  EXPECT_GT(amp["interval95"][1].get<double>(), amp["value"].get<double>());
  EXPECT_EQ(fp["phase"]["unit"], "rad");
  EXPECT_TRUE(fp["phase"]["standard_uncertainty"].is_null());
  EXPECT_GT(f["evidence"]["statistic"].get<double>(), f["evidence"]["threshold"].get<double>());
  ASSERT_EQ(j["extended_model"]["sinusoids"].size(), 1u);
  EXPECT_LT(j["gain"]["misfit_extended"].get<double>(), j["gain"]["misfit_base"].get<double>());
  EXPECT_GE(j["gain"]["coverage_extended"].get<double>(), j["gain"]["coverage_base"].get<double>());
  // B with the named terms in the data (the base) and without them (the extended model).
  const auto& b = j["bias_instability_named_terms"];
  EXPECT_DOUBLE_EQ(b["with_deg_per_h"].get<double>(), j["base_model"]["bias_instability_deg_per_h"].get<double>());
  EXPECT_DOUBLE_EQ(b["without_deg_per_h"].get<double>(),
                   j["extended_model"]["bias_instability_deg_per_h"].get<double>());
  ASSERT_TRUE(b["with_over_without_percent"].is_number() || b["without_deg_per_h"].get<double>() == 0.0);
  EXPECT_EQ(b["named_terms"], json::array({"sinusoid"}));
}

TEST_F(DiagnoseCli, ResultDoesNotDependOnTheThreadCount) {
  auto diagnosis = [](const char* threads) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    const auto d = rwcalc::test::run_exe({"diagnose", record_, "--json", "--runs", "12", "--seed", "5"});
    EXPECT_EQ(d.status, 0) << d.err;
    json j = json::parse(d.out);
    j.erase("seconds");
    return j;
  };
  const json one = diagnosis("1");
  EXPECT_EQ(one, diagnosis("2"));
  json same = *json_;
  same.erase("seconds");
  EXPECT_EQ(one, same);
}

TEST_F(DiagnoseCli, ReportCarriesUnitsAndTheFinding) {
  const auto r = run_cli({"diagnose", record_, "--runs", "10"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("  sinusoid:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frequency = 0.05"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" Hz; amplitude = "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("°/h"), std::string::npos);
  EXPECT_NE(r.out.find("likelihood gain on held-out runs (−2Δ ln L)"), std::string::npos);
  EXPECT_EQ(r.out.find("nan"), std::string::npos);
}

TEST_F(DiagnoseCli, SimulateTakesTheExtendedModel) {
  const fs::path diag = dir_->path() / "diag.json";
  { std::ofstream(diag) << json_->dump(); }
  const fs::path out = dir_->path() / "again.csv";
  const fs::path truth = dir_->path() / "truth.json";
  const auto r = run_cli({"simulate", "--from", diag.string(), "-o", out.string(), "--truth", truth.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const json t = json::parse(slurp(truth));
  EXPECT_NE(t.dump().find("\"sinusoids\":[{"), std::string::npos) << t.dump();
}

TEST_F(DiagnoseCli, PlotIsAWellFormedSvgWithBothBands) {
  if (!rwcalc::gnuplot_available()) GTEST_SKIP() << "gnuplot not found: install gnuplot-nox to render";
  const fs::path svg = dir_->path() / "diag.svg";
  const fs::path script = dir_->path() / "diag.gp";
  const auto r = run_cli({"diagnose", record_, "--runs", "10", "--json", "-o", (dir_->path() / "d.json").string(),
                          "--plot", svg.string(), "--plot-script", script.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string s = slurp(svg);
  EXPECT_EQ(rwcalc::test::xml_problem(s), "");
  EXPECT_GE(rwcalc::test::svg_series(s).size(), 4u);
  EXPECT_NE(s.find("findings: sinusoid"), std::string::npos);
  EXPECT_NE(slurp(script).find("$base << EOD"), std::string::npos);
  // Existing outputs are not overwritten without --force.
  const auto again = run_cli({"diagnose", record_, "--runs", "10", "--plot", svg.string()});
  EXPECT_EQ(again.status, 3) << again.err;
}

TEST(DiagnoseCliErrors, BadInputUsageAndShortRecords) {
  TempDir dir;
  auto r = run_cli({"diagnose", (dir.path() / "missing.csv").string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("missing.csv"), std::string::npos);
  const auto bad = dir.write("bad.csv", "pulses\n1\n2\nx\n");
  r = run_cli({"diagnose", bad.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.csv"), std::string::npos);
  EXPECT_NE(r.err.find(":4"), std::string::npos) << r.err;
  const auto rec = (dir.path() / "short.csv").string();
  ASSERT_EQ(run_cli({"simulate", "-o", rec, "--duration", "600", "--rate", "10", "--arw", "0.001"}).status, 0);
  r = run_cli({"diagnose", rec, "--runs", "10"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("1200 s"), std::string::npos) << r.err;
  r = run_cli({"diagnose", rec, "--runs", "3"});
  EXPECT_EQ(r.status, 2);
  r = run_cli({"diagnose", rec, "--plot", (dir.path() / "x.gif").string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("gif"), std::string::npos) << r.err;
  const auto out = dir.write("exists.txt", "keep");
  r = run_cli({"diagnose", rec, "-o", out.string()});
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(out), "keep");
}

// An output-chain low-pass (τf = 0.05 s) on a dithered read-out at 100 Hz: `simulate` writes the
// filtered angle, `diagnose --input angle` names `lowpass` with its time constant, and
// `simulate --from` carries it in the extended model; its interval holds the truth.
TEST(DiagnoseCliLowpass, OutputChainFilterIsNamedAndSimulatedBack) {
  TempDir dir;
  const auto rec = (dir.path() / "lp.csv").string();
  auto r = run_cli({"simulate", "-o", rec, "--duration", "1500", "--rate", "100", "--arw", "0.001",
                    "--bias-instability", "0.005", "--white-readout", "--output-lowpass", "0.05", "--seed", "4"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(rec).find("\nangle\n"), std::string::npos);
  const auto out = (dir.path() / "lp.json").string();
  r = run_cli({"diagnose", rec, "--input", "angle", "--json", "--runs", "10", "--seed", "3", "-o", out});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(slurp(out));
  const json* lp = nullptr;
  for (const auto& f : j["findings"])
    if (f["effect"] == "lowpass") lp = &f;
  ASSERT_NE(lp, nullptr) << j["findings"].dump();
  const auto& tc = (*lp)["parameters"]["time_constant"];
  EXPECT_NEAR(tc["value"].get<double>(), 0.05, 0.0125);
  EXPECT_EQ(tc["unit"], "s");
  EXPECT_GT(tc["standard_uncertainty"].get<double>(), 0.0);
  EXPECT_LT(tc["interval95"][0].get<double>(), 0.05);
  EXPECT_GT(tc["interval95"][1].get<double>(), 0.05);
  // The simulated rate spectrum is the first-order filter's: its deviance per bin is its mean.
  EXPECT_NEAR((*lp)["evidence"]["spectrum_dispersion"].get<double>(), 1.0, 0.15);
  EXPECT_NEAR(j["extended_model"]["output_lowpass_tc_s"].get<double>(), tc["value"].get<double>(), 1e-12);
  EXPECT_LT(j["gain"]["misfit_extended"].get<double>(), j["gain"]["misfit_base"].get<double>());
  EXPECT_GT(j["gain"]["likelihood_in_sample"].get<double>(), 0.0);
  EXPECT_GT(j["gain"]["likelihood_holdout"].get<double>(), 0.0);
  const auto again = (dir.path() / "again.csv").string();
  r = run_cli({"simulate", "--from", out, "-o", again, "--duration", "1200"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = slurp(again);
  EXPECT_NE(text.find("# output_lowpass_tc_s: "), std::string::npos);
  EXPECT_NE(text.find("\nangle\n"), std::string::npos);
}

// The base model names the read-out the record was counted with, also below one pulse per sample
// (0.34 pulses at 40 Hz), where a plain counter's σ(τ0) is as large as a dithered one's and only
// the fit's counter model tells them apart.
TEST(DiagnoseReadOut, BaseModelNamesTheReadOutBelowOnePulsePerSample) {
  TempDir dir;
  for (const bool white : {false, true}) {
    const auto f = (dir.path() / (white ? "white.csv" : "counting.csv")).string();
    std::vector<std::string> sim = {"simulate", "-o",     f,       "--duration", "1800",
                                    "--rate",   "40",     "--arw", "0.001",      "--bias-instability",
                                    "0.005",    "--seed", "11"};
    if (white) sim.emplace_back("--white-readout");
    ASSERT_EQ(run_cli(sim).status, 0);
    const auto r = run_cli({"diagnose", f, "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json::parse(r.out).at("base_model").at("readout"), white ? "white" : "counting") << f;
  }
}
