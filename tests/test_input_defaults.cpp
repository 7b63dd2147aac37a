// The reader makes no silent choices for IMU files: rate and angle input need a sample rate; time
// columns are read in s, ms, us or ns (by name or by the stamps' magnitude); jitter is accepted and
// reported, a gap refused (or, with --gaps segments, the record split at it); a unit suffix of the column name chooses
// the unit (and the input kind) that no option gave, and every such choice is said on standard error and in the JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "test_support.hpp"

namespace rwcalc::test {
namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A rate value with a little deterministic noise around `mean` (exactly `mean` on average over
// each pair of samples), so that the Allan variance has something to measure.
double noisy(double mean, int k) { return mean + ((k * 7919) % 13 - 6) * 1e-3 + (k % 2 ? 1e-3 : -1e-3); }

// "HEADER\n" then n lines made by `line(k)`.
std::string table(const std::string& header, int n, const std::function<std::string(int)>& line) {
  std::string s = header + "\n";
  for (int k = 0; k < n; ++k) s += line(k) + "\n";
  return s;
}

nlohmann::json allan_json(const CliResult& r) {
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
}

TEST(InputDefaults, RateInputWithoutASampleRateIsAnErrorNamingTheThreeWays) {
  TempDir dir;
  const auto f = dir.write("imu.csv", table("gyro", 200, [](int k) { return fmt::format("{}", noisy(0, k)); }));
  for (const std::string input : {"rate", "angle"}) {
    const auto r = run_cli({"allan", f.string(), "--input", input});
    EXPECT_EQ(r.status, 2) << input;
    EXPECT_TRUE(has(r.err, "no sample rate")) << r.err;
    EXPECT_TRUE(has(r.err, "--rate")) << r.err;
    EXPECT_TRUE(has(r.err, "rate_hz")) << r.err;
    EXPECT_TRUE(has(r.err, "time column")) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
  // Without --input, fractional samples in a column without a unit are no pulse counts: the error
  // says how to read them as rate or angle samples.
  const auto g = run_cli({"allan", f.string()});
  EXPECT_EQ(g.status, 2);
  EXPECT_TRUE(has(g.err, "pulse counts must be integers")) << g.err;
  EXPECT_TRUE(has(g.err, "give --input rate or --input angle")) << g.err;
  // Pulses keep the GL-2D default, and say so in every output.
  const auto p = dir.write("p.txt", table("pulses", 200, [](int k) { return std::to_string(k % 3); }));
  const auto j = allan_json(run_cli({"allan", p.string(), "--json", "--tau", "decade"}));
  EXPECT_EQ(j["input"]["rate_source"], "default");
  EXPECT_EQ(j["rate_hz"], 400.0);
  const auto t = run_cli({"allan", p.string(), "--tau", "decade"});
  EXPECT_TRUE(has(t.out, "rate: 400 Hz (default)")) << t.out;
  EXPECT_TRUE(has(t.out, "# input: column 'pulses': pulse counts, 0.92 arcsec per pulse")) << t.out;
}

TEST(InputDefaults, NanosecondTimestampsByMagnitudeGiveTheRate) {
  TempDir dir;
  const std::int64_t t0 = 1'700'000'000'000'000'000;
  const auto f = dir.write("ns.csv", table("timestamp,gyro", 400, [&](int k) {
                             return fmt::format("{},{}", t0 + std::int64_t{k} * 10'000'000, noisy(0, k));
                           }));
  const auto r = run_cli({"allan", f.string(), "--input", "rate", "--json", "--tau", "decade"});
  const auto j = allan_json(r);
  EXPECT_EQ(j["rate_hz"], 100.0);
  EXPECT_EQ(j["input"]["rate_source"], "time column");
  EXPECT_EQ(j["input"]["time_unit"], "ns");
  EXPECT_EQ(j["input"]["time_unit_source"], "magnitude");
  EXPECT_TRUE(has(r.err, "rwcalc: note: ")) << r.err;
  EXPECT_TRUE(has(r.err, "time column 'timestamp' in ns (by magnitude")) << r.err;
}

TEST(InputDefaults, StampsNearZeroAreSecondsAndAmbiguousOnesAreAnError) {
  TempDir dir;
  const auto s =
      dir.write("s.csv", table("time,gyro", 300, [](int k) { return fmt::format("{},{}", 0.005 * k, noisy(0, k)); }));
  const auto j = allan_json(run_cli({"allan", s.string(), "--input", "rate", "--json", "--tau", "decade"}));
  EXPECT_EQ(j["rate_hz"], 200.0);
  EXPECT_EQ(j["input"]["time_unit"], "s");
  // A first stamp of 5e6 is neither near 0 nor Unix time in any unit: no guess.
  const auto m = dir.write("m.csv", table("time,gyro", 300,
                                          [](int k) { return fmt::format("{},{}", 5'000'000 + 10 * k, noisy(0, k)); }));
  const auto r = run_cli({"allan", m.string(), "--input", "rate"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "cannot tell the unit of the time column 'time'")) << r.err;
  EXPECT_TRUE(has(r.err, "time_ms")) << r.err;
}

TEST(InputDefaults, RosPercentTimeColumnIsNanosecondsSinceTheEpoch) {
  TempDir dir;
  const std::int64_t t0 = 1'690'000'000'123'456'789;
  const auto f = dir.write("ros.csv", table("%time,field.header.seq,field.angular_velocity.z", 400, [&](int k) {
                             return fmt::format("{},{},{}", t0 + std::int64_t{k} * 5'000'000, k, noisy(0, k));
                           }));
  const auto r = run_cli({"allan", f.string(), "--input", "rate", "--rate-unit", "rad/s", "--column",
                          "field.angular_velocity.z", "--json", "--tau", "decade"});
  const auto j = allan_json(r);
  EXPECT_EQ(j["rate_hz"], 200.0);
  EXPECT_EQ(j["input"]["time_column"], "%time");
  EXPECT_EQ(j["input"]["time_unit"], "ns");
  EXPECT_EQ(j["input"]["time_unit_source"], "name");
}

TEST(InputDefaults, MillisecondAndMicrosecondColumnsByName) {
  TempDir dir;
  const auto ms = dir.write("ms.csv", table("time_ms,gyro", 300,
                                            [](int k) { return fmt::format("{},{}", 1000 + 4 * k, noisy(0, k)); }));
  const auto us =
      dir.write("us.csv", table("t_us,gyro", 300, [](int k) { return fmt::format("{},{}", 1000 * k, noisy(0, k)); }));
  const auto a = allan_json(run_cli({"allan", ms.string(), "--input", "rate", "--json", "--tau", "decade"}));
  EXPECT_EQ(a["rate_hz"], 250.0);
  EXPECT_EQ(a["input"]["time_unit"], "ms");
  const auto b = allan_json(run_cli({"allan", us.string(), "--input", "rate", "--json", "--tau", "decade"}));
  EXPECT_EQ(b["rate_hz"], 1000.0);
  EXPECT_EQ(b["input"]["time_unit"], "us");
}

TEST(InputDefaults, DpsSuffixMeansDegreesPerSecondAndImpliesRateInput) {
  TempDir dir;
  // 1 °/s on average: the mean rate must come out 3600 °/h, not 1 °/h.
  const auto f = dir.write("imu.csv", table("gyro_x_dps,acc_x_g", 40000,
                                            [](int k) { return fmt::format("{},{}", noisy(1.0, k), -1.0); }));
  const auto r = run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["mean_rate"].get<double>(), 3600.0, 0.01);  // 1 °/h if read as °/h
  EXPECT_EQ(j["input"]["kind"], "rate");
  EXPECT_EQ(j["input"]["unit"], "deg/s");
  EXPECT_EQ(j["input"]["column"], "gyro_x_dps");
  EXPECT_TRUE(has(r.err, "rwcalc: note: ")) << r.err;
  EXPECT_TRUE(has(r.err, "rate unit deg/s from the column name 'gyro_x_dps'")) << r.err;
  EXPECT_TRUE(has(r.err, "input rate from the column name 'gyro_x_dps'")) << r.err;
  // The text report names the column, the kind and the unit.
  const auto t = run_cli({"analyze", f.string(), "--column", "gyro_x_dps", "--rate", "100"});
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_TRUE(has(t.out, "input: rate samples in deg/s from column 'gyro_x_dps'; sample rate from option")) << t.out;
  // An accelerometer channel is read in g as an accelerometer, not as a gyro.
  const auto acc = allan_json(run_cli({"allan", f.string(), "--column", "acc_x_g", "--rate", "100", "--json"}));
  EXPECT_EQ(acc["input"]["unit"], "g");
  EXPECT_EQ(acc["unit"], "m/s/h");
}

TEST(InputDefaults, AUnitThatContradictsTheColumnNameIsUsedWithAWarning) {
  TempDir dir;
  const auto f = dir.write("imu.csv", table("gyro_x_dps", 300, [](int k) { return fmt::format("{}", noisy(1, k)); }));
  const auto r = run_cli(
      {"allan", f.string(), "--input", "rate", "--rate-unit", "deg/h", "--rate", "100", "--json", "--tau", "decade"});
  const auto j = allan_json(r);
  EXPECT_EQ(j["input"]["unit"], "deg/h");
  ASSERT_EQ(j["input"]["warnings"].size(), 1u);
  EXPECT_TRUE(has(r.err, "rwcalc: warning: ")) << r.err;
  EXPECT_TRUE(has(r.err, "says rate in deg/s, but --rate-unit deg/h is used")) << r.err;
}

TEST(InputDefaults, JitterIsAcceptedAndReported) {
  TempDir dir;
  // 100 Hz stamps in ms, every 10th step 3 % long and the next 3 % short: 1 % is the tolerance.
  const auto f = dir.write("jit.csv", table("time_ms,gyro", 500, [](int k) {
                             return fmt::format("{},{}", 10.0 * k + (k % 10 == 5 ? 0.3 : 0.0), noisy(0, k));
                           }));
  const auto r = run_cli({"allan", f.string(), "--input", "rate", "--json", "--tau", "decade"});
  const auto j = allan_json(r);
  EXPECT_EQ(j["rate_hz"], 100.0);
  EXPECT_EQ(j["input"]["jitter"]["steps"], 100);
  EXPECT_NEAR(j["input"]["jitter"]["max_fraction"].get<double>(), 0.03, 1e-9);
  EXPECT_NEAR(j["input"]["jitter"]["rms_fraction"].get<double>(), 0.03 * std::sqrt(100.0 / 499), 1e-9);
  EXPECT_TRUE(has(r.err, "jitter: 100 time steps off the period")) << r.err;
  // Without jitter the record says so: no steps off.
  const auto g = dir.write("even.csv",
                           table("time_ms,gyro", 300, [](int k) { return fmt::format("{},{}", 10 * k, noisy(0, k)); }));
  const auto e = allan_json(run_cli({"allan", g.string(), "--input", "rate", "--json", "--tau", "decade"}));
  EXPECT_EQ(e["input"]["jitter"]["steps"], 0);
}

TEST(InputDefaults, AGapIsAnErrorWithTheLineAndTheMissingDuration) {
  TempDir dir;
  // 100 Hz; samples 100..102 missing: line 101 (sample 99) to line 102 (sample 103), 0.03 s missing.
  const auto f = dir.write("gap.csv", table("time_s,gyro", 300, [](int k) {
                             const int i = k < 100 ? k : k + 3;
                             return fmt::format("{},{}", 0.01 * i, noisy(0, k));
                           }));
  const auto r = run_cli({"allan", f.string(), "--input", "rate"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "gap.csv:102: gap in the time column: 0.99 s at line 101, then 1.03 s: 0.03 s missing"))
      << r.err;
  EXPECT_TRUE(has(r.err, "give --gaps segments")) << r.err;
  EXPECT_TRUE(r.out.empty());
  // --gaps segments: accepted, split in two, and said (allan on stderr, analyze in text and JSON).
  const auto a = run_cli({"allan", f.string(), "--input", "rate", "--gaps", "segments"});
  EXPECT_EQ(a.status, 0) << a.err;
  EXPECT_TRUE(has(a.err, "2 segments")) << a.err;
  EXPECT_FALSE(has(a.err, "jitter")) << a.err;  // a gap is not jitter
  const auto j = run_cli({"analyze", f.string(), "--input", "rate", "--gaps", "segments", "--json"});
  ASSERT_EQ(j.status, 0) << j.err;
  const auto seg = nlohmann::json::parse(j.out)["segments"];
  ASSERT_TRUE(seg.is_object()) << j.out.substr(0, 400);
  EXPECT_EQ(seg["count"], 2);
  EXPECT_EQ(seg["samples"], nlohmann::json::parse("[100, 200]"));
  ASSERT_EQ(seg["gaps"].size(), 1u);
  EXPECT_EQ(seg["gaps"][0]["line"], 102);
  EXPECT_NEAR(seg["gaps"][0]["missing_s"].get<double>(), 0.03, 1e-9);
  const auto t = run_cli({"analyze", f.string(), "--input", "rate", "--gaps", "segments"});
  EXPECT_TRUE(has(t.out, "segments: 2 (split at the time column's gaps by --gaps segments: 0.03 s before line 102"))
      << t.out;
  // Only refuse and segments are ways to deal with a gap.
  const auto g = run_cli({"analyze", f.string(), "--input", "rate", "--gaps", "bridge"});
  EXPECT_NE(g.status, 0);
}

// Round trip: a simulated 4-h record (N 0.15 °/h/√h, B 3 °/h) with 10 minutes cut out of it, read
// with its time column and --gaps segments, gives intervals that hold the truth; the differences
// never span the gap (the angle runs on through it: a spanning difference would see 600 s of
// Earth rate, 7460″).
TEST(InputDefaults, GapsSegmentsRecoverTheCoefficientsOfARecordWithAChunkCutOut) {
  TempDir dir;
  const auto sim = dir.path() / "sim.csv";
  ASSERT_EQ(run_cli({"simulate", "-o", sim.string(), "--duration", "14400", "--rate", "10", "--scale", "0.2", "--arw",
                     "0.15", "--bias-instability", "3", "--white-readout", "--output-lowpass", "0.001", "--seed", "3"})
                .status,
            0);
  std::istringstream in(slurp(sim));
  std::string line, out = "# rate_hz: 10\ntime_s,angle\n";
  int k = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line == "angle") continue;
    ++k;
    if (k >= 60000 && k < 66000) continue;  // 600 s cut out
    out += fmt::format("{:.1f},{}\n", 0.1 * k, line);
  }
  const auto f = dir.write("cut.csv", out);
  const auto r = run_cli({"analyze", f.string(), "--input", "angle", "--gaps", "segments", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["segments"]["count"], 2);
  EXPECT_NEAR(j["segments"]["gaps"][0]["missing_s"].get<double>(), 600.0, 1e-6);
  for (const auto& [key, truth] : {std::pair{"N", 0.15}, std::pair{"B", 3.0}}) {
    const auto& c = j["fit"][key];
    EXPECT_TRUE(c["resolved"].get<bool>()) << key;
    EXPECT_LE(c["low95"].get<double>(), truth) << key << " " << c.dump();
    EXPECT_GE(c["high95"].get<double>(), truth) << key << " " << c.dump();
  }
  EXPECT_LT(j["fit"]["chi2_per_dof"].get<double>(), 3.0);
}

TEST(InputDefaults, ARateThatDisagreesWithTheTimeColumnNamesTheToleranceThatWouldAcceptIt) {
  TempDir dir;
  // Stamps at 101.5 Hz, --rate 100: the mean step is 1.48 % off the given period.
  const auto f = dir.write("r.csv", table("time_s,gyro", 300,
                                          [](int k) { return fmt::format("{:.6f},{}", k / 101.5, noisy(0, k)); }));
  const auto r = run_cli({"allan", f.string(), "--input", "rate", "--rate", "100"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "inconsistent with the time column 'time_s'")) << r.err;
  EXPECT_TRUE(has(r.err, "a --time-tolerance of 0.0148 or more would accept it")) << r.err;
  const auto ok = run_cli(
      {"allan", f.string(), "--input", "rate", "--rate", "100", "--time-tolerance", "0.0148", "--tau", "decade"});
  EXPECT_EQ(ok.status, 0) << ok.err;
}

// The gyro and the test are identified from the file's metadata, and the command line takes the
// place of a key (with a note); text and JSON carry them, with the file's size and SHA-256.
TEST(InputDefaults, SerialOperatorDateAndConditionsFromMetadataOrOptions) {
  TempDir dir;
  std::string body = "# rate_hz: 400\n# Serial: GL2D-0421\n# operator: Ivanov\npulses\n";
  for (int i = 0; i < 24000; ++i) body += std::to_string(i % 5 - 2) + "\n";
  const auto f = dir.write("run.csv", body);
  const auto text = run_cli({"analyze", f.string(), "--operator", "Petrov", "--test-date", "2026-11-27"});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("gyro and test: serial GL2D-0421; operator Petrov; test date 2026-11-27"), std::string::npos)
      << text.out;
  EXPECT_NE(text.err.find("operator 'Petrov' from the command line, not the file's 'Ivanov'"), std::string::npos)
      << text.err;
  const auto js = run_cli({"analyze", f.string(), "--json", "--conditions", "static, +25 °C"});
  ASSERT_EQ(js.status, 0) << js.err;
  const auto in = nlohmann::json::parse(js.out).at("input");
  EXPECT_EQ(in.at("identification").at("serial"), "GL2D-0421");
  EXPECT_EQ(in.at("identification").at("operator"), "Ivanov");
  EXPECT_EQ(in.at("identification").at("conditions"), "static, +25 °C");
  EXPECT_TRUE(in.at("identification").at("test_date").is_null());
  EXPECT_EQ(in.at("file_bytes").get<std::uintmax_t>(), std::filesystem::file_size(f));
  EXPECT_EQ(in.at("sha256").get<std::string>().size(), 64u);
}

}  // namespace
}  // namespace rwcalc::test
