// The counter read-out's Allan variance (counter_readout.hpp): known answers of the sawtooth's
// covariance, the exact AV of a noiseless counter against a direct computation from counted pulses,
// and the analysis of simulate's default output (a plain counter) end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "rwcalc/counter_readout.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

TEST(CounterReadout, SawtoothCovarianceKnownAnswers) {
  // No jitter: (y² − y + 1/6)/2; R(0) = 1/12, at half a pulse −1/24.
  EXPECT_NEAR(sawtooth_covariance(0.0, 0.0), 1.0 / 12.0, 1e-15);
  EXPECT_NEAR(sawtooth_covariance(0.5, 0.0), -1.0 / 24.0, 1e-15);
  EXPECT_NEAR(sawtooth_covariance(2.25, 0.0), 0.5 * (0.0625 - 0.25 + 1.0 / 6.0), 1e-15);
  // Large jitter: white; at s = 0.6 only the first harmonic is left (the second is damped by 10⁻¹²).
  EXPECT_NEAR(sawtooth_covariance(0.3, 2.0), 0.0, 1e-30);
  const double s = 0.6, damp = std::exp(-2.0 * M_PI * M_PI * s * s);
  EXPECT_NEAR(sawtooth_covariance(0.0, s), damp / (2.0 * M_PI * M_PI), 1e-14);
  // The closed form (s ≤ 0.15) and the Fourier series (beyond) meet at the switch.
  for (const double x : {0.0, 0.1, 0.37, 0.5, 0.81})
    EXPECT_NEAR(sawtooth_covariance(x, 0.15), sawtooth_covariance(x, 0.15 + 1e-12), 1e-12) << x;
  // Symmetric in the advance.
  EXPECT_NEAR(sawtooth_covariance(0.2, 0.05), sawtooth_covariance(-0.2, 0.05), 1e-15);
}

/// Overlapping AV, (″/s)², of exact counts ⌊r·k + φ⌋·q at cluster size m.
double counted_avar(double r, double phase, double q, double tau0, std::int64_t m, std::int64_t n) {
  auto c = [&](std::int64_t k) { return std::floor(r * static_cast<double>(k) + phase); };
  double sum = 0;
  for (std::int64_t k = 0; k + 2 * m <= n; ++k) {
    const double d = c(k + 2 * m) - 2 * c(k + m) + c(k);
    sum += d * d;
  }
  const double tau = static_cast<double>(m) * tau0;
  return q * q * sum / (2.0 * tau * tau * static_cast<double>(n - 2 * m + 1));
}

TEST(CounterReadout, NoiselessCounterMatchesItsCountedPulses) {
  // An irrational rate sweeps the phase evenly: the time average is the model's expectation.
  const CounterReadout c{std::sqrt(2.0) / 40.0, 0.92, 0.0025, 400001};
  for (const std::int64_t m : {1, 3, 16, 29, 100, 1000}) {
    const double model = counter_avar(c, m, {});
    const double counted = counted_avar(c.pulses_per_sample, 0.3, c.q_arcsec, c.tau0_s, m, 400000);
    EXPECT_NEAR(counted / model, 1.0, 2e-3) << m;
  }
  // q²/τ²·dist(r·m, ℤ): zero where m samples advance a whole number of pulses.
  const CounterReadout whole{0.25, 0.92, 0.0025, 100001};
  EXPECT_NEAR(counter_avar(whole, 4, {}), 0.0, 1e-12);
  EXPECT_NEAR(counter_avar(whole, 2, {}), 0.92 * 0.92 * 0.5 / (0.005 * 0.005), 1e-6);
  // Jitter far beyond a pulse: the white line q²/(4τ²), Q = q/√12.
  const AngleJitter loud{4.0, 0, 0};
  EXPECT_NEAR(counter_avar(c, 10, loud), 0.92 * 0.92 / (4.0 * 0.025 * 0.025), 1e-9);
  // The increments' part: 2q²[R(0) − R(h)], twice the white level when R(h) = 0.
  EXPECT_NEAR(counter_increment_var(c, 10, loud), 2.0 * 0.92 * 0.92 / 12.0, 1e-12);
}

TEST(CounterReadout, SimulateDefaultOutputIsFittedWithTheCounter) {
  const test::TempDir dir;
  const std::string path = (dir.path() / "c.csv").string();
  ASSERT_EQ(test::run_cli({"simulate", "-o", path, "--duration", "1800", "--arw", "0.0009", "--bias-instability",
                           "0.006", "--seed", "3"})
                .status,
            0);
  const auto r = test::run_cli({"analyze", "--json", path});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("fit").at("readout"), "counter");
  EXPECT_GE(j.at("fit").at("p_value").get<double>(), 0.001);
  const auto& n = j.at("fit").at("N");
  EXPECT_LE(n.at("low95").get<double>(), 0.0009);
  EXPECT_GE(n.at("high95").get<double>(), 0.0009);
  // The white model alone, asked for, is rejected on the same record.
  const auto w = test::run_cli({"analyze", "--json", "--readout", "white", path});
  ASSERT_EQ(w.status, 0) << w.err;
  const auto jw = nlohmann::json::parse(w.out);
  EXPECT_EQ(jw.at("fit").at("readout"), "white");
  EXPECT_LT(jw.at("fit").at("p_value").get<double>(), 0.001);
  const auto t = test::run_cli({"analyze", path});
  EXPECT_NE(t.out.find("read-out: a plain counter"), std::string::npos);
}

TEST(CounterReadout, AnUnknownReadoutIsAUsageError) {
  const auto r = test::run_cli({"analyze", "--readout", "sawtooth", "x.csv"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--readout"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rwcalc
