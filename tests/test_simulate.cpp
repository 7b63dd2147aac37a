// Quick tests of the simulator: RNG, reproducibility, file format, options, and that each
// deterministic effect appears in the time series where and how it should.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "rwcalc/error.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/random.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;
using rwcalc::test::gunzip;
using rwcalc::test::run_cli;
using rwcalc::test::TempDir;
constexpr double kPi = std::numbers::pi;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A record with (almost) no quantization and no noise: the rate series shows the deterministic terms.
SimulationSettings fine(double duration_s, double rate_hz = 100.0) {
  SimulationSettings s;
  s.duration_s = duration_s;
  s.rate_hz = rate_hz;
  s.scale_arcsec = 1e-6;
  s.seed = 11;
  return s;
}

// Mean rate (°/h) over samples [a, b).
double block_mean(const PhaseSeries& p, std::size_t a, std::size_t b) {
  return p.diff(b, a) / (static_cast<double>(b - a) * p.tau0_s);
}

TEST(Random, ZigguratNormalHasStandardMomentsAndTails) {
  Rng rng(123, 7);
  const int n = 2'000'000;
  double s1 = 0, s2 = 0, s4 = 0;
  int tail = 0, beyond1 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = rng.normal();
    s1 += z;
    s2 += z * z;
    s4 += z * z * z * z;
    tail += std::abs(z) > 3.6541528853610088;
    beyond1 += std::abs(z) > 1.0;
  }
  EXPECT_NEAR(s1 / n, 0.0, 5 * std::sqrt(1.0 / n));
  EXPECT_NEAR(s2 / n, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(s4 / n, 3.0, 5 * std::sqrt(96.0 / n));
  // P(|z| > r) = erfc(r/√2) = 2.58e-4; P(|z| > 1) = 0.31731.
  const double p_tail = std::erfc(3.6541528853610088 / std::sqrt(2.0));
  EXPECT_NEAR(tail / double(n), p_tail, 5 * std::sqrt(p_tail / n));
  EXPECT_NEAR(beyond1 / double(n), std::erfc(1 / std::sqrt(2.0)), 5 * std::sqrt(0.2166 / n));
}

TEST(Random, StreamsDifferAndRepeat) {
  Rng a(5, 1), b(5, 1), c(5, 2), d(6, 1);
  const auto xa = a.next();
  EXPECT_EQ(xa, b.next());
  EXPECT_NE(xa, c.next());
  EXPECT_NE(xa, d.next());
}

NoiseModel all_terms() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.01;
  m.bias_instability_deg_per_h = 0.05;
  m.rrw_deg_per_h_per_sqrt_h = 0.1;
  m.ramp_deg_per_h2 = 0.5;
  m.bias_deg_per_h = 1.5;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.white_angle_arcsec = 0.1;
  m.sinusoids.push_back({3.0, 2.0, 0.3});
  m.gauss_markov.push_back({0.5, 2.0});
  m.bias_steps.push_back({1.0, 0.7});
  m.warmups.push_back({3.0, 0.5});
  m.lowpass_tc_s = 0.01;
  m.temperature_bias = TemperatureBias{0.02, {TemperatureProfile::Kind::Cycle, 0, 0, 2.0, 1.5}};
  return m;
}

TEST(Simulate, SameSeedSameRecordOtherSeedOtherRecord) {
  SimulationSettings s;
  s.duration_s = 3;
  s.seed = 42;
  const auto a = simulate(all_terms(), s);
  const auto b = simulate(all_terms(), s);
  EXPECT_EQ(a.counts, b.counts);
  s.seed = 43;
  EXPECT_NE(simulate(all_terms(), s).counts, a.counts);
  // The ensemble path gives the record of simulate() for the same seed, run after run.
  s.seed = 42;
  Simulator sim(all_terms(), s);
  PhaseSeries p;
  sim.run(7, p);
  sim.run(42, p);
  EXPECT_EQ(p.counts, a.counts);
  EXPECT_EQ(a.counts.front(), 0);
  EXPECT_EQ(a.counts.size(), s.samples() + 1);
}

// FNV-1a over the pulse increments.
std::uint64_t fnv1a(const std::vector<std::int64_t>& v) {
  std::uint64_t h = 1469598103934665603ULL;
  for (auto x : v)
    for (int i = 0; i < 8; ++i) {
      h ^= (static_cast<std::uint64_t>(x) >> (8 * i)) & 0xff;
      h *= 1099511628211ULL;
    }
  return h;
}

TEST(Simulate, GoldenChecksumPinsTheGenerator) {
  // This pins the whole generator (xoshiro256++ streams, ziggurat, every term's discretisation,
  // the counting). If it changes, every shipped record and every seeded result changes with it:
  // data/gl2d must then be regenerated and the change documented.
  SimulationSettings s;
  s.duration_s = 2;
  s.seed = 2024;
  NoiseModel m = all_terms();
  m.readout = ReadoutMode::White;
  const auto c = pulse_increments(simulate(m, s));
  ASSERT_EQ(c.size(), 800u);
  EXPECT_EQ(fnv1a(c), 10499906738464653987ULL) << fnv1a(c);
}

TEST(Simulate, CliRunsAreByteIdenticalAndFileFormatIsComplete) {
  TempDir dir;
  const auto a = dir.path() / "a.csv", b = dir.path() / "b.csv";
  const std::vector<std::string> common = {
      "--duration", "5",     "--seed",        "9",  "--arw",          "0.002", "--bias-instability", "0.01",
      "--sinusoid", "1:0.5", "--temperature", "25", "--white-readout"};
  auto args = common;
  args.insert(args.begin(), {"simulate", "-o", a.string()});
  ASSERT_EQ(run_cli(args).status, 0);
  args = common;
  args.insert(args.begin(), {"simulate", "-o", b.string()});
  ASSERT_EQ(run_cli(args).status, 0);
  const std::string ta = slurp(a);
  EXPECT_EQ(ta, slurp(b));
  for (const char* key :
       {"# rate_hz: 400\n", "# scale_arcsec_per_pulse: 0.92\n", "# temperature_c: 25\n", "# seed: 9\n",
        "# arw_deg_per_sqrt_h: 0.002\n", "# bias_instability_deg_per_h: 0.01\n", "# readout: white\n",
        "# sinusoid: frequency_hz=1 amplitude_deg_per_h=0.5 phase_rad=0\n", "\npulses\n"})
    EXPECT_NE(ta.find(key), std::string::npos) << key;
  // 2000 integer lines after the header, summing to the record's final count.
  std::istringstream in(ta.substr(ta.find("\npulses\n") + 8));
  long long sum = 0, v = 0;
  int lines = 0;
  while (in >> v) {
    sum += v;
    ++lines;
  }
  EXPECT_EQ(lines, 2000);
  SimulationSettings s;
  s.duration_s = 5;
  s.seed = 9;
  s.temperature_c = 25;
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.002;
  m.bias_instability_deg_per_h = 0.01;
  m.sinusoids.push_back({1, 0.5, 0});
  m.readout = ReadoutMode::White;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  EXPECT_EQ(sum, simulate(m, s).counts.back());
  // The 12.43 °/h Earth rate over 5 s is 62.2″, i.e. ~67 pulses.
  EXPECT_NEAR(static_cast<double>(sum) * 0.92, earth_rate_at(55.75) * 5, 3.0);
}

TEST(Simulate, GzipOutputAndRunsNumbering) {
  TempDir dir;
  const auto f = dir.path() / "rec.csv.gz";
  auto r = run_cli({"simulate", "-o", f.string(), "--duration", "1", "--runs", "3", "--seed", "100", "--arw", "0.01"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (int i = 1; i <= 3; ++i) ASSERT_TRUE(std::filesystem::exists(dir.path() / fmt::format("rec_00{}.csv.gz", i)));
  const std::string t2 = gunzip(dir.path() / "rec_002.csv.gz");
  EXPECT_NE(t2.find("# seed: 101\n"), std::string::npos);
  EXPECT_NE(gunzip(dir.path() / "rec_001.csv.gz").substr(t2.find("pulses")), t2.substr(t2.find("pulses")));
  // Existing output without --force: exit 3.
  r = run_cli({"simulate", "-o", (dir.path() / "rec_001.csv.gz").string(), "--duration", "1"});
  EXPECT_EQ(r.status, 3);
}

TEST(Simulate, BadOptionValuesAreUsageErrorsNamingTheOption) {
  TempDir dir;
  const std::string out = (dir.path() / "x.csv").string();
  struct Case {
    std::vector<std::string> extra;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{"--sinusoid", "1"}, "--sinusoid"},
      {{"--sinusoid", "a:b"}, "--sinusoid"},
      {{"--sinusoid", "0:1"}, "--sinusoid"},
      {{"--gauss-markov", "1:0"}, "--gauss-markov"},
      {{"--gauss-markov", "1:2:3"}, "--gauss-markov"},
      {{"--bias-step", "-1:1"}, "--bias-step"},
      {{"--warmup", "1:-2"}, "--warmup"},
      {{"--arw", "-1"}, "--arw"},
      {{"--bias-instability", "-0.1"}, "--bias-instability"},
      {{"--rrw", "-1"}, "--rrw"},
      {{"--lowpass", "-1"}, "--lowpass"},
      {{"--latitude", "95"}, "--latitude"},
      {{"--duration", "0"}, "--duration"},
      {{"--rate", "-4"}, "--rate"},
      {{"--scale", "0"}, "--scale"},
      {{"--runs", "0"}, "--runs"},
      {{"--temp-bias", "0.1"}, "--temp-profile"},
      {{"--temp-bias", "0.1", "--temp-profile", "wave:1:2"}, "--temp-profile"},
      {{"--temp-profile", "ramp:1:2"}, "--temp-bias"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {"simulate", "-o", out};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 2) << c.extra.front();
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

TEST(Simulate, FromAnalysisJsonTakesFitAndRecordSettings) {
  TempDir dir;
  nlohmann::json j = {{"schema_version", json_input::kResultSchemaVersion},
                      {"samples", 4000},
                      {"rate_hz", 200.0},
                      {"duration_s", 20.0},
                      {"temperature_c", -25.0},
                      {"mean_rate", 13.0},
                      {"earth_rate", 12.43},
                      {"fit",
                       {{"Q", {{"value", 0.5}}},
                        {"N", {{"value", 0.001}}},
                        {"B", {{"value", 0.008}}},
                        {"K", {{"value", 0.0}, {"resolved", false}}},
                        {"R", nullptr}}}};
  SimulationSettings s;
  const NoiseModel m = model_from_analysis_json(j, "a.json", s);
  EXPECT_DOUBLE_EQ(m.arw_deg_per_sqrt_h, 0.001);
  EXPECT_DOUBLE_EQ(m.bias_instability_deg_per_h, 0.008);
  EXPECT_DOUBLE_EQ(m.earth_rate_deg_per_h, 12.43);
  EXPECT_NEAR(m.bias_deg_per_h, 0.57, 1e-12);
  EXPECT_EQ(m.readout, ReadoutMode::White);
  // Total white angle noise equals the fitted Q.
  EXPECT_NEAR(m.white_angle_arcsec * m.white_angle_arcsec + 0.92 * 0.92 / 6, 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(s.rate_hz, 200.0);
  EXPECT_DOUBLE_EQ(s.duration_s, 20.0);
  EXPECT_EQ(s.temperature_c, -25.0);

  // Diagnose output: the extended model with its findings.
  nlohmann::json d = {{"schema_version", json_input::kResultSchemaVersion},
                      {"base_model", j},
                      {"extended_model", j},
                      {"findings", nlohmann::json::array()}};
  d["extended_model"]["terms"] = {{{"effect", "sinusoid"}, {"frequency_hz", 0.0125}, {"amplitude_deg_per_h", 0.03}},
                                  {{"effect", "bias_step"}, {"time_s", 5.0}, {"size_deg_per_h", -0.01}}};
  const NoiseModel e = model_from_analysis_json(d, "d.json", s);
  ASSERT_EQ(e.sinusoids.size(), 1u);
  EXPECT_DOUBLE_EQ(e.sinusoids[0].f_hz, 0.0125);
  ASSERT_EQ(e.bias_steps.size(), 1u);
  EXPECT_DOUBLE_EQ(e.bias_steps[0].size_deg_per_h, -0.01);

  // Through the CLI: the record takes the analysis' rate and duration.
  const auto path = dir.write("analysis.json", j.dump());
  const auto out = dir.path() / "sim.csv";
  auto r = run_cli({"simulate", "--from", path.string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = slurp(out);
  EXPECT_NE(text.find("# rate_hz: 200\n"), std::string::npos);
  EXPECT_NE(text.find("# samples: 4000\n"), std::string::npos);
  EXPECT_NE(text.find("# temperature_c: -25\n"), std::string::npos);
  // A broken JSON file is an input error naming the file.
  const auto bad = dir.write("bad.json", "{\"fit\": ");
  r = run_cli({"simulate", "--from", bad.string(), "-o", (dir.path() / "y.csv").string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos);
}

TEST(Simulate, ModelJsonRoundTrips) {
  const NoiseModel m = all_terms();
  nlohmann::json j = m;
  const NoiseModel back = j.get<NoiseModel>();
  EXPECT_EQ(nlohmann::json(back), j);
  EXPECT_EQ(back.sinusoids.size(), 1u);
  EXPECT_DOUBLE_EQ(back.gauss_markov[0].tc_s, 2.0);
  ASSERT_TRUE(back.temperature_bias);
  EXPECT_DOUBLE_EQ(back.temperature_bias->profile.period_s, 1.5);
  EXPECT_THROW(add_finding({{"effect", "gremlin"}}, const_cast<NoiseModel&>(back)), UsageError);
}

TEST(Simulate, EarthRateMeanFromLatitude) {
  EXPECT_NEAR(earth_rate_at(55.75), 12.4328, 1e-4);  // Moscow, °/h
  NoiseModel m;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  SimulationSettings s;  // GL-2D: 0.92″ pulses
  s.duration_s = 100;
  const auto p = simulate(m, s);
  // The counted angle is within one pulse of the true one.
  EXPECT_NEAR(p.at(p.points() - 1), m.earth_rate_deg_per_h * 100, 0.92);
}

TEST(Simulate, BiasStepAppearsAtItsTimeWithItsSize) {
  NoiseModel m;
  m.bias_deg_per_h = 10;
  m.bias_steps.push_back({30.0, 0.25});
  const auto p = simulate(m, fine(60));  // 100 Hz: the step is at sample 3000
  EXPECT_NEAR(block_mean(p, 0, 3000), 10.0, 1e-6);
  EXPECT_NEAR(block_mean(p, 3000, 6000), 10.25, 1e-6);
  EXPECT_NEAR(block_mean(p, 2990, 3000), 10.0, 1e-4);
  EXPECT_NEAR(block_mean(p, 3000, 3010), 10.25, 1e-4);
  // A step inside a sample adds its share of that sample.
  m.bias_steps[0].t_s = 30.004;
  const auto q = simulate(m, fine(60));
  EXPECT_NEAR(q.rate(3000), 10.0 + 0.25 * 0.6, 1e-2);
}

TEST(Simulate, WarmupDecaysExponentially) {
  NoiseModel m;
  m.warmups.push_back({5.0, 20.0});
  const auto p = simulate(m, fine(100));
  for (double t : {0.5, 10.0, 20.0, 40.0, 80.0}) {
    const auto k = static_cast<std::size_t>(t * 100);
    // The 1-s block mean of A·e^{−t/Tc} over [t, t+1).
    const double expected = 5.0 * 20.0 * (std::exp(-t / 20.0) - std::exp(-(t + 1) / 20.0));
    EXPECT_NEAR(block_mean(p, k, k + 100), expected, 1e-6) << t;
  }
}

// Least-squares fit of a + c·cos(ωt) + s·sin(ωt) to the rate samples from sample `from`.
struct SineFit {
  double amp, phase;
};
SineFit fit_sine(const PhaseSeries& p, double f, std::size_t from) {
  // Sample k is the mean rate over [kτ0, (k+1)τ0]; fit at the mid time with the sinc factor.
  double m[3][3] = {}, v[3] = {};
  const double w = 2 * kPi * f, tau0 = p.tau0_s;
  for (std::size_t k = from; k + 1 < p.points(); ++k) {
    const double t = (static_cast<double>(k) + 0.5) * tau0;
    const double b[3] = {1.0, std::cos(w * t), std::sin(w * t)};
    const double y = p.rate(k);
    for (int i = 0; i < 3; ++i) {
      v[i] += b[i] * y;
      for (int j = 0; j < 3; ++j) m[i][j] += b[i] * b[j];
    }
  }
  // Solve by Cramer's rule (3×3).
  auto det = [](double a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  double x[3];
  const double d = det(m);
  for (int c = 0; c < 3; ++c) {
    double t[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) t[i][j] = j == c ? v[i] : m[i][j];
    x[c] = det(t) / d;
  }
  const double sinc = std::sin(w * tau0 / 2) / (w * tau0 / 2);  // sample means attenuate slightly
  // rate ≈ A·cos(ωt + φ) = A cosφ cos ωt − A sinφ sin ωt
  return {std::hypot(x[1], x[2]) / sinc, std::atan2(-x[2], x[1])};
}

TEST(Simulate, SinusoidHasItsFrequencyAmplitudeAndPhase) {
  NoiseModel m;
  m.sinusoids.push_back({0.7, 3.0, 0.4});
  const auto p = simulate(m, fine(60));
  const auto fit = fit_sine(p, 0.7, 0);
  EXPECT_NEAR(fit.amp, 3.0, 1e-4);
  EXPECT_NEAR(fit.phase, 0.4, 1e-4);
  // At a wrong frequency the fit finds (almost) nothing.
  EXPECT_LT(fit_sine(p, 0.9, 0).amp, 0.2);
}

TEST(Simulate, LowpassAttenuatesAndDelaysASinusoid) {
  for (const double tf : {0.05, 0.3}) {
    NoiseModel m;
    m.sinusoids.push_back({1.0, 3.0, 0.0});
    m.lowpass_tc_s = tf;
    const auto p = simulate(m, fine(40, 400.0));
    const auto fit = fit_sine(p, 1.0, static_cast<std::size_t>(10 * tf * 400) + 400);
    const double wt = 2 * kPi * 1.0 * tf;
    EXPECT_NEAR(fit.amp, 3.0 / std::sqrt(1 + wt * wt), 2e-3 * 3.0) << tf;
    EXPECT_NEAR(fit.phase, -std::atan(wt), 2e-3) << tf;
  }
}

TEST(Simulate, TemperatureRampGivesALinearBias) {
  NoiseModel m;
  m.temperature_bias = TemperatureBias{0.01, {TemperatureProfile::Kind::Ramp, -10.0, 30.0, 0, 0}};
  auto s = fine(100);
  s.temperature_c = 10.0;  // nominal: bias 0 at mid-record
  const auto p = simulate(m, s);
  EXPECT_NEAR(block_mean(p, 0, 100), 0.01 * (-10.0 + 0.2 - 10.0), 1e-6);
  EXPECT_NEAR(block_mean(p, 4950, 5050), 0.0, 1e-6);
  EXPECT_NEAR(block_mean(p, 9900, 10000), 0.01 * (30.0 - 0.2 - 10.0), 1e-6);
}

TEST(Simulate, CountsStayExactOverLongRecords) {
  // A fast rate over 10^7 samples: the count must equal floor(θ/q + phase), no drift.
  NoiseModel m;
  m.bias_deg_per_h = 1000.0;
  SimulationSettings s;
  s.rate_hz = 1000;
  s.duration_s = 10000;
  s.scale_arcsec = 0.37;
  const auto p = simulate(m, s);
  const double theta = 1000.0 * 10000.0;  // ″
  EXPECT_LE(std::abs(p.at(p.points() - 1) - theta), 0.37);
}

TEST(Simulate, TheoreticalFlickerMatchesTheSmallLagTable) {
  const double floor = 2 * 0.01 * 0.01 * std::numbers::ln2 / kPi;
  EXPECT_NEAR(flicker_avar(0.01, 1), 2 * 0.01 * 0.01 / kPi, 1e-12);
  const std::pair<int, double> table[] = {{2, 1.1542}, {3, 1.0804},  {4, 1.0500},
                                          {8, 1.0154}, {16, 1.0046}, {64, 1.00038}};
  for (auto [m, ratio] : table) EXPECT_NEAR(flicker_avar(0.01, m) / floor, ratio, 1e-4) << m;
}

TEST(Simulate, ValidateRejectsBadModels) {
  NoiseModel m;
  SimulationSettings s;
  m.gauss_markov.push_back({1.0, 0.0});
  EXPECT_THROW(validate(m, s), UsageError);
  m = {};
  m.arw_deg_per_sqrt_h = std::nan("");
  EXPECT_THROW(validate(m, s), UsageError);
  m = {};
  s.duration_s = 0.001;
  EXPECT_THROW(validate(m, s), UsageError);
}

}  // namespace
