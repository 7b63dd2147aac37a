// No class verdict from a rejected fit: records the noise model cannot describe (a square wave in
// the rate, a plain counter's read-out, the full-range fit of an ADIS16405 axis) give no class and
// no probability in analyze's JSON and text, batch's rows, overall line and CSV, merge, and the
// report; and over any record, a rejected fit (p < 0.001) and a withheld verdict go together.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace rwcalc {
namespace {

using nlohmann::json;
using namespace rwcalc::test;

/// 40 min at 100 Hz of a rate in °/h: white noise plus a ±50 °/h square wave of period 60 s. Its
/// Allan variance has the square wave's bump and ripples, which no sum of the five terms follows.
std::string square_wave_record(const TempDir& dir) {
  const std::string path = (dir.path() / "square.csv").string();
  std::ofstream out(path);
  out << "rate_deg_h\n";
  std::mt19937_64 gen(7);
  std::normal_distribution<double> white(0.0, 100.0);
  for (int i = 0; i < 240000; ++i) {
    const double t = i / 100.0;
    out << ((static_cast<long>(t / 30.0) % 2 == 0) ? 50.0 : -50.0) + white(gen) << "\n";
  }
  return path;
}

std::vector<std::string> square_args(const std::string& path) {
  return {path, "--input", "rate", "--rate-unit", "deg/h", "--rate", "100", "--vertical"};
}

/// A record from `simulate` (400 Hz); `extra` adds options (e.g. --white-readout).
std::string simulated(const TempDir& dir, const std::string& name, std::vector<std::string> extra) {
  const std::string path = (dir.path() / name).string();
  std::vector<std::string> args = {"simulate",           "-o",    path,     "--duration", "1200", "--arw", "0.0009",
                                   "--bias-instability", "0.006", "--seed", "3"};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = run_cli(args);
  EXPECT_EQ(r.status, 0) << r.err;
  return path;
}

/// The property: a verdict from a rejected fit is withheld (no class, no probability, the reason
/// and the command, a no_verdict warning first), and one from an accepted fit is given.
void expect_verdict_follows_the_fit(const json& j, const std::string& what) {
  const json& v = j.at("verdict");
  const bool rejected = j.at("fit").at("p_value").get<double>() < 0.001;
  EXPECT_EQ(v.value("withheld", false), rejected) << what;
  if (!rejected) {
    EXPECT_TRUE(v.at("p_class").is_number()) << what;
    return;
  }
  for (const char* k : {"class", "class_B", "class_N", "class_strict", "p_class", "p_class_B", "p_class_N", "p_is"})
    EXPECT_TRUE(v.at(k).is_null()) << what << ": " << k;
  for (const char* k : {"B", "N"}) {
    EXPECT_TRUE(v.at(k).at("class").is_null()) << what << ": " << k;
    EXPECT_TRUE(v.at(k).at("p_class").is_null()) << what << ": " << k;
  }
  EXPECT_EQ(v.at("statement"), "no verdict: the noise model does not describe this record") << what;
  EXPECT_NE(v.at("reason").get<std::string>().find("chi2/dof"), std::string::npos) << what;
  EXPECT_EQ(v.at("command").get<std::string>().rfind("rwcalc diagnose ", 0), 0u) << what;
  ASSERT_FALSE(j.at("warnings").empty()) << what;
  EXPECT_EQ(j.at("warnings").front().at("code"), "no_verdict") << what;
}

json analyze_json(const std::vector<std::string>& args) {
  std::vector<std::string> a = {"analyze"};
  a.insert(a.end(), args.begin(), args.end());
  a.push_back("--json");
  const auto r = run_cli(a);
  EXPECT_EQ(r.status, 0) << r.err;
  return json::parse(r.out);
}

TEST(NoVerdict, SquareWaveIsRejectedAndGetsNoClass) {
  TempDir dir;
  const json j = analyze_json(square_args(square_wave_record(dir)));
  EXPECT_LT(j["fit"]["p_value"].get<double>(), 1e-6);  // the misfit stays rejected whatever term is added
  expect_verdict_follows_the_fit(j, "square wave");
}

TEST(NoVerdict, ARejectedFitAndAWithheldVerdictGoTogether) {
  TempDir dir;
  // The simulator's default read-out (a plain counter), the dithered one, and a user's full range.
  const std::string counter = simulated(dir, "counter.csv.gz", {});
  const std::string dithered = simulated(dir, "dithered.csv.gz", {"--white-readout"});
  const json d = analyze_json({dithered});
  EXPECT_GE(d["fit"]["p_value"].get<double>(), 0.001);  // the other branch of the property is exercised
  expect_verdict_follows_the_fit(d, "dithered counter");
  expect_verdict_follows_the_fit(analyze_json({counter}), "plain counter");
  expect_verdict_follows_the_fit(analyze_json({counter, "--b-estimate", "sigma-min"}), "plain counter, sigma-min");
}

TEST(NoVerdict, TextSaysSoAtTheTopAndInTheVerdict) {
  TempDir dir;
  std::vector<std::string> args = {"analyze"};
  const auto sq = square_args(square_wave_record(dir));
  args.insert(args.end(), sq.begin(), sq.end());
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("WARNINGS\n  [no_verdict] No class verdict: the fit is rejected"), r.out.find("WARNINGS"))
      << r.out.substr(0, 800);
  const auto verdict = r.out.find("\nVerdict (");
  ASSERT_NE(verdict, std::string::npos);
  const std::string tail = r.out.substr(verdict);
  EXPECT_NE(tail.find("no verdict: the noise model does not describe this record"), std::string::npos) << tail;
  EXPECT_NE(tail.find("next: rwcalc diagnose"), std::string::npos) << tail;
  EXPECT_EQ(tail.find("P="), std::string::npos) << tail;
  args.insert(args.end(), {"--lang", "ru"});
  const auto ru = run_cli(args);
  ASSERT_EQ(ru.status, 0) << ru.err;
  EXPECT_NE(ru.out.find("заключения нет: модель шумов не описывает эту запись"), std::string::npos);
}

TEST(NoVerdict, BatchMergeAndReportGiveNoOverallClass) {
  TempDir dir;
  const std::string square = square_wave_record(dir);
  const std::string dithered = simulated(dir, "dithered.csv.gz", {"--white-readout"});
  // Two runs through batch: the square wave's row and the overall line say "no verdict".
  const auto jsonl = (dir.path() / "runs.jsonl").string();
  for (const auto& [file, out] : {std::pair{square, "a.json"}, std::pair{dithered, "b.json"}}) {
    std::vector<std::string> a = {"analyze"};
    const auto args = file == square ? square_args(square) : std::vector<std::string>{dithered, "--vertical"};
    a.insert(a.end(), args.begin(), args.end());
    a.insert(a.end(), {"--json", "-o", (dir.path() / out).string()});
    ASSERT_EQ(run_cli(a).status, 0);
  }
  {
    std::ofstream lines(jsonl);
    for (const char* f : {"a.json", "b.json"}) lines << json::parse(slurp(dir.path() / f)).dump() << "\n";
  }
  const auto m = run_cli({"merge", jsonl, "--json"});
  ASSERT_EQ(m.status, 0) << m.err;
  const json summary = json::parse(m.out);
  const json& ov = summary.at("overall");
  EXPECT_TRUE(ov.value("withheld", false)) << ov.dump();
  EXPECT_TRUE(ov.at("class").is_null());
  EXPECT_TRUE(ov.at("p_class").is_null());
  EXPECT_EQ(ov.at("runs_withheld").size(), 1u);
  const auto text = run_cli({"merge", jsonl});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("Overall over the runs: no verdict: the fit of 1 of 2 run(s) is rejected"), std::string::npos)
      << text.out;
  const auto csv = run_cli({"merge", jsonl, "--csv"});
  ASSERT_EQ(csv.status, 0) << csv.err;
  EXPECT_NE(csv.out.find("\noverall,,,,,,,,,,,,,,,,,\n"), std::string::npos) << csv.out;  // no class, no P
  const auto out = dir.path() / "report";
  const auto rep = run_cli({"report", (dir.path() / "a.json").string(), (dir.path() / "b.json").string(), "-o",
                            out.string(), "--no-figures"});
  ASSERT_EQ(rep.status, 0) << rep.err;
  const std::string html = slurp(out / "report.html");
  const auto verdict = html.find("<p class=\"verdict\">");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_EQ(html.substr(verdict, 200).rfind("<p class=\"verdict\"><b>No verdict</b> over", 0), 0u)
      << html.substr(verdict, 200);
  EXPECT_NE(html.find("run next: <code>rwcalc diagnose"), std::string::npos);
}

TEST(NoVerdict, RejectedAdisAxisWithVertical) {
  const auto path = shared_data("real/imudata_adis16405/adis_16405_imu1.csv.gz");
  RWCALC_REQUIRE_SHARED(path);
  // The Z gyro over every octave point (its 20-Hz line and the filter in the fit): rejected
  // (docs/adis16405.md), so --vertical, which asks for the class verdict, gets none.
  const json j = analyze_json({path.string(), "--input", "rate", "--rate-unit", "deg/s", "--rate", "100", "--column",
                               "gyro_z_dps", "--vertical", "--fit-range", "0:"});
  EXPECT_LT(j["fit"]["p_value"].get<double>(), 0.001);
  expect_verdict_follows_the_fit(j, "ADIS run 1 Z, full range");
  EXPECT_NE(j["verdict"]["reason"].get<std::string>().find("--fit-range"), std::string::npos);
}

}  // namespace
}  // namespace rwcalc
