// `rwcalc diagnose` with an outlier, end to end through the built executable: a 22-min simulated
// pulse record with one 10^6-pulse spike. The diagnosis reports the spike (count, input line,
// action) in its JSON and text; with --outliers remove or replace the action is applied before the
// diagnosis, so N is the clean record's and no bias step is named; with keep the spike is
// reported as kept (and dominates N). RWCALC_DIAGNOSE_CASES=K checks the first K of the actions
// remove, replace, keep (default all three).
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "outliers_cli_fixture.hpp"
#include "test_support.hpp"

using nlohmann::json;
using rwcalc::test::run_exe;
using rwcalc::test::SpikedRecord;

namespace {

std::size_t cases(std::size_t dflt) {
  if (const char* s = std::getenv("RWCALC_DIAGNOSE_CASES")) return static_cast<std::size_t>(std::atoi(s));
  return dflt;
}

json diagnose_json(const std::string& file, const std::string& action) {
  const auto r = run_exe({"diagnose", file, "--json", "--runs", "10", "--seed", "5", "--outliers", action});
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? json::parse(r.out) : json::object();
}

/// N of the base model the diagnosis simulates (the text's "Base model: N = …"). Not the raw
/// five-term fit's N, which on 22 min of pulse counts fitted from τ = 20 s is poorly determined
/// (a one-sample splice can move it to 0), whatever the outliers.
double base_n(const json& d) { return d.at("base_model").at("arw_deg_per_sqrt_h").get<double>(); }

bool names_effect(const json& d, const std::string& effect) {
  for (const auto& f : d.at("findings"))
    if (f.at("effect") == effect) return true;
  return false;
}

}  // namespace

TEST(DiagnoseOutliers, SpikeIsReportedAndTheActionAppliedBeforeTheDiagnosis) {
  const SpikedRecord rec(1320.0);  // the diagnosis needs at least 1200 s
  const json clean = diagnose_json(rec.clean, "keep");
  ASSERT_TRUE(clean.contains("outliers"));
  EXPECT_EQ(clean.at("outliers").at("count"), 0);
  const double n_clean = base_n(clean);

  const std::vector<std::string> actions{"remove", "replace", "keep"};
  for (std::size_t k = 0; k < actions.size() && k < cases(actions.size()); ++k) {
    const std::string& action = actions[k];
    SCOPED_TRACE("--outliers " + action);
    const json d = diagnose_json(rec.spiked, action);
    ASSERT_TRUE(d.contains("outliers")) << "the diagnosis does not report outliers";
    const json& o = d.at("outliers");
    EXPECT_EQ(o.at("count"), 1) << o.dump();
    EXPECT_EQ(o.at("action"), action);
    ASSERT_FALSE(o.at("positions").empty());
    EXPECT_EQ(o.at("positions")[0].at("line"), rec.spike_line);
    if (action == "keep") {
      EXPECT_GT(base_n(d), 10 * n_clean) << "the kept spike should dominate N";
    } else {
      EXPECT_NEAR(base_n(d), n_clean, 0.1 * n_clean);
      EXPECT_FALSE(names_effect(d, "bias_step")) << d.at("findings").dump();
      EXPECT_EQ(d.at("samples"), rec.samples - (action == "remove" ? 1 : 0));
    }
  }

  // The readable report says it too: count, action and line.
  const auto r = run_exe({"diagnose", rec.spiked, "--runs", "10", "--seed", "5", "--outliers", "replace"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 found; 1 REPLACED"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" " + std::to_string(rec.spike_line) + " "), std::string::npos) << r.out;
}

// `rwcalc report --diagnose` shows the outliers of the diagnosed record above its diagnosis.
TEST(DiagnoseOutliers, ReportDiagnosisSectionNamesTheOutliers) {
  const SpikedRecord rec(1320.0);
  rwcalc::test::TempDir tmp;
  const auto dir = tmp.path() / "report";
  const auto r = run_exe({"report", rec.spiked, "-o", dir.string(), "--no-figures", "--diagnose", "--diagnose-runs",
                          "10", "--outliers", "remove"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string html = rwcalc::test::slurp(dir / "report.html");
  const auto at = html.find("id=\"run1-diagnosis-outliers\"");
  ASSERT_NE(at, std::string::npos) << "no outlier line in the diagnosis section";
  const std::string line = html.substr(at, html.find("</p>", at) - at);
  EXPECT_NE(line.find("1 found"), std::string::npos) << line;
  EXPECT_NE(line.find("removed"), std::string::npos) << line;
  EXPECT_NE(line.find("line " + std::to_string(rec.spike_line)), std::string::npos) << line;
}
