// End-to-end tests of 'rwcalc analyze', 'rwcalc batch' and 'rwcalc merge' on the shipped GL-2D runs.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rwcalc/analysis.hpp"
#include "rwcalc/batch.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

using nlohmann::json;
using test::run_cli;

std::string gl2d(const std::string& name) { return test::source_path("data/gl2d/" + name).string(); }

json truth(const std::string& run) {
  std::ifstream in(gl2d(run + ".truth.json"));
  return json::parse(in);
}

// The passes of an analysis (Allan sums, fit, outlier scan) give the same bits whatever the number
// of threads: a simulated hour with an outlier, analysed with RWCALC_THREADS=1 and =2.
TEST(Analyze, ThreadCountDoesNotChangeTheResult) {
  Recording rec = test::gl2d_hour(77);
  for (std::size_t i = 123456; i < rec.phase.counts.size(); ++i) rec.phase.counts[i] += 90;  // one outlier
  auto analysed = [&](const char* threads) {
    const test::ScopedEnv env("RWCALC_THREADS", threads);
    return to_json(analyze(rec, {})).dump();
  };
  const std::string one = analysed("1");
  EXPECT_EQ(one, analysed("2"));
  EXPECT_GE(json::parse(one).at("outliers").at("count").get<int>(), 1);
}

TEST(TemperatureFromName, Patterns) {
  EXPECT_EQ(temperature_from_name("data/gl2d_m50C.csv.gz"), -50.0);
  EXPECT_EQ(temperature_from_name("run-50C.csv"), -50.0);
  EXPECT_EQ(temperature_from_name("gyro_p25C.csv"), 25.0);
  EXPECT_EQ(temperature_from_name("gyro_+25C.txt"), 25.0);
  EXPECT_EQ(temperature_from_name("gyro_0C.csv"), 0.0);
  EXPECT_EQ(temperature_from_name("/x/m12C/run_12.5C.csv"), 12.5);
  EXPECT_FALSE(temperature_from_name("gl2d_run.csv").has_value());
  EXPECT_FALSE(temperature_from_name("ABC.csv").has_value());
  EXPECT_FALSE(temperature_from_name("x25Cy.csv").has_value());
}

TEST(EarthRate, MoscowIs12p43) { EXPECT_NEAR(vertical_earth_rate(55.75), 12.433, 1e-3); }

TEST(AnalyzeCli, JsonHasTheIssueKeysAndCoversTheTruth) {
  const auto r = run_cli({"analyze", gl2d("gl2d_p25C.csv.gz"), "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("nan"), std::string::npos);
  const json j = json::parse(r.out);
  EXPECT_EQ(j["samples"], 2880000);
  EXPECT_EQ(j["rate_hz"], 400.0);
  EXPECT_NEAR(j["duration_s"].get<double>(), 7200.0, 1e-9);
  EXPECT_EQ(j["temperature_c"], 25.0);
  EXPECT_NEAR(j["earth_rate"].get<double>(), 12.433, 1e-3);
  // The simulated run senses exactly the Earth rate: the bias is within the noise of a 2-h mean.
  EXPECT_NEAR(j["mean_rate"].get<double>(), 12.433, 0.01);
  for (const char* k : {"Q", "N", "B", "K", "R"})
    for (const char* f : {"value", "sigma", "low95", "high95", "resolved"})
      EXPECT_TRUE(j["fit"][k].contains(f)) << k << f;
  EXPECT_TRUE(j["fit"].contains("chi2_per_dof"));
  EXPECT_TRUE(j["methods"]["N_direct"].contains("value"));
  EXPECT_TRUE(j["methods"]["B_100s"].contains("value"));
  for (const char* k : {"class_B", "class_N", "class", "p_class"}) EXPECT_TRUE(j["verdict"].contains(k)) << k;
  EXPECT_GT(j["allan"]["points"].size(), 15u);
  // Truth of the run's N inside the reported interval; Q (q/√6 for the white read-out) too.
  const json t = truth("gl2d_p25C");
  const double n = t["model"]["arw_deg_per_sqrt_h"];
  EXPECT_LE(j["fit"]["N"]["low95"].get<double>(), n);
  EXPECT_GE(j["fit"]["N"]["high95"].get<double>(), n);
  EXPECT_NEAR(j["fit"]["Q"]["value"].get<double>() / t["quantization_q_arcsec"].get<double>(), 1.0, 0.02);
  // K and R are absent in the truth: reported as upper bounds.
  EXPECT_FALSE(j["fit"]["R"]["resolved"].get<bool>());
}

TEST(AnalyzeCli, ReportStatesUnitsConventionsAndVerdict) {
  const auto r = run_cli({"analyze", gl2d("gl2d_m25C.csv.gz"), "--earth-rate", "12.0", "--b-estimate", "sigma-min"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"°/√h", "°/h", "arcsec", "√3·Q", "Verdict", "B from the minimum of the Allan deviation",
                        "N direct", "expected vertical Earth rate 12.0000 °/h (given)"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  EXPECT_EQ(r.out.find("nan"), std::string::npos);
}

TEST(AnalyzeCli, ErrorPaths) {
  test::TempDir dir;
  std::string flat = "# rate_hz: 400\npulses\n";
  for (int i = 0; i < 4000; ++i) flat += "1\n";
  const auto c = run_cli({"analyze", dir.write("const.csv", flat).string()});
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.err.find("no noise"), std::string::npos);
  std::string tiny = "pulses\n";
  for (int i = 0; i < 40; ++i) tiny += std::to_string(i % 3) + "\n";
  const auto s = run_cli({"analyze", dir.write("short.csv", tiny).string()});
  EXPECT_EQ(s.status, 1);
  EXPECT_NE(s.err.find("fit range"), std::string::npos);
  const auto narrow = run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--fit-range", "100:300"});
  EXPECT_EQ(narrow.status, 1);
  EXPECT_EQ(run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--fit-range", "300:100"}).status, 2);
  EXPECT_EQ(run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--terms", "QNX"}).status, 2);
  EXPECT_EQ(run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--b-estimate", "median"}).status, 2);
  EXPECT_EQ(run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--limits", (dir.path() / "none.json").string()}).status, 2);
  for (const auto* r : {&c, &s, &narrow}) EXPECT_EQ(r->out.find("nan"), std::string::npos);
}

TEST(AnalyzeCli, LimitsFileChangesTheVerdict) {
  test::TempDir dir;
  const auto lim = dir.write("lax.json", R"({"name": "lax", "classes": [
      {"class": 1, "B_deg_per_h": 1.0, "N_deg_per_sqrt_h": 1.0}]})");
  const auto r = run_cli({"analyze", gl2d("gl2d_0C.csv.gz"), "--json", "--limits", lim.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["verdict"]["class"], 1);
  EXPECT_GT(j["verdict"]["p_class"].get<double>(), 0.999);
}

TEST(AnalyzeCli, DenseGridIsReportedButTheFitKeepsTheOctavePoints) {
  const auto oct = run_cli({"analyze", gl2d("gl2d_p50C.csv.gz"), "--json"});
  const auto dense = run_cli({"analyze", gl2d("gl2d_p50C.csv.gz"), "--json", "--tau", "dense"});
  ASSERT_EQ(oct.status, 0) << oct.err;
  ASSERT_EQ(dense.status, 0) << dense.err;
  const json a = json::parse(oct.out), b = json::parse(dense.out);
  // Same coefficients, cross-checks and verdict, bit for bit.
  for (const char* k : {"fit", "slope_readout", "methods", "verdict"}) EXPECT_EQ(a[k], b[k]) << k;
  // Every octave point is there with the same numbers; the dense points lie between them, at
  // least 15 per decade up to N/10 (beyond it only the octave points continue).
  const auto& pa = a["allan"]["points"];
  const auto& pb = b["allan"]["points"];
  const auto n = pb.size();
  ASSERT_GT(n, pa.size() + 80);
  std::size_t found = 0, beyond = 0;
  const auto points = b["allan"]["points_in"].get<std::int64_t>();
  for (const auto& p : pb) {
    const auto m = p["m"].get<std::int64_t>();
    if (m > points / 10) {
      ++beyond;
      EXPECT_EQ(m & (m - 1), 0) << "beyond N/10 only octave points, got m = " << m;
    }
    for (const auto& q : pa)
      if (q["m"] == p["m"]) {
        EXPECT_EQ(q, p);
        ++found;
      }
  }
  EXPECT_EQ(found, pa.size());
  EXPECT_GE(beyond, 1u);
  for (std::size_t i = 1; i < n; ++i) EXPECT_LT(pb[i - 1]["m"].get<std::int64_t>(), pb[i]["m"].get<std::int64_t>());
  EXPECT_EQ(run_cli({"analyze", gl2d("gl2d_p50C.csv.gz"), "--tau", "dense:0"}).status, 2);
  // A grid whose longest τ is not an octave point: the fit's last point still carries the
  // previous octave α, as on the octave grid.
  const auto dec = run_cli({"analyze", gl2d("gl2d_p50C.csv.gz"), "--json", "--tau", "decade"});
  ASSERT_EQ(dec.status, 0) << dec.err;
  const json c = json::parse(dec.out);
  for (const char* k : {"fit", "slope_readout", "verdict"}) EXPECT_EQ(a[k], c[k]) << k;
}

class BatchCli : public ::testing::Test {
 protected:
  static std::vector<std::string> files() {
    return {gl2d("gl2d_p50C.csv.gz"), gl2d("gl2d_m50C.csv.gz"), gl2d("gl2d_0C.csv.gz"), gl2d("gl2d_p25C.csv.gz"),
            gl2d("gl2d_m25C.csv.gz")};
  }
};

TEST_F(BatchCli, JsonLinesMergeToTheSameTablesAndTheToleranceGivesClass2) {
  test::TempDir dir;
  std::vector<std::string> args{"batch"};
  for (const auto& f : files()) args.push_back(f);
  args.insert(args.end(), {"--tolerance", "50", "--jsonl", "-o", (dir.path() / "runs.jsonl").string()});
  const auto b = run_cli(args);
  ASSERT_EQ(b.status, 0) << b.err;
  // One JSON line per run.
  std::ifstream in(dir.path() / "runs.jsonl");
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    EXPECT_TRUE(json::parse(line).contains("verdict"));
  }
  EXPECT_EQ(lines, 5);

  const auto m = run_cli({"merge", (dir.path() / "runs.jsonl").string(), "--json"});
  ASSERT_EQ(m.status, 0) << m.err;
  const json s = json::parse(m.out);
  ASSERT_EQ(s["runs"].size(), 5u);
  double last = -1e9;
  for (const auto& r : s["runs"]) {
    EXPECT_GE(r["temperature_c"].get<double>(), last);  // sorted by temperature
    last = r["temperature_c"].get<double>();
  }
  for (const char* k : {"class_B", "class_N", "class"}) EXPECT_TRUE(s["overall"].contains(k));
  // The paper's rule: with +50 % on B the overall class is 2, and marked as a tolerance verdict.
  EXPECT_EQ(s["overall"]["class"], 2);
  EXPECT_TRUE(s["overall"]["tolerance_changed"].get<bool>());
  EXPECT_NE(s["overall"]["statement"].get<std::string>().find("class 2"), std::string::npos);

  // The same analysis through 'batch' directly prints the same table as 'merge'.
  std::vector<std::string> direct{"batch"};
  for (const auto& f : files()) direct.push_back(f);
  direct.insert(direct.end(), {"--tolerance", "50", "--markdown"});
  const auto d = run_cli(direct);
  ASSERT_EQ(d.status, 0) << d.err;
  const auto md = run_cli({"merge", (dir.path() / "runs.jsonl").string(), "--markdown"});
  EXPECT_EQ(d.out, md.out);
  const auto csv = run_cli({"merge", (dir.path() / "runs.jsonl").string(), "--csv"});
  EXPECT_EQ(std::count(csv.out.begin(), csv.out.end(), '\n'), 7);  // header, 5 runs, overall
}

TEST_F(BatchCli, ThreadCountDoesNotChangeTheResult) {
  // One thread runs the files one after the other; two, three and four run several at once and
  // finish them in another order: every schedule gives the same bytes, in input order.
  std::vector<std::string> args{"batch"};
  for (const auto& f : files()) args.push_back(f);
  args.push_back("--json");
  auto run_with = [&](const char* threads) {
    const test::ScopedEnv env("RWCALC_THREADS", threads);
    return run_cli(args);
  };
  const auto r1 = run_with("1");
  ASSERT_EQ(r1.status, 0) << r1.err;
  for (const char* threads : {"2", "3", "4"}) {
    const auto r = run_with(threads);
    ASSERT_EQ(r.status, 0) << "RWCALC_THREADS=" << threads << ": " << r.err;
    EXPECT_EQ(r1.out, r.out) << "RWCALC_THREADS=" << threads;
  }
}

TEST_F(BatchCli, AnInputErrorInTheLastFilesNamesItsFile) {
  // Three files on two threads: the bad one is the last, read while the others are analysed.
  test::TempDir dir;
  const auto bad = dir.write("broken_p10C.csv", "# rate_hz: 400\npulses\n1\n2\nthree\n4\n");
  const test::ScopedEnv env("RWCALC_THREADS", "2");
  const auto r = run_cli({"batch", gl2d("gl2d_0C.csv.gz"), gl2d("gl2d_p25C.csv.gz"), bad.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("broken_p10C.csv:5"), std::string::npos) << r.err;
}

TEST_F(BatchCli, MergeErrors) {
  test::TempDir dir;
  const auto bad = dir.write("bad.jsonl", "{\"a\": 1}\n");
  const auto r = run_cli({"merge", bad.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.jsonl:1"), std::string::npos);
  const auto garbage = dir.write("g.jsonl", "\n\nnot json\n");
  const auto g = run_cli({"merge", garbage.string()});
  EXPECT_EQ(g.status, 2);
  EXPECT_NE(g.err.find("g.jsonl:3"), std::string::npos);
  EXPECT_EQ(run_cli({"batch", gl2d("gl2d_0C.csv.gz"), "--json", "--csv"}).status, 2);
  EXPECT_EQ(run_cli({"batch", gl2d("gl2d_0C.csv.gz"), gl2d("gl2d_p25C.csv.gz"), "--temperature", "20"}).status, 2);
}

}  // namespace
}  // namespace rwcalc
