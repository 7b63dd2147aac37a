// A simulated six-axis IMU with known truth through `rwcalc imu`: every coefficient the fit resolves
// (its 95 % interval above 0) must hold the truth in at least 90 % of the seeded cases, for each
// term and sensor kind (with every term kept; the default term selection is measured beside it). Each axis is an exact
// simulator record (white noise N, flicker B, rate or acceleration random walk K, a fine white read-out) written as a
// rate column: gyros in deg/s, accelerometers in m/s^2 (the simulated angle in ″ read as velocity in 1/3600 m/s,
// units.hpp). 12 cases, 50 under RWCALC_ACCEPTANCE=1 (tests/support/population.hpp), whose figures
// docs/imu.md quotes; RWCALC_IMU_COVERAGE_CASES sets the count.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>

#include "population.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace rwcalc::test {
namespace {

constexpr double kRateHz = 10, kDurationS = 14400, kScale = 0.001;

struct Truth {
  double n, b, k;  // fit-scale units: °/√h, °/h, °/h/√h (gyro); m/s/√h, m/s/h, m/s/h/√h (accelerometer)
};
// Each term owns a stretch of τ in the 4-h record, so that every one is resolved in most cases (a
// term near its detection limit is resolved only when its estimate happens to be high, and the
// coverage of such a selection is below the nominal level):
// gyro: ARW 0.15 °/√h, B 3 °/h, K 8 °/h/√h (white to flicker near 20 s, flicker to K near 670 s);
// accelerometer: VRW 0.025 m/s/√h, B 0.7 m/s/h (≈ 20 µg), K 2 m/s/h/√h (10 s and 580 s).
constexpr Truth kGyro{0.15, 3.0, 8.0}, kAccel{0.025, 0.7, 2.0};

PhaseSeries axis(const Truth& t, std::uint64_t seed) {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = t.n;
  m.bias_instability_deg_per_h = t.b;
  m.rrw_deg_per_h_per_sqrt_h = t.k;
  m.readout = ReadoutMode::White;
  SimulationSettings s;
  s.duration_s = kDurationS;
  s.rate_hz = kRateHz;
  s.scale_arcsec = kScale;
  s.seed = seed;
  return simulate(m, s);
}

// Six columns: three gyro axes in deg/s, three accelerometer axes in m/s² (rates from the phase
// increments: ″/s = °/h → /3600 for °/s; (1/3600 m/s)/s = m/s/h → /3600 for m/s²).
std::string imu_file(std::uint64_t seed) {
  std::array<PhaseSeries, 6> ax;
  for (std::size_t i = 0; i < 6; ++i) ax[i] = axis(i < 3 ? kGyro : kAccel, seed * 16 + i);
  std::string s = "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_mps2,acc_y_mps2,acc_z_mps2\n";
  const std::size_t n = ax[0].points() - 1;
  s.reserve(n * 100);
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < 6; ++i)
      fmt::format_to(std::back_inserter(s), "{}{:.10g}", i ? "," : "", ax[i].rate(k) / 3600.0);
    s += '\n';
  }
  return s;
}

constexpr int kAcceptanceCases = 50;

int cases() { return population("RWCALC_IMU_COVERAGE_CASES", 12, kAcceptanceCases, 10); }

// Resolved cases and how many of them hold the truth, per "kind term"; with each term's median
// estimate/truth among them.
struct Tally {
  std::map<std::string, std::pair<int, int>> counts;
  std::map<std::string, std::vector<double>> ratio;
};

Tally run_cases(int n_cases, const std::vector<std::string>& extra) {
  Tally t;
  for (int c = 0; c < n_cases; ++c) {
    TempDir dir;
    const auto f = dir.write("imu.csv", imu_file(1000 + c));
    std::vector<std::string> args{"imu",     f.string(), "--rate", fmt::format("{:g}", kRateHz), "--gyro", "1,2,3",
                                  "--accel", "4,5,6",    "--json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 0) << r.err;
    if (r.status != 0) return t;
    const auto j = nlohmann::json::parse(r.out);
    for (std::size_t i = 0; i < 6; ++i) {
      const auto& ch = j["channels"][i];
      const Truth& truth = i < 3 ? kGyro : kAccel;
      // The JSON shows °/√h, °/h, °/h/√h for gyros; m/s/√h, µg, m/s/h/√h for accelerometers.
      const double b_factor = i < 3 ? 1.0 : 1e6 / 3600 / 9.80665;
      for (const auto& [term, value] :
           {std::pair{"N", truth.n}, std::pair{"B", truth.b * b_factor}, std::pair{"K", truth.k}}) {
        const auto& co = ch["fit"][term];
        if (!co["resolved"].get<bool>()) continue;
        const std::string name = fmt::format("{} {}", ch["sensor"].get<std::string>(), term);
        auto& [resolved, inside] = t.counts[name];
        ++resolved;
        if (co["low95"].get<double>() <= value && value <= co["high95"].get<double>()) ++inside;
        t.ratio[name].push_back(co["value"].get<double>() / value);
      }
    }
  }
  return t;
}

double coverage_of(Tally& t, const std::string& name, int n_cases, const char* label) {
  const auto [resolved, inside] = t.counts[name];
  auto& q = t.ratio[name];
  std::sort(q.begin(), q.end());
  const double coverage = resolved ? static_cast<double>(inside) / resolved : 0.0;
  std::cout << fmt::format(
      "{:<10} {:<16} resolved in {:3} of {} axis-cases, truth inside {:.3f}; median "
      "estimate/truth {:.3f}\n",
      label, name, resolved, 3 * n_cases, coverage, q.empty() ? 0.0 : q[q.size() / 2]);
  return coverage;
}

/// A coverage bound at the acceptance's 3 × 50 axis-cases, widened for fewer resolved ones.
double bound(double at_acceptance, Tally& t, const std::string& name) {
  return at_acceptance - share_allowance(at_acceptance, t.counts[name].first, 3 * kAcceptanceCases);
}

// Every term kept (--all-terms): each resolved coefficient holds the truth in ≥ 90 % of the cases.
TEST(ImuCoverage, ResolvedCoefficientsHoldTheTruthInTheirIntervals) {
  const int n = cases();
  Tally t = run_cases(n, {"--all-terms"});
  for (const char* name : {"gyro N", "gyro B", "gyro K", "accelerometer N", "accelerometer B", "accelerometer K"}) {
    const double coverage = coverage_of(t, name, n, "all-terms");
    if (t.counts[name].first >= 20) {
      EXPECT_GE(coverage, bound(0.90, t, name)) << name;
    }
  }
  for (const char* must : {"gyro N", "gyro B", "accelerometer N", "accelerometer B"})
    EXPECT_GE(t.counts[must].first, 3 * n / 2) << must << " resolved too rarely to test";
}

// The default term selection drops K where it lowers the deviance too little, and Q where the
// read-out is fine; B then takes up part of K's variance and N's interval shrinks with Q's (measured
// 0.885 for gyro B and 0.878 for accelerometer N, docs/imu.md). The bounds hold that state (N and K
// ≥ 0.85, B ≥ 0.80) so that a further loss shows; the nominal 0.90 is asserted with every term kept.
TEST(ImuCoverage, DefaultTermSelection) {
  const int n = cases();
  Tally t = run_cases(n, {});
  for (const char* name : {"gyro N", "gyro K", "accelerometer N", "accelerometer K"}) {
    const double coverage = coverage_of(t, name, n, "default");
    if (t.counts[name].first >= 20) {
      EXPECT_GE(coverage, bound(0.85, t, name)) << name;
    }
  }
  for (const char* name : {"gyro B", "accelerometer B"})
    EXPECT_GE(coverage_of(t, name, n, "default"), bound(0.80, t, name)) << name;
}

}  // namespace
}  // namespace rwcalc::test
