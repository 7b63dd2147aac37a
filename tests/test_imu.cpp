// Accelerometer channels and `rwcalc imu`: accelerometer units by option or column suffix, the
// channel's results in the units asked for and in SI, every axis of a recording in one command,
// and the Kalibr/OpenVINS noise file.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>

#include "test_support.hpp"

namespace rwcalc::test {
namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

constexpr double kG = 9.80665;
constexpr double kRateHz = 100;
constexpr int kSamples = 60000;  // 600 s
// Per-sample standard deviations of the white noise written: gyro °/s, accelerometer g.
constexpr double kGyroSd = 0.05, kAccelSd = 0.002;

// A static 6-axis IMU of white noise: gyro in °/s (mean 0.1 °/s), accelerometer in g (z at −1 g).
std::string imu_csv(const std::string& header) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z;
  std::string s = header + "\n";
  for (int k = 0; k < kSamples; ++k)
    s += fmt::format("{:.6f},{:.6f},{:.6f},{:.7f},{:.7f},{:.7f}\n", 0.1 + kGyroSd * z(rng), 0.1 + kGyroSd * z(rng),
                     0.1 + kGyroSd * z(rng), kAccelSd * z(rng), kAccelSd * z(rng), -1 + kAccelSd * z(rng));
  return s;
}

const char* kHeader = "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_g,acc_y_g,acc_z_g";

// The white level's N in SI: the per-sample deviation over √(sample rate).
double gyro_n_si() { return kGyroSd * std::numbers::pi / 180 / std::sqrt(kRateHz); }
double accel_n_si() { return kAccelSd * kG / std::sqrt(kRateHz); }

nlohmann::json parse_ok(const CliResult& r) {
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
}

TEST(Imu, GSuffixMeansAnAccelerometerInG) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto r = run_cli({"analyze", f.string(), "--column", "acc_z_g", "--rate", "100", "--json"});
  const auto j = parse_ok(r);
  EXPECT_EQ(j["sensor"], "accelerometer");
  EXPECT_EQ(j["input"]["unit"], "g");
  EXPECT_EQ(j["input"]["kind"], "rate");
  EXPECT_NEAR(j["mean_rate"].get<double>(), -1e6, 2e3);  // −1 g in µg; 1/3600 or 9.8× off if misread
  EXPECT_EQ(j["units"]["rate"], "ug");
  EXPECT_TRUE(j["verdict"].is_null());
  EXPECT_TRUE(has(r.err, "rate unit g from the column name 'acc_z_g'")) << r.err;
  const auto& n = j["fit"]["N"];
  EXPECT_EQ(n["meaning"], "velocity random walk");
  EXPECT_EQ(n["si"]["unit"], "m/s^2/sqrt(Hz)");
  EXPECT_NEAR(n["si"]["value"].get<double>() / accel_n_si(), 1.0, 0.05);
  // The text names the kind, the column and the units.
  const auto t = run_cli({"analyze", f.string(), "--column", "acc_z_g", "--rate", "100"});
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_TRUE(has(t.out, "rwcalc accelerometer:")) << t.out;
  EXPECT_TRUE(has(t.out, "velocity random walk")) << t.out;
  EXPECT_TRUE(has(t.out, "m/s/√h")) << t.out;
  EXPECT_TRUE(has(t.out, "no Earth rate, no class verdict (accelerometer)")) << t.out;
}

TEST(Imu, AccelerometerUnitsAgreeWithEachOther) {
  // The same channel written in g, mg, ug and m/s²: one noise density in SI.
  TempDir dir;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z;
  std::string s = "a_g,a_mg,a_ug,a_mps2\n";
  for (int k = 0; k < kSamples; ++k) {
    const double g = kAccelSd * z(rng);
    s += fmt::format("{:.9f},{:.6f},{:.3f},{:.8f}\n", g, g * 1e3, g * 1e6, g * kG);
  }
  const auto f = dir.write("acc.csv", s);
  std::vector<double> n;
  for (const char* c : {"a_g", "a_mg", "a_ug", "a_mps2"}) {
    const auto j = parse_ok(run_cli({"analyze", f.string(), "--column", c, "--rate", "100", "--json"}));
    n.push_back(j["fit"]["N"]["si"]["value"].get<double>());
  }
  for (double v : n) EXPECT_NEAR(v / n[0], 1.0, 1e-6);
  EXPECT_NEAR(n[0] / accel_n_si(), 1.0, 0.05);
}

TEST(Imu, AnAccelerometerUnitOptionThatContradictsTheNameIsUsedWithAWarning) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto r =
      run_cli({"analyze", f.string(), "--column", "acc_x_g", "--rate-unit", "mg", "--rate", "100", "--json"});
  const auto j = parse_ok(r);
  EXPECT_EQ(j["input"]["unit"], "mg");
  EXPECT_TRUE(has(r.err, "rwcalc: warning: ")) << r.err;
  EXPECT_TRUE(has(r.err, "says rate in g, but --rate-unit mg is used as given")) << r.err;
}

TEST(Imu, OutputUnitChoosesTheShownUnitsOfEitherKind) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto g = parse_ok(
      run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100", "--json", "--output-unit", "deg/s"}));
  EXPECT_EQ(g["fit"]["N"]["unit"], "deg/s/sqrt(Hz)");
  EXPECT_NEAR(g["fit"]["N"]["value"].get<double>() / (kGyroSd / std::sqrt(kRateHz)), 1.0, 0.05);
  EXPECT_NEAR(g["mean_rate"].get<double>(), 0.1, 1e-3);
  const auto a = parse_ok(
      run_cli({"analyze", f.string(), "--column", "acc_z_g", "--rate", "100", "--json", "--output-unit", "mg"}));
  EXPECT_EQ(a["fit"]["B"]["unit"], "mg");
  EXPECT_NEAR(a["mean_rate"].get<double>(), -1000.0, 2.0);
  // imu: one unit per kind, in either order.
  const auto i = parse_ok(run_cli(
      {"imu", f.string(), "--rate", "100", "--gyro", "1", "--accel", "6", "--json", "--output-unit", "mg,rad/s"}));
  EXPECT_EQ(i["channels"][0]["fit"]["N"]["unit"], "rad/s/sqrt(Hz)");
  EXPECT_NEAR(i["channels"][0]["fit"]["N"]["value"].get<double>() / gyro_n_si(), 1.0, 0.05);
  EXPECT_EQ(i["channels"][1]["allan"]["unit"], "mg");
  EXPECT_NEAR(i["channels"][1]["mean_rate"].get<double>(), -1000.0, 2.0);
  const auto bad = run_cli({"analyze", f.string(), "--column", "acc_z_g", "--rate", "100", "--output-unit", "deg/s"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(has(bad.err, "output unit 'deg/s' is an gyro unit")) << bad.err;
}

TEST(Imu, EveryAxisInOneCommandWithTheNoiseFile) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto yaml = dir.path() / "imu.yaml";
  const auto r = run_cli({"imu", f.string(), "--rate", "100", "--gyro", "gyro_x_dps,gyro_y_dps,gyro_z_dps", "--accel",
                          "acc_x_g,acc_y_g,acc_z_g", "--json", "--kalibr", yaml.string()});
  const auto j = parse_ok(r);
  ASSERT_EQ(j["channels"].size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const auto& c = j["channels"][i];
    EXPECT_EQ(c["sensor"], i < 3 ? "gyro" : "accelerometer");
    const double want = i < 3 ? gyro_n_si() : accel_n_si();
    EXPECT_NEAR(c["fit"]["N"]["si"]["value"].get<double>() / want, 1.0, 0.05) << c["column"];
  }
  EXPECT_EQ(j["channels"][3]["column"], "acc_x_g");
  EXPECT_EQ(j["noise"]["gyro"]["axes"].size(), 3u);
  EXPECT_EQ(j["noise"]["accelerometer"]["axes"][0]["noise_density"]["unit"], "m/s^2/sqrt(Hz)");
  // The noise file: the keys, each with its unit; white noise only, so K is an upper bound.
  const std::string y = slurp(yaml);
  for (const char* key : {"rostopic: \"/imu0\"", "update_rate: 100.000000", "gyroscope_noise_density: ",
                          "gyroscope_random_walk: ", "accelerometer_noise_density: ", "accelerometer_random_walk: "})
    EXPECT_TRUE(has(y, key)) << key << "\n" << y;
  EXPECT_TRUE(has(y, "[rad/s/sqrt(Hz)]")) << y;
  EXPECT_TRUE(has(y, "[rad/s^2/sqrt(Hz)]")) << y;
  EXPECT_TRUE(has(y, "[m/s^2/sqrt(Hz)]")) << y;
  EXPECT_TRUE(has(y, "[m/s^3/sqrt(Hz)]")) << y;
  EXPECT_TRUE(has(y, "UPPER BOUND")) << y;
  EXPECT_TRUE(has(y, "#   acc_y_g: N ")) << y;
  // A YAML parser reads it as numbers (PyYAML when python3 has it).
  if (std::system("python3 -c 'import yaml' >/dev/null 2>&1") == 0) {
    const auto py =
        dir.write("check.py",
                  "import sys, yaml\nd = yaml.safe_load(open(sys.argv[1]))\n"
                  "keys = ['gyroscope_noise_density', 'gyroscope_random_walk', 'accelerometer_noise_density',\n"
                  "        'accelerometer_random_walk', 'update_rate']\n"
                  "assert all(isinstance(d[k], float) and d[k] > 0 for k in keys), d\n"
                  "assert d['rostopic'] == '/imu0'\n"
                  "print(d['gyroscope_noise_density'])\n");
    EXPECT_EQ(std::system(fmt::format("python3 '{}' '{}' >/dev/null", py.string(), yaml.string()).c_str()), 0);
  }
  // The tables: one per kind.
  const auto t = run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3", "--accel", "4,5,6"});
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_TRUE(has(t.out, "Gyro (3 axes;")) << t.out;
  EXPECT_TRUE(has(t.out, "Accelerometer (3 axes;")) << t.out;
}

TEST(Imu, EitherKindMayBeAbsentButOneIsNeeded) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto g = parse_ok(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "gyro_z_dps", "--json"}));
  EXPECT_EQ(g["channels"].size(), 1u);
  // Without --gyro and --accel the column names choose (test_bag.cpp); names without a unit cannot.
  const auto plain = dir.write("plain.csv", imu_csv("a,b,c,d,e,f"));
  const auto none = run_cli({"imu", plain.string(), "--rate", "100"});
  EXPECT_EQ(none.status, 2);
  EXPECT_TRUE(has(none.err, "give --gyro COLS and/or --accel COLS")) << none.err;
}

// No rate (no --rate, rate_hz line or time column): refused at the first data line, before the
// samples are read, so a bad line further on is never reached and nothing is written.
TEST(Imu, NoRateIsRefusedBeforeTheSamplesAreRead) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader) + "1,2,3,4,5,oops\n");
  const auto r = run_cli({"imu", f.string(), "--json"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "no sample rate")) << r.err;
  EXPECT_FALSE(has(r.err, "oops")) << r.err;
  EXPECT_TRUE(r.out.empty());
  const auto bad = run_cli({"imu", f.string(), "--rate", "100", "--json"});  // with a rate, the bad line
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(has(bad.err, fmt::format(":{}:", kSamples + 2)) && has(bad.err, "oops")) << bad.err;
}

TEST(Imu, AColumnOfTheWrongKindIsAnError) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto r = run_cli({"imu", f.string(), "--rate", "100", "--gyro", "acc_x_g"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "column 'acc_x_g' is given as --gyro but was read as accelerometer")) << r.err;
  const auto u = run_cli({"imu", f.string(), "--rate", "100", "--accel", "4", "--accel-unit", "deg/s"});
  EXPECT_EQ(u.status, 2);
  EXPECT_TRUE(has(u.err, "--accel-unit deg/s is not an accelerometer unit")) << u.err;
  // batch prints a gyro's units and classes: an accelerometer column is refused there.
  const auto b = run_cli({"batch", f.string(), "--column", "acc_x_g", "--rate", "100"});
  EXPECT_EQ(b.status, 2);
  EXPECT_TRUE(has(b.err, "is an accelerometer channel; batch and report take gyro runs")) << b.err;
  // Without a suffix or --accel-unit an accelerometer column cannot be read as one.
  const auto plain = dir.write("plain.csv", "a\n0.001\n0.002\n-0.001\n0.003\n");
  const auto p = run_cli({"imu", plain.string(), "--rate", "100", "--accel", "a"});
  EXPECT_NE(p.status, 0);
}

TEST(Imu, EarthRateAndVerdictOnlyForPulsesOrWhenAsked) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  // A rate gyro: neither, and the output says so and how to ask.
  const auto off = run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100", "--json"});
  const auto j = parse_ok(off);
  EXPECT_EQ(j["earth_rate_subtracted"], false);
  EXPECT_EQ(j["earth_rate"].get<double>(), 0.0);
  EXPECT_TRUE(j["latitude_deg"].is_null());
  EXPECT_NEAR(j["bias"].get<double>(), 360.0, 5.0);  // the mean, 0.1 °/s
  EXPECT_EQ(j["verdict"]["applies"], false);
  EXPECT_TRUE(has(j["not_applied_reason"].get<std::string>(), "--vertical")) << j["not_applied_reason"];
  const auto t = run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100"});
  EXPECT_TRUE(has(t.out, "Verdict: not given (rate input")) << t.out;
  EXPECT_FALSE(has(t.out, "P(meets class)")) << t.out;
  EXPECT_TRUE(has(t.out, "(no Earth rate subtracted)")) << t.out;
  // --vertical: both, as for pulse input (no not_applied keys at all).
  const auto v =
      parse_ok(run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100", "--json", "--vertical"}));
  EXPECT_FALSE(v.contains("not_applied_reason"));
  EXPECT_NEAR(v["earth_rate"].get<double>(), 12.43, 0.01);
  // --earth-rate alone: the Earth rate, still no verdict.
  const auto e = parse_ok(
      run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100", "--json", "--earth-rate", "10"}));
  EXPECT_EQ(e["earth_rate_subtracted"], true);
  EXPECT_EQ(e["verdict"]["applies"], false);
  // Pulse input keeps both.
  const auto p = parse_ok(run_cli({"analyze", source_path("data/gl2d/gl2d_p25C.csv.gz").string(), "--json"}));
  EXPECT_FALSE(p.contains("not_applied_reason"));
  EXPECT_TRUE(p["verdict"].contains("class"));
  // imu: only the gyro said to be vertical.
  const auto i = parse_ok(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "gyro_x_dps,gyro_z_dps",
                                   "--vertical-gyro", "gyro_z_dps", "--json"}));
  EXPECT_EQ(i["channels"][0]["verdict"]["applies"], false);
  EXPECT_EQ(i["channels"][0]["earth_rate_subtracted"], false);
  EXPECT_TRUE(i["channels"][1]["verdict"].contains("class"));
  EXPECT_FALSE(i["channels"][1]["verdict"].contains("applies"));
  EXPECT_FALSE(i["channels"][1].contains("earth_rate_subtracted"));  // both applied: no key says otherwise
  EXPECT_NEAR(i["channels"][1]["earth_rate"].get<double>(), 12.43, 0.01);
}

TEST(Imu, IncrementsGiveWhatTheRatesGive) {
  // The same axes as rates and as per-sample increments (Δθ = ω·τ0 in rad, Δv = a·τ0 in m/s).
  TempDir dir;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> z;
  std::string s = "w_rads,a_g,dtheta,dv\n";
  for (int k = 0; k < kSamples; ++k) {
    const double w = 0.001 + 0.0009 * z(rng), a = -1 + kAccelSd * z(rng);
    s += fmt::format("{:.12g},{:.12g},{:.12g},{:.12g}\n", w, a, w / kRateHz, a * kG / kRateHz);
  }
  const auto f = dir.write("inc.csv", s);
  const auto j =
      parse_ok(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "w_rads", "--accel", "a_g", "--json"}));
  ASSERT_EQ(j["channels"].size(), 2u);
  const auto g = parse_ok(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "dtheta", "--gyro-unit", "rad",
                                   "--accel", "dv", "--accel-unit", "m/s", "--json"}));
  const auto& rate = j["channels"];
  EXPECT_EQ(g["channels"][0]["input"]["kind"], "increment");
  EXPECT_EQ(g["channels"][1]["input"]["unit"], "m/s");
  EXPECT_EQ(g["channels"][1]["sensor"], "accelerometer");
  for (const char* t : {"N", "B"}) {
    EXPECT_NEAR(g["channels"][0]["fit"][t]["si"]["value"].get<double>() /
                    rate[0]["fit"][t]["si"]["value"].get<double>(),
                1.0, 1e-6)
        << t;
    EXPECT_NEAR(g["channels"][1]["fit"][t]["si"]["value"].get<double>() /
                    rate[1]["fit"][t]["si"]["value"].get<double>(),
                1.0, 1e-6)
        << t;
  }
  EXPECT_NEAR(g["channels"][1]["mean_rate"].get<double>(), -1e6, 2e3);  // µg
  // analyze takes them too: --input increment --angle-unit m/s.
  const auto a = parse_ok(run_cli({"analyze", f.string(), "--column", "dv", "--input", "increment", "--angle-unit",
                                   "m/s", "--rate", "100", "--json"}));
  EXPECT_EQ(a["sensor"], "accelerometer");
}

TEST(Imu, ReportDirectoryHoldsTheWholeResult) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto out = dir.path() / "report";
  const auto r = run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3", "--accel", "4,5,6", "--report",
                          out.string(), "-o", (dir.path() / "tables.txt").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* name : {"index.html", "imu.txt", "imu.json", "imu.yaml"})
    EXPECT_TRUE(std::filesystem::exists(out / name)) << name;
  EXPECT_EQ(slurp(out / "imu.txt"), slurp(dir.path() / "tables.txt"));
  // The page is in the test report's look (its stylesheet, A4 with page numbers) and holds the
  // tables as HTML tables, a column per axis, not preformatted text that runs off the page.
  const std::string html = slurp(out / "index.html");
  EXPECT_TRUE(has(html, "@page")) << html;
  EXPECT_TRUE(has(html, "<header class=\"title\">")) << html;
  EXPECT_FALSE(has(html, "<pre>")) << html;
  EXPECT_TRUE(has(html, "<b>Table 2.</b> Accelerometer axes")) << html;
  for (const char* column : {"gyro_x_dps", "gyro_z_dps", "acc_x_g", "acc_z_g"})
    EXPECT_TRUE(has(html, fmt::format("<th class=\"axis\">{}</th>", column))) << column;
  EXPECT_TRUE(has(html, "N velocity random walk <span class=\"unit\">(m/s/√h)</span>")) << html;
  EXPECT_TRUE(has(html, "<a href=\"imu.yaml\">")) << html;
  EXPECT_TRUE(has(html, "<a href=\"imu.json\">")) << html;
  // The figure is on the page when gnuplot drew it, and absent (no broken image) when not.
  EXPECT_EQ(has(html, "<img alt=\"Allan deviation of every axis"), std::filesystem::exists(out / "imu.svg")) << html;
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "imu.json"))["channels"].size(), 6u);
}

// A 6-axis recording of 3000 samples: enough for the checks below, quick to analyse.
std::string short_imu_csv() {
  std::string s = imu_csv(kHeader);
  std::size_t end = 0;
  for (int lines = 0; lines <= 3000; ++lines) end = s.find('\n', end) + 1;
  return s.substr(0, end);
}

TEST(Imu, EveryOutputIsCheckedBeforeAnyIsWritten) {
  TempDir dir;
  const auto f = dir.write("imu.csv", short_imu_csv());
  const auto report = dir.path() / "report";
  const std::vector<std::string> base{"imu", f.string(), "--rate", "100", "--gyro", "1,2", "--accel", "4"};
  // An existing imu.yaml in the report directory stops every output: no imu.txt, no imu.json, no
  // --kalibr file (before, imu.txt and imu.json were written and the command ended with status 3).
  std::filesystem::create_directory(report);
  std::ofstream(report / "imu.yaml") << "old\n";
  const auto kalibr = dir.path() / "k.yaml";
  auto r = run_cli(concat(base, {"--report", report.string(), "--kalibr", kalibr.string()}));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(has(r.err, "imu.yaml: exists")) << r.err;
  for (const char* name : {"imu.txt", "imu.json", "index.html", "imu.svg"})
    EXPECT_FALSE(std::filesystem::exists(report / name)) << name;
  EXPECT_FALSE(std::filesystem::exists(kalibr));
  EXPECT_EQ(slurp(report / "imu.yaml"), "old\n");
  // -o naming a file of the report is a usage error; so is a rostopic no YAML file can carry.
  r = run_cli(concat(base, {"--report", report.string(), "-o", (report / "imu.txt").string(), "--force"}));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "the same file")) << r.err;
  const auto fresh = dir.path() / "fresh";
  r = run_cli(concat(base, {"--report", fresh.string(), "--rostopic", "/imu\xff"}));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "--rostopic")) << r.err;
  EXPECT_FALSE(std::filesystem::exists(fresh));
  // A report directory under a file cannot be made: said before the analysis.
  r = run_cli(concat(base, {"--report", (f / "sub").string()}));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(has(r.err, "cannot create the report directory")) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  // With --force the whole set is written.
  r = run_cli(concat(base, {"--report", report.string(), "--force"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(report / "imu.yaml"), "old\n");
}

TEST(Imu, AColumnGivenTwiceOrTheTimeColumnIsRefusedNamingIt) {
  TempDir dir;
  // The short recording with a time column first.
  const std::string plain = short_imu_csv();
  std::string timed = "time_s,";
  for (std::size_t at = 0, k = 0; at < plain.size(); ++k) {
    const auto eol = plain.find('\n', at);
    timed += (k == 0 ? "" : fmt::format("{:.2f},", static_cast<double>(k - 1) / 100)) + plain.substr(at, eol - at + 1);
    at = eol + 1;
  }
  const auto f = dir.write("imu.csv", timed);
  const std::vector<std::string> base{"imu", f.string()};
  // Once by name and once by index; as gyro and as accelerometer: the noise would count twice.
  auto r = run_cli(concat(base, {"--gyro", "gyro_x_dps,2"}));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "column 'gyro_x_dps' is given twice (--gyro gyro_x_dps and --gyro 2)")) << r.err;
  r = run_cli(concat(base, {"--gyro", "gyro_x_dps", "--accel", "acc_x_g,gyro_x_dps", "--accel-unit", "g"}));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "column 'gyro_x_dps' is given twice (--gyro gyro_x_dps and --accel gyro_x_dps)")) << r.err;
  // The time column is no sensor's output, whatever unit is claimed for it.
  for (const char* time : {"time_s", "1"}) {
    r = run_cli(concat(base, {"--gyro", std::string("gyro_x_dps,") + time, "--gyro-unit", "deg/s"}));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_TRUE(has(r.err, "imu.csv:1: column 'time_s' (1) is the time column")) << r.err;
  }
}

TEST(Imu, AConstantChannelIsRefusedNamingItsColumn) {
  TempDir dir;
  std::string text = imu_csv("gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_g,acc_y_g,acc_z_g");
  // gyro_y_dps stuck at one value: the second field of every data line.
  std::string stuck;
  for (std::size_t at = 0, line = 0; at < text.size() && line < 3001; ++line) {
    const auto eol = text.find('\n', at);
    std::string l = text.substr(at, eol - at);
    if (line > 0) {
      const auto a = l.find(','), b = l.find(',', a + 1);
      l = l.substr(0, a + 1) + "0.25" + l.substr(b);
    }
    stuck += l + "\n";
    at = eol + 1;
  }
  const auto f = dir.write("imu.csv", stuck);
  const auto r = run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(has(r.err, "column 'gyro_y_dps': ")) << r.err;
  EXPECT_TRUE(has(r.err, "every sample has the same value")) << r.err;
  EXPECT_TRUE(has(r.err, "leave it out of --gyro")) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  // Left out, the other axes are analysed.
  EXPECT_EQ(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,3"}).status, 0);
}

}  // namespace
}  // namespace rwcalc::test

namespace rwcalc::test {
namespace {

// Three gyro axes of white noise (°/s), the last with a ±0.05 °/s square wave of period 60 s
// (a rejected fit): 40 min at 100 Hz.
std::string gyros_one_misfit() {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z;
  std::string s = "gyro_x_dps,gyro_y_dps,gyro_z_dps\n";
  for (int k = 0; k < 240000; ++k) {
    const double square = (k / 3000) % 2 == 0 ? 0.05 : -0.05;
    s += fmt::format("{:.6f},{:.6f},{:.6f}\n", kGyroSd * z(rng), 1.2 * kGyroSd * z(rng),
                     square + 1.5 * kGyroSd * z(rng));
  }
  return s;
}

// The value of a key of the noise file.
double yaml_key(const std::string& y, const std::string& key) {
  const auto at = y.find("\n" + key + ": ");
  EXPECT_NE(at, std::string::npos) << key;
  return at == std::string::npos ? 0.0 : std::stod(y.substr(at + key.size() + 3));
}

TEST(ImuNoiseFile, KeysTakeAcceptedResolvedAxesAndNameTheOthers) {
  TempDir dir;
  const auto f = dir.write("g.csv", gyros_one_misfit());
  const auto yaml = dir.path() / "imu.yaml";
  const auto j =
      parse_ok(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3", "--json", "--kalibr", yaml.string()}));
  const auto& axes = j["noise"]["gyro"]["axes"];
  ASSERT_EQ(axes.size(), 3u);
  ASSERT_FALSE(axes[0]["fit_rejected"].get<bool>());
  ASSERT_FALSE(axes[1]["fit_rejected"].get<bool>());
  ASSERT_TRUE(axes[2]["fit_rejected"].get<bool>());  // the square wave
  // N: the worst accepted axis (y), not z's larger value from a rejected fit.
  const double ny = axes[1]["noise_density"]["value"].get<double>();
  EXPECT_GT(axes[2]["noise_density"]["value"].get<double>(), ny);
  const std::string y = slurp(yaml);
  EXPECT_DOUBLE_EQ(yaml_key(y, "gyroscope_noise_density"), ny) << y;  // every digit written
  EXPECT_EQ(j["noise"]["gyro"]["worst"]["noise_density_axis"], "gyro_y_dps");
  EXPECT_FALSE(axes[2]["noise_density"]["in_keys"].get<bool>());
  EXPECT_TRUE(has(y, "#     N left out of the keys: its fit is rejected")) << y;
  // K: white noise only, so no axis resolves it: the key is the largest bound, said in the first lines.
  const auto first_lines = y.substr(0, y.find("# gyro axes"));
  EXPECT_TRUE(has(first_lines, "# WARNING: no gyro axis has an accepted fit and a resolved K")) << y;
  EXPECT_TRUE(has(y, "gyroscope_random_walk: ")) << y;
  EXPECT_TRUE(j["noise"]["gyro"]["worst"]["random_walk_no_axis_qualifies"].get<bool>());
  EXPECT_FALSE(has(first_lines, "resolved N")) << y;
  // Asked for, every axis goes into the keys: then z is the worst.
  const auto all = dir.path() / "all.yaml";
  ASSERT_EQ(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3", "-o", (dir.path() / "t.txt").string(),
                     "--kalibr", all.string(), "--keys-from-all-axes"})
                .status,
            0);
  const std::string ya = slurp(all);
  EXPECT_GT(yaml_key(ya, "gyroscope_noise_density"), yaml_key(y, "gyroscope_noise_density"));
  EXPECT_TRUE(has(ya, "worst axis gyro_z_dps")) << ya;
  EXPECT_TRUE(has(ya, "in the keys (--keys-from-all-axes) although its fit is rejected")) << ya;
}

// Loads a noise file as its consumer does (PyYAML; for OpenCV's %YAML:1.0 form, the directive line
// taken off as OpenCV's reader does) and checks its header, its keys and their values against the
// JSON's worst axes: factor_n and factor_k times them, within 1e-9 relative.
const char* kLoadNoiseFile = R"(import sys, json, math, yaml
path, fmt, jpath, fn, fk, topic = sys.argv[1:7]
fn, fk = float(fn), float(fk)
text = open(path, encoding='utf-8').read()
opencv = fmt != 'kalibr'
first, rest = text.split('\n', 1)
assert (first == '%YAML:1.0') == opencv, first
d = yaml.safe_load(rest if opencv else text)
j = json.load(open(jpath))['noise']
keys = {'kalibr': ('accelerometer_noise_density', 'accelerometer_random_walk', 'gyroscope_noise_density', 'gyroscope_random_walk'),
        'vins-fusion': ('acc_n', 'acc_w', 'gyr_n', 'gyr_w'),
        'orb-slam3': ('IMU.NoiseAcc', 'IMU.AccWalk', 'IMU.NoiseGyro', 'IMU.GyroWalk')}
keys['openvins'] = keys['kalibr']
if fmt == 'openvins':
    d = d['imu0']
    assert d['model'] == 'kalibr' and len(d['T_i_b']) == 4 and d['T_i_b'][3] == [0.0, 0.0, 0.0, 1.0], d
want = [j['accelerometer']['worst']['noise_density'] * fn, j['accelerometer']['worst']['random_walk'] * fk,
        j['gyro']['worst']['noise_density'] * fn, j['gyro']['worst']['random_walk'] * fk]
for k, w in zip(keys[fmt], want):
    assert isinstance(d[k], float) and abs(d[k] / w - 1) < 1e-9, (k, d[k], w)
rate = {'kalibr': 'update_rate', 'openvins': 'update_rate', 'orb-slam3': 'IMU.Frequency'}
if fmt in rate: assert d[rate[fmt]] == 100.0, d
if fmt in ('kalibr', 'openvins'): assert d['rostopic'] == topic, d['rostopic']
if fmt == 'vins-fusion':
    assert d['imu_topic'] == topic and abs(d['g_norm'] / 9.80665 - 1) < 1e-3, d
)";

bool have_pyyaml() { return std::system("python3 -c 'import yaml' >/dev/null 2>&1") == 0; }

TEST(ImuNoiseFile, EveryFormatLoadsAsItsConsumerReadsIt) {
  if (!have_pyyaml()) GTEST_SKIP() << "python3-yaml is not installed";
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto py = dir.write("load.py", kLoadNoiseFile);
  const std::vector<std::string> base{"imu",   f.string(), "--rate", "100",   "--gyro",
                                      "1,2,3", "--accel",  "4,5,6",  "--json"};
  const std::string topic = "/imu \"0\" \xc3\xa9";  // a quote and a non-ASCII letter, encoded for YAML
  auto check = [&](const std::string& format, const std::vector<std::string>& extra, double fn,
                   double fk) -> std::string {
    const auto yaml = dir.path() / (format + ".yaml");
    const auto json = dir.path() / (format + ".json");
    std::vector<std::string> args = base;
    for (const auto& a : {std::string("--noise-file"), yaml.string(), std::string("--noise-format"), format,
                          std::string("--rostopic"), topic, std::string("-o"), json.string(), std::string("--force")})
      args.push_back(a);
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = run_cli(args);
    if (r.status != 0) {
      ADD_FAILURE() << format << ": " << r.err;
      return {};
    }
    const std::string cmd = fmt::format("python3 '{}' '{}' '{}' '{}' {:.17g} {:.17g} '{}'", py.string(), yaml.string(),
                                        format, json.string(), fn, fk, topic);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << format << "\n" << slurp(yaml);
    return slurp(yaml);
  };
  for (const char* format : {"kalibr", "openvins", "vins-fusion", "orb-slam3"}) {
    const std::string y = check(format, {}, 1, 1);
    EXPECT_TRUE(has(y, "# values: continuous time")) << y;
    EXPECT_TRUE(has(y, "# not inflated")) << y;
    const std::string inflated = check(format, {"--inflate", "3.5"}, 3.5, 3.5);
    EXPECT_TRUE(has(inflated, "# INFLATED: every key's noise value is 3.5 x the measured one (--inflate 3.5)"))
        << inflated;
  }
  // Discrete time at 100 Hz: sigma_d = N*sqrt(100), sigma_bd = K/sqrt(100), inflated on top.
  const std::string d = check("vins-fusion", {"--discrete", "--inflate", "2"}, 2 * 10.0, 2 / 10.0);
  EXPECT_TRUE(has(d, "# values: DISCRETE time at 100 Hz (--discrete)")) << d;
  EXPECT_TRUE(has(d, "acc_n: ") && has(d, "  # [m/s^2] worst axis")) << d;
  // --kalibr stays the Kalibr shorthand beside a --noise-file of another format.
  const auto k = dir.path() / "k.yaml";
  const auto o = dir.path() / "o.yaml";
  ASSERT_EQ(run_cli({"imu", f.string(), "--rate", "100", "--gyro", "1,2,3", "--kalibr", k.string(), "--noise-file",
                     o.string(), "--noise-format", "orb-slam3", "-o", (dir.path() / "t.txt").string()})
                .status,
            0);
  EXPECT_TRUE(has(slurp(k), "\ngyroscope_noise_density: "));
  EXPECT_TRUE(has(slurp(o), "\nIMU.NoiseGyro: "));
  EXPECT_FALSE(has(slurp(o), "IMU.NoiseAcc"));  // no accelerometer channel: its keys left out, said
  EXPECT_TRUE(has(slurp(o), "# no accelerometer channel was analysed"));
}

TEST(ImuNoiseFile, BadFormatInflateOrDiscreteIsAUsageErrorBeforeAnyOutput) {
  TempDir dir;
  const auto f = dir.write("imu.csv", imu_csv(kHeader));
  const auto yaml = dir.path() / "n.yaml";
  const std::vector<std::string> base{"imu",    f.string(), "--rate",       "100",
                                      "--gyro", "1,2,3",    "--noise-file", yaml.string()};
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--noise-format", "rovio"}, "--noise-format"},
      {{"--noise-format", "vins-fusion", "--inflate", "0.5"}, "--inflate"},
      {{"--inflate", "nan"}, "--inflate"},
      {{"--inflate", "inf"}, "--inflate"},
      {{"--inflate", "-2"}, "--inflate"},
      {{"--noise-format", "orb-slam3", "--discrete"}, "--discrete"},
      {{"--noise-format", "openvins", "--discrete"}, "--discrete"},
      {{"--discrete"}, "--discrete"}};  // kalibr by default
  for (const auto& [extra, option] : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 2) << extra.front() << " " << extra.back();
    EXPECT_TRUE(has(r.err, option)) << r.err;
    EXPECT_FALSE(std::filesystem::exists(yaml)) << extra.back();
  }
}

}  // namespace
}  // namespace rwcalc::test
