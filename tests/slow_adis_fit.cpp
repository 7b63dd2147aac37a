// The shipped ADIS16405 runs (../shared/data/real/imudata_adis16405, docs/adis16405.md): on every run
// and gyro axis, analyze's fit (its range chosen by the short-τ check) gives N within 3 % of an
// independent white level, a Welch estimate of the one-sided rate PSD between 1 and 5 Hz computed here
// (N = √(S/2), S in (°/h)²/Hz: 2.417, 2.546, 2.275 °/√h for run 1 X, Y, Z, as numpy gives), with
// χ²/dof ≤ 3 and the range and its reason stated.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace rwcalc {
namespace {

using nlohmann::json;
using namespace rwcalc::test;

/// The three gyro columns (°/s) of a run, as °/h.
std::array<std::vector<double>, 3> gyro_rates(const std::filesystem::path& path) {
  std::array<std::vector<double>, 3> out;
  std::istringstream in(gunzip(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'g') continue;
    std::size_t at = 0;
    for (auto& col : out) {
      const std::size_t comma = line.find(',', at);
      col.push_back(std::stod(line.substr(at, comma - at)) * 3600.0);
      at = comma + 1;
    }
  }
  return out;
}

/// Welch: Hann windows of 1024 samples, half overlapping, each segment's mean removed; the one-sided
/// PSD (°/h)²/Hz averaged over the bins from 1 to 5 Hz, as a white level N = √(S/2)/60 °/√h.
double welch_white_level(const std::vector<double>& y, double fs) {
  constexpr std::size_t kLen = 1024;
  std::vector<double> w(kLen);
  double w2 = 0;
  for (std::size_t i = 0; i < kLen; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(kLen - 1));
    w2 += w[i] * w[i];
  }
  const auto k_lo = static_cast<std::size_t>(std::ceil(1.0 * kLen / fs));
  const auto k_hi = static_cast<std::size_t>(std::floor(5.0 * kLen / fs));
  std::vector<double> cosv(kLen), sinv(kLen), seg(kLen);
  for (std::size_t i = 0; i < kLen; ++i) {
    cosv[i] = std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / kLen);
    sinv[i] = std::sin(2.0 * std::numbers::pi * static_cast<double>(i) / kLen);
  }
  double sum = 0;
  std::size_t segments = 0;
  for (std::size_t start = 0; start + kLen <= y.size(); start += kLen / 2, ++segments) {
    double mean = 0;
    for (std::size_t i = 0; i < kLen; ++i) mean += y[start + i];
    mean /= kLen;
    for (std::size_t i = 0; i < kLen; ++i) seg[i] = (y[start + i] - mean) * w[i];
    for (std::size_t k = k_lo; k <= k_hi; ++k) {
      double re = 0, im = 0;
      for (std::size_t i = 0; i < kLen; ++i) {
        re += seg[i] * cosv[k * i % kLen];
        im -= seg[i] * sinv[k * i % kLen];
      }
      sum += (re * re + im * im) * 2.0 / (fs * w2);
    }
  }
  const double s = sum / static_cast<double>(segments * (k_hi - k_lo + 1));
  return std::sqrt(s / 2.0) / 60.0;
}

TEST(SlowAdis, FitMatchesTheWelchWhiteLevelOnEveryRunAndAxis) {
  const auto first = shared_data("real/imudata_adis16405/adis_16405_imu1.csv.gz");
  RWCALC_REQUIRE_SHARED(first);
  for (int run = 1; run <= 4; ++run) {
    const auto path = shared_data(fmt::format("real/imudata_adis16405/adis_16405_imu{}.csv.gz", run));
    const auto rates = gyro_rates(path);
    for (int axis = 0; axis < 3; ++axis) {
      const std::string column = std::string("gyro_") + "xyz"[axis] + "_dps";
      const auto r = run_cli({"analyze", path.string(), "--input", "rate", "--rate-unit", "deg/s", "--rate", "100",
                              "--column", column, "--earth-rate", "0", "--json"});
      ASSERT_EQ(r.status, 0) << r.err;
      const json j = json::parse(r.out);
      const double n = j["fit"]["N"]["value"].get<double>();
      const double welch = welch_white_level(rates[static_cast<std::size_t>(axis)], 100.0);
      const double chi2 = j["fit"]["chi2_per_dof"].get<double>();
      std::printf("run %d %s: N %.4f, Welch %.4f (%+.2f %%), chi2/dof %.2f, fit from %g s (%s)\n", run, column.c_str(),
                  n, welch, 100.0 * (n / welch - 1.0), chi2, j["fit"]["tau_min_s"].get<double>(),
                  j["fit"]["range"]["chosen_by"].get<std::string>().c_str());
      EXPECT_NEAR(n / welch, 1.0, 0.03) << run << column;
      EXPECT_LE(chi2, 3.0) << run << column;
      EXPECT_EQ(j["fit"]["range"]["chosen_by"], "short_tau_check") << run << column;
      EXPECT_FALSE(j["warnings"].empty()) << run << column;
      if (run == 1 && axis == 0) {
        EXPECT_NEAR(welch, 2.4174, 0.0005);  // numpy's figure, quoted above
      }
    }
  }
}

}  // namespace
}  // namespace rwcalc
