// `rwcalc simulate --layout imu`: a six-axis MEMS-like IMU record (rwcalc/imu_simulate.hpp) — its
// layout, whole output steps, reproducibility, the truth `rwcalc imu` finds in it, its errors — and
// the `imu` figure's fitted model per axis.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "rwcalc/imu_simulate.hpp"
#include "test_support.hpp"

namespace rwcalc::test {
namespace {

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// The data lines of a record (after the `#` lines and the header), split at commas.
std::vector<std::vector<double>> rows_of(const std::string& text, std::string& header) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.starts_with("#")) continue;
    if (header.empty()) {
      header = line;
      continue;
    }
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) row.push_back(std::stod(f));
    rows.push_back(std::move(row));
  }
  return rows;
}

TEST(SimulateImu, SixColumnsInWholeOutputSteps) {
  TempDir dir;
  const auto f = dir.path() / "imu.csv.gz";
  const auto r = run_cli({"simulate", "--layout", "imu", "--accel-unit", "g", "--rate", "100", "--duration", "60",
                          "--seed", "3", "-o", f.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "six IMU axes, 6000 samples")) << r.out;
  const std::string text = gunzip(f);
  EXPECT_TRUE(has(text, "# rate_hz: 100\n")) << text.substr(0, 400);
  EXPECT_TRUE(has(text, "# acc_z_g: N=0.27 m/s/sqrt(h) B=270 ug K=55 m/s/h/sqrt(h) bias=-1.016 g step=3.33 mg\n"));
  std::string header;
  const auto rows = rows_of(text, header);
  EXPECT_EQ(header, "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_g,acc_y_g,acc_z_g");
  ASSERT_EQ(rows.size(), 6000u);
  constexpr std::array<double, 6> kStep{0.05, 0.05, 0.05, 0.00333, 0.00333, 0.00333};
  std::array<double, 6> mean{};
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(row[i] / kStep[i], std::round(row[i] / kStep[i]), 1e-6) << i;
      mean[i] += row[i] / static_cast<double>(rows.size());
    }
  }
  // The biases of the layout: 0.40, −0.42, −0.29 °/s; −0.007, 0, −1.016 g. The flicker rate starts
  // at a random level of a few B (31 °/h ≈ 0.009 °/s; 270 µg) and the white noise adds 0.005 °/s
  // and 0.05 mg to a 6000-sample mean: within 0.1 °/s and 3 mg.
  EXPECT_NEAR(mean[0], 0.40, 0.1);
  EXPECT_NEAR(mean[1], -0.42, 0.1);
  EXPECT_NEAR(mean[5], -1.016, 3e-3);
  EXPECT_GT(std::abs(mean[5]), 0.9);  // gravity on the Z accelerometer only
  EXPECT_LT(std::abs(mean[3]) + std::abs(mean[4]), 0.02);
  // The same seed gives the same bytes; another seed another record.
  const auto again = dir.path() / "again.csv.gz";
  ASSERT_EQ(run_cli({"simulate", "--layout", "imu", "--accel-unit", "g", "--rate", "100", "--duration", "60", "--seed",
                     "3", "-o", again.string()})
                .status,
            0);
  EXPECT_EQ(gunzip(again), text);
  const auto other = dir.path() / "other.csv.gz";
  ASSERT_EQ(run_cli({"simulate", "--layout", "imu", "--accel-unit", "g", "--rate", "100", "--duration", "60", "--seed",
                     "4", "-o", other.string()})
                .status,
            0);
  EXPECT_NE(gunzip(other), text);
}

// Known answer: `rwcalc imu` finds every axis' white noise N (the best-determined term) within 3 %
// of the values given per axis, the accelerometers in m/s² columns.
TEST(SimulateImu, ImuFindsTheGivenNoiseDensities) {
  TempDir dir;
  const auto f = dir.path() / "imu.csv";
  const auto r = run_cli({"simulate", "--layout", "imu", "--rate", "50", "--duration", "1800", "--seed", "11",
                          "--gyro-noise", "1.0:10:50,2.0:10:50,4.0:10:50", "--accel-noise", "0.1:100:20", "--gyro-step",
                          "0.01", "-o", f.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  std::string header;
  (void)rows_of(slurp(f).substr(0, 2000), header);
  EXPECT_EQ(header, "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_mps2,acc_y_mps2,acc_z_mps2");
  const auto imu = run_cli({"imu", f.string(), "--json"});
  ASSERT_EQ(imu.status, 0) << imu.err;
  const auto j = nlohmann::json::parse(imu.out);
  ASSERT_EQ(j["channels"].size(), 6u);
  EXPECT_EQ(j["rate_hz"], 50.0);  // from the record's metadata
  constexpr std::array<double, 6> kN{1.0, 2.0, 4.0, 0.1, 0.1, 0.1};
  for (std::size_t i = 0; i < 6; ++i) {
    const auto& ch = j["channels"][i];
    EXPECT_EQ(ch["sensor"], i < 3 ? "gyro" : "accelerometer");
    EXPECT_NEAR(ch["fit"]["N"]["value"].get<double>() / kN[i], 1.0, 0.03) << ch["column"];
  }
}

TEST(SimulateImu, ErrorsNameTheOption) {
  TempDir dir;
  const auto out = (dir.path() / "x.csv").string();
  const std::vector<std::string> base{"simulate", "-o", out, "--duration", "10", "--rate", "10"};
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases{
      {{"--layout", "imu", "--arw", "1"}, "--arw is an option of the pulse layout"},
      {{"--layout", "imu", "--from", "a.json"}, "--from is an option of the pulse layout"},
      {{"--layout", "imu", "--gyro-noise", "1:2"}, "--gyro-noise: '1:2' is not of the form N:B:K"},
      {{"--layout", "imu", "--accel-noise", "1:2:3,1:2:3"}, "give N:B:K once (every axis) or three times"},
      {{"--layout", "imu", "--gyro-noise", "1:-2:3"}, "--gyro-noise: every term must be >= 0 in '1:-2:3'"},
      {{"--gyro-noise", "1:2:3"}, "need --layout imu"},
      {{"--accel-unit", "g"}, "need --layout imu"},
      {{"--layout", "imu", "--accel-step", "0"}, "--accel-step"},
      {{"--layout", "gyro"}, "--layout"},
  };
  for (const auto& c : cases) {
    const auto r = run_cli(concat(base, c.args));
    EXPECT_EQ(r.status, 2) << c.message;
    EXPECT_TRUE(has(r.err, c.message)) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.message;
  }
}

// The figure draws each axis' fitted model in its own unit: the fit's SI coefficients times
// allan.unit_per_si (°/h per rad/s for a gyro, µg per m/s² for an accelerometer).
TEST(SimulateImu, FigureDrawsEachAxisFittedModel) {
  TempDir dir;
  const auto f = dir.path() / "imu.csv";
  ASSERT_EQ(run_cli(
                {"simulate", "--layout", "imu", "--rate", "20", "--duration", "1200", "--seed", "5", "-o", f.string()})
                .status,
            0);
  const auto script = dir.path() / "imu.gp";
  const auto r = run_cli({"imu", f.string(), "--json", "--plot-script", script.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const std::string gp = slurp(script);
  const double deg_h_per_rad_s = 180.0 / std::numbers::pi * 3600.0;
  const double ug_per_mps2 = 1e6 / 9.80665;
  for (std::size_t i = 0; i < 6; ++i) {
    const auto& ch = j["channels"][i];
    EXPECT_NEAR(ch["allan"]["unit_per_si"].get<double>() / (i < 3 ? deg_h_per_rad_s : ug_per_mps2), 1.0, 1e-12);
    const auto column = ch["column"].get<std::string>();
    EXPECT_TRUE(has(gp, fmt::format("t '{}: fitted model (χ²/dof = ", column))) << column << "\n" << gp;
    // Axis k of its panel (1-based) has the function model_axisk with this axis' curve in SI.
    const std::string fn =
        fmt::format("model_axis{}(t) = {:.10g} * sqrt(", i % 3 + 1, ch["allan"]["unit_per_si"].get<double>());
    EXPECT_TRUE(has(gp, fn)) << fn << "\n" << gp;
    // The fitted curve's N (model_value), not the reported estimate.
    EXPECT_TRUE(has(gp, fmt::format("{:.10g}**2 / t +", ch["fit"]["N"]["si"]["model_value"].get<double>()))) << column;
  }
}

}  // namespace
}  // namespace rwcalc::test
