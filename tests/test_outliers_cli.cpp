// Outliers on every command that analyses a record (analyze, batch, report, allan; diagnose in
// test_outliers_diagnose_cli.cpp), end to end through the built executable: a short simulated pulse
// record with one 10^6-pulse spike is reported in each output — text, JSON, CSV, HTML — with its
// count, input line and the action taken, and --outliers keep|remove|replace is applied (the
// record analysed is one sample shorter after remove; keep and replace keep every sample).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "outliers_cli_fixture.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rwcalc::test::run_exe;
using rwcalc::test::slurp;
using rwcalc::test::SpikedRecord;
using rwcalc::test::TempDir;

namespace {

class OutliersCli : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() { rec_ = new SpikedRecord(300.0); }
  static void TearDownTestSuite() {
    delete rec_;
    rec_ = nullptr;
  }
  static SpikedRecord* rec_;
  /// The outlier object must name the one spike, at its input line, with the requested action.
  static void expect_spike(const json& o, const std::string& action) {
    ASSERT_TRUE(o.is_object()) << "no outlier summary";
    EXPECT_EQ(o.at("count"), 1) << o.dump();
    EXPECT_EQ(o.at("action"), action);
    ASSERT_FALSE(o.at("positions").empty());
    EXPECT_EQ(o.at("positions")[0].at("line"), rec_->spike_line);
    EXPECT_EQ(o.at("removed"), action == "remove" ? 1 : 0);
    EXPECT_EQ(o.at("replaced"), action == "replace" ? 1 : 0);
  }
  /// The readable form: the count, the action's word and the line.
  static void expect_spike_text(const std::string& text, const std::string& action) {
    const std::string word = action == "keep" ? "KEPT" : action == "remove" ? "REMOVED" : "REPLACED";
    EXPECT_NE(text.find("1 found; "), std::string::npos) << text;
    EXPECT_NE(text.find(word), std::string::npos) << text;
    EXPECT_NE(text.find(" " + std::to_string(rec_->spike_line) + " "), std::string::npos) << text;
  }
  std::size_t expected_samples() const { return rec_->samples - (GetParam() == "remove" ? 1 : 0); }
};
SpikedRecord* OutliersCli::rec_ = nullptr;

}  // namespace

TEST_P(OutliersCli, AnalyzeReportsAndAppliesTheAction) {
  const std::string action = GetParam();
  auto r = run_exe({"analyze", rec_->spiked, "--json", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  expect_spike(j.at("outliers"), action);
  EXPECT_EQ(j.at("samples"), expected_samples());
  r = run_exe({"analyze", rec_->spiked, "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_spike_text(r.out, action);
}

TEST_P(OutliersCli, BatchReportsEachRunInTextJsonCsvAndMarkdown) {
  const std::string action = GetParam();
  auto r = run_exe({"batch", rec_->spiked, rec_->clean, "--json", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j.at("runs").size(), 2u);
  for (const auto& run : j.at("runs")) {
    if (run.at("source") == rec_->spiked) {
      expect_spike(run.at("outliers"), action);
      EXPECT_EQ(run.at("samples"), expected_samples());
    } else {
      EXPECT_EQ(run.at("outliers").at("count"), 0) << run.at("outliers").dump();
    }
  }
  const std::string done = action == "keep" ? "kept" : action == "remove" ? "removed" : "replaced";
  const std::string spiked_line = rec_->spiked + ": 1 outlier(s) " + done;
  r = run_exe({"batch", rec_->spiked, rec_->clean, "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(spiked_line), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line " + std::to_string(rec_->spike_line)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(rec_->clean + ": none found"), std::string::npos) << r.out;
  r = run_exe({"batch", rec_->spiked, "--markdown", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(spiked_line), std::string::npos) << r.out;
  r = run_exe({"batch", rec_->spiked, "--csv", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(",outliers,outlier_action\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(",1," + action + "\n"), std::string::npos) << r.out;
}

TEST_P(OutliersCli, ReportShowsTheOutliersOfRecordingsAndOfSavedResults) {
  const std::string action = GetParam();
  TempDir tmp;
  const auto check_html = [&](const fs::path& dir) {
    const std::string html = slurp(dir / "report.html");
    const auto row = html.find("id=\"run1-outliers\"");
    ASSERT_NE(row, std::string::npos) << "no outlier row in the report";
    const std::string line = html.substr(row, html.find("</tr>", row) - row);
    EXPECT_NE(line.find("1 found"), std::string::npos) << line;
    EXPECT_NE(line.find("line " + std::to_string(rec_->spike_line)), std::string::npos) << line;
    const std::string word = action == "keep" ? "kept" : action == "remove" ? "removed" : "replaced";
    EXPECT_NE(line.find(word), std::string::npos) << line;
  };
  auto r = run_exe({"report", rec_->spiked, "-o", (tmp.path() / "rec").string(), "--no-figures", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  check_html(tmp.path() / "rec");
  // The settings name the action in words (its option value is "keep", "remove" or "replace").
  const std::string action_words = action == "keep"     ? "kept in the analysis"
                                   : action == "remove" ? "removed"
                                                        : "replaced by the median of their neighbours";
  EXPECT_NE(slurp(tmp.path() / "rec" / "report.html").find("<tr><th>outliers</th><td>" + action_words + "</td></tr>"),
            std::string::npos)
      << "the settings table does not name the outlier action";
  // The same from the saved analysis JSON, which carries the outlier summary.
  r = run_exe({"analyze", rec_->spiked, "--json", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto saved = tmp.write("saved.json", r.out);
  r = run_exe({"report", saved.string(), "-o", (tmp.path() / "saved").string(), "--no-figures"});
  ASSERT_EQ(r.status, 0) << r.err;
  check_html(tmp.path() / "saved");
  // Saved results without an outlier summary (older or hand-made JSON) say so, never "none".
  json stripped = json::parse(slurp(saved));
  stripped.erase("outliers");
  const auto bare = tmp.write("bare.json", stripped.dump());
  r = run_exe({"report", bare.string(), "-o", (tmp.path() / "bare").string(), "--no-figures"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(tmp.path() / "bare" / "report.html").find("not in these results"), std::string::npos);
}

TEST_P(OutliersCli, AllanReportsAndAppliesTheAction) {
  const std::string action = GetParam();
  auto r = run_exe({"allan", rec_->spiked, "--json", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  expect_spike(j.at("outliers"), action);
  EXPECT_EQ(j.at("samples"), expected_samples());
  r = run_exe({"allan", rec_->spiked, "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_spike_text(r.out, action);
  r = run_exe({"allan", rec_->spiked, "--csv", "--outliers", action});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_spike_text(r.err, action);  // the CSV stays a table; the note goes to standard error
}

INSTANTIATE_TEST_SUITE_P(Actions, OutliersCli, ::testing::Values("keep", "remove", "replace"));

// The spike changes the data that every action analyses: kept, it raises the short-τ Allan
// deviation far above the clean record's; removed or replaced, the deviation is the clean one's.
TEST(OutliersCliEffect, AllanDeviationWithTheSpikeRemovedIsTheCleanOne) {
  const SpikedRecord rec(300.0);
  auto dev_at_first_tau = [&](const std::string& file, const std::string& action) {
    const auto r = run_exe({"allan", file, "--json", "--outliers", action});
    EXPECT_EQ(r.status, 0) << r.err;
    return json::parse(r.out).at("points")[0].at("dev").get<double>();
  };
  const double clean = dev_at_first_tau(rec.clean, "keep");
  EXPECT_GT(dev_at_first_tau(rec.spiked, "keep"), 10 * clean);
  EXPECT_NEAR(dev_at_first_tau(rec.spiked, "remove"), clean, 0.01 * clean);
  EXPECT_NEAR(dev_at_first_tau(rec.spiked, "replace"), clean, 0.01 * clean);
}
