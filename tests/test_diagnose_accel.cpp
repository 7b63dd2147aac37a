// `rwcalc diagnose` on an accelerometer column, end to end: exact simulator records written as
// acceleration in m/s² (the simulated angle in ″ read as a velocity in 1/3600 m/s, units.hpp), one
// with a known sinusoid (named, its amplitude in µg within its uncertainty) and one clean (nothing
// named); the report and the JSON state the column, the sensor kind and the units, and give no
// Earth rate or class.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>

#include "rwcalc/normal_quantile.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/units.hpp"
#include "test_support.hpp"

using nlohmann::json;
using rwcalc::test::run_cli;
using rwcalc::test::TempDir;

namespace {

// 30 min at 100 Hz: VRW 0.02 m/s/√h, B 0.5 m/s/h (≈ 14 µg), a fine white read-out.
constexpr double kMicroGPerMpsH = 1e6 / 3600.0 / rwcalc::units::standard_gravity;  // m/s/h → µg
constexpr double kSinAmp = 3.0;                                                    // m/s/h (≈ 85 µg)
constexpr double kSinHz = 0.05;

/// One accelerometer column (time, acc_x in m/s²) of a simulated record.
std::string accel_csv(bool with_sinusoid, std::uint64_t seed) {
  rwcalc::NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.02;
  m.bias_instability_deg_per_h = 0.5;
  m.readout = rwcalc::ReadoutMode::White;
  if (with_sinusoid) m.sinusoids.push_back({kSinHz, kSinAmp, 0.3});
  rwcalc::SimulationSettings s;
  s.duration_s = 1800;
  s.rate_hz = 100;
  s.scale_arcsec = 0.001;
  s.seed = seed;
  const rwcalc::PhaseSeries x = rwcalc::simulate(m, s);
  std::string out = "time_s,acc_x_mps2\n";
  for (std::size_t k = 0; k + 1 < x.points(); ++k)
    fmt::format_to(std::back_inserter(out), "{:.2f},{:.10g}\n", static_cast<double>(k) / s.rate_hz,
                   rwcalc::units::standard_gravity + x.rate(k) / 3600.0);  // + 1 g of gravity's projection
  return out;
}

/// `rwcalc diagnose --json` of a simulated accelerometer record (the file in a temporary folder).
json diagnose_record(bool with_sinusoid, std::uint64_t seed) {
  TempDir dir;
  const auto f = dir.write("acc.csv", accel_csv(with_sinusoid, seed)).string();
  const auto r = run_cli({"diagnose", f, "--json", "--runs", "12", "--seed", "3"});
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? json::parse(r.out) : json();
}

}  // namespace

TEST(DiagnoseAccelerometer, NamesTheSinusoidInAccelerometerUnits) {
  const json j = diagnose_record(true, 21);
  ASSERT_FALSE(j.is_null());
  EXPECT_EQ(j["sensor"], "accelerometer");
  EXPECT_EQ(j["column"], "acc_x_mps2");
  EXPECT_EQ(j["input_unit"], "m/s^2");
  EXPECT_EQ(j["units"]["level"], "ug");
  EXPECT_FALSE(j.contains("scale_arcsec_per_pulse"));
  EXPECT_DOUBLE_EQ(j["base_model"]["earth_rate_deg_per_h"].get<double>(), 0.0);
  ASSERT_EQ(j["findings"].size(), 1u) << j["findings"].dump();
  const auto& s = j["findings"][0];
  EXPECT_EQ(s["effect"], "sinusoid");
  // The same keys as a gyro's finding, the unit a field: µg for the accelerometer's amplitude.
  const auto& sp = s["parameters"];
  EXPECT_NEAR(sp["frequency"]["value"].get<double>(), kSinHz, 1e-3);
  EXPECT_EQ(sp["amplitude"]["unit"], "ug") << s.dump();
  const double amp = sp["amplitude"]["value"].get<double>(),
               sigma = sp["amplitude"]["standard_uncertainty"].get<double>();
  EXPECT_NEAR(sp["amplitude"]["interval95"][1].get<double>(), amp + rwcalc::kZ95 * sigma, 1e-9 * amp);
  EXPECT_GT(sigma, 0.0);
  EXPECT_LT(std::abs(amp - kSinAmp * kMicroGPerMpsH), std::max(4 * sigma, 0.1 * kSinAmp * kMicroGPerMpsH))
      << amp << " ± " << sigma << " µg";
  // The base model's B in µg beside the fit-scale one, and the band in µg.
  const double b_fit = j["base_model"]["bias_instability_deg_per_h"].get<double>();
  EXPECT_NEAR(j["base_model"]["coefficients"]["B_ug"].get<double>(), b_fit * kMicroGPerMpsH, 1e-9 * b_fit);
  ASSERT_TRUE(j["bias_instability_named_terms"].contains("with_ug"));
  const auto& band0 = j["base_model"]["band"][0];
  EXPECT_GT(band0["dev"].get<double>(), 0.0);
}

TEST(DiagnoseAccelerometer, CleanRecordHasNoFinding) {
  const json j = diagnose_record(false, 22);
  ASSERT_FALSE(j.is_null());
  EXPECT_EQ(j["sensor"], "accelerometer");
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump();
  // B within a factor of 2 of the truth (0.5 m/s/h ≈ 14 µg) in the base model.
  const double b = j["base_model"]["coefficients"]["B_ug"].get<double>();
  EXPECT_GT(b, 0.5 * 0.5 * kMicroGPerMpsH);
  EXPECT_LT(b, 2.0 * 0.5 * kMicroGPerMpsH);
}

TEST(DiagnoseAccelerometer, ReportStatesColumnKindAndUnits) {
  TempDir dir;
  const auto f = dir.write("acc.csv", accel_csv(true, 21)).string();
  const auto r = run_cli({"diagnose", f, "--runs", "12", "--seed", "3"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* want : {"column 'acc_x_mps2' of an accelerometer read in m/s^2", "levels in µg",
                           "amplitude = ", "µg;", "m/s/√h", "white velocity", "no Earth rate"})
    EXPECT_NE(r.out.find(want), std::string::npos) << want << "\n" << r.out;
  for (const char* never : {"°/h", "Earth rate 0", "pulse weight", "″"})
    EXPECT_EQ(r.out.find(never), std::string::npos) << never << "\n" << r.out;
}
