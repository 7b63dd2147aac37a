// Unit tests of the cross-checks: direct N and the spread of 100-s mean rates.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <nlohmann/json.hpp>

#include "rwcalc/fit.hpp"
#include "rwcalc/methods.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

/// Pure angle random walk N (°/√h) plus a constant rate (°/h), as a floating phase in ″,
/// `seconds` long at `rate_hz`.
PhaseSeries arw(double n, double rate, double seconds, double rate_hz, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  PhaseSeries x;
  x.tau0_s = 1.0 / rate_hz;
  const auto m = static_cast<std::size_t>(seconds * rate_hz);
  x.values.resize(m + 1);
  const double step = 60.0 * n * std::sqrt(x.tau0_s);  // ″ per sample (N_s = 60 N ″/√s)
  double th = 0;
  x.values[0] = 0;
  for (std::size_t k = 1; k <= m; ++k) {
    th += rate * x.tau0_s + step * g(rng);
    x.values[k] = th;
  }
  return x;
}

/// The same, read out as pulse counts of weight q (floor of the cumulative angle).
PhaseSeries quantize(const PhaseSeries& x, double q) {
  PhaseSeries c;
  c.tau0_s = x.tau0_s;
  c.arcsec_per_count = q;
  c.counts.resize(x.values.size());
  for (std::size_t k = 0; k < x.values.size(); ++k)
    c.counts[k] = static_cast<std::int64_t>(std::floor(x.values[k] / q));
  return c;
}

TEST(DirectN, AgreesWithTheTruthOnPureArw) {
  // 30 min at 100 Hz; Earth rate present (removed by the method).
  int inside = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const PhaseSeries x = arw(0.05, 12.43, 1800.0, 100.0, seed);
    const DirectNResult r = direct_n(x);
    ASSERT_TRUE(r.N.valid);
    ASSERT_TRUE(r.N.resolved);
    EXPECT_LT(std::abs(r.N.value - 0.05), 4.0 * r.N.sigma) << seed;
    inside += (r.N.low <= 0.05 && 0.05 <= r.N.high) ? 1 : 0;
    // N is the regression's N″² coefficient.
    EXPECT_NEAR(std::sqrt(r.n2_arcsec2_per_s) / 60.0, r.N.value, 1e-12);
    ASSERT_GE(r.points.size(), 4u);
    EXPECT_TRUE(r.straight.valid);
  }
  EXPECT_GE(inside, 8);
}

TEST(DirectN, WhiteAngleNoiseAndQuantizationGoIntoTheQTerm) {
  // 1″ rms white angle noise (a dither residue) before 0.92″ pulse quantization: the angle
  // variance gains the constant 2(σφ² + q²/12) and N is unchanged.
  const double q = 0.92;
  const double sphi = 1.0;
  PhaseSeries x = arw(0.02, 12.43, 3600.0, 100.0, 42);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (auto& v : x.values) v += sphi * g(rng);
  const DirectNResult r = direct_n(quantize(x, q));
  ASSERT_TRUE(r.N.valid);
  EXPECT_LT(std::abs(r.N.value - 0.02), 4.0 * r.N.sigma);
  EXPECT_NEAR(r.q2_arcsec2, sphi * sphi + q * q / 12.0, 0.1);
}

TEST(DirectN, TooShortIsInvalidNotAnError) {
  const PhaseSeries x = arw(0.05, 0, 20.0, 100.0, 1);
  const DirectNResult r = direct_n(x);
  EXPECT_FALSE(r.N.valid);
}

/// Brute force: E[Σ(Δ_k − Δ̄)²]/(M − 1) from the O(M²) double sum of increment covariances
/// −½ Σ a_i b_j D(i − j) over the generalized structure function D.
IncrementBasis brute_force_basis(std::size_t t, std::size_t points, double step, bool overlapping) {
  const std::size_t n = points - 1;
  const std::size_t stride = overlapping ? 1 : t;
  const std::size_t m = overlapping ? n - t + 1 : n / t;
  auto d = [&](double u, int term) {
    u = std::abs(u) * step;
    if (u == 0) return 0.0;
    return term == 0 ? 2.0 : term == 1 ? u : -u * u * std::log(u) / std::numbers::pi;
  };
  // Cov(Δ_k, Δ_l) with Δ_k = θ(k·stride + t) − θ(k·stride).
  auto cov = [&](std::size_t k, std::size_t l, int term) {
    const double a = static_cast<double>(k * stride), b = static_cast<double>(l * stride), td = static_cast<double>(t);
    return 0.5 * (d(a + td - b, term) + d(a - b - td, term) - d(a - b, term) - d(a - b, term));
  };
  std::array<double, 3> e{};
  for (int term = 0; term < 3; ++term) {
    double diag = 0, all = 0;
    for (std::size_t k = 0; k < m; ++k)
      for (std::size_t l = 0; l < m; ++l) {
        const double c = cov(k, l, term);
        all += c;
        if (k == l) diag += c;
      }
    e[static_cast<std::size_t>(term)] = (diag - all / static_cast<double>(m)) / static_cast<double>(m - 1);
  }
  return {e[0], e[1], e[2]};
}

TEST(IncrementBasis, MatchesTheBruteForceDoubleSum) {
  for (const bool ovl : {true, false})
    for (const std::size_t t : {1u, 3u, 7u})
      for (const double step : {0.25, 1.0, 3.0}) {
        const std::size_t points = 61;
        const IncrementBasis g = increment_basis(t, points, step, ovl);
        const IncrementBasis b = brute_force_basis(t, points, step, ovl);
        EXPECT_NEAR(g.q, b.q, 1e-10 * std::abs(b.q) + 1e-12) << ovl << " " << t << " " << step;
        EXPECT_NEAR(g.n, b.n, 1e-10 * std::abs(b.n)) << ovl << " " << t << " " << step;
        EXPECT_NEAR(g.b, b.b, 1e-9 * std::abs(b.b)) << ovl << " " << t << " " << step;
      }
}

TEST(IncrementBasis, LimitsOfEachTerm) {
  // White angle: 2 (less 2t/M² for the mean); white rate: t (less t²/M-ish); flicker: ≈ t² ln(T/t)/π.
  const std::size_t points = 100001;
  const IncrementBasis g = increment_basis(100, points, 0.01, true);
  EXPECT_NEAR(g.q, 2.0, 1e-3);
  EXPECT_NEAR(g.n, 1.0, 0.02);
  EXPECT_NEAR(g.b / (std::log(1000.0) / std::numbers::pi), 1.0, 0.2);
}

TEST(BlockSpread, ArwSpreadIsNOverRootBlock) {
  const double n = 0.05;
  const PhaseSeries x = arw(n, 12.43, 7200.0, 50.0, 9);
  const BlockSpreadResult r = block_spread(x, 100.0);
  ASSERT_TRUE(r.spread.valid);
  EXPECT_EQ(r.blocks, 72u);
  const double expect = 60.0 * n / 10.0;  // N_s/√(100 s), °/h
  EXPECT_LT(std::abs(r.spread.value - expect), 3.5 * r.spread.sigma);
  EXPECT_LE(r.spread.low, r.spread.value);
  EXPECT_GE(r.spread.high, r.spread.value);
}

TEST(BlockSpread, ExpectationUnderTheModel) {
  using V = Eigen::Matrix<double, kTermCount, 1>;
  // Two blocks: the sample variance of two means is the Allan variance at that τ, for any model.
  const V c = (V() << 0.07, 0.0036, 3.6e-5, 1e-9, 1e-13).finished();
  for (double tau : {1.0, 100.0, 1000.0}) {
    double av = 0;
    for (int i = 0; i < kTermCount; ++i) av += c[i] * term_basis(kAllTerms[static_cast<std::size_t>(i)], tau);
    EXPECT_NEAR(expected_block_variance(c, tau, 2) / av, 1.0, 1e-9) << tau;
  }
  // White rate: the block means are independent, E[s²] = N_s²/τ for any number of blocks.
  const V w = (V() << 0, 0.0036, 0, 0, 0).finished();
  EXPECT_NEAR(expected_block_variance(w, 100.0, 72) / (0.0036 / 100.0), 1.0, 1e-9);
  // A ramp R_s: block means on a line, E[s²] = R_s² τ² M(M+1)/12.
  const double rs2 = 2e-10;
  const V r = (V() << 0, 0, 0, 0, rs2).finished();
  EXPECT_NEAR(expected_block_variance(r, 100.0, 10) / (rs2 * 1e4 * 10 * 11 / 12.0), 1.0, 1e-9);
  // Flicker: the spread of 100-s means grows with the number of blocks (ln T), unlike the AV.
  const V f = (V() << 0, 0, 3.6e-5, 0, 0).finished();
  EXPECT_GT(expected_block_variance(f, 100.0, 72), 1.5 * expected_block_variance(f, 100.0, 2));
}

TEST(IncrementBasis, ReproducesTheMonteCarloMeanOfSingleTermRecords) {
  // Simulated single-term records (1000 s at 10 Hz, pulse weight 1e-6″): the mean of the overlapping
  // increment variances over 300 records against g at unit coefficient times the term's c.
  struct Case {
    NoiseModel model;
    double c_q, c_n, c_b;
  };
  std::vector<Case> cases(3);
  cases[0].model.white_angle_arcsec = 1.0;
  cases[0].c_q = 1.0;
  cases[1].model.arw_deg_per_sqrt_h = 0.05;
  cases[1].c_n = 3600.0 * 0.05 * 0.05;
  cases[2].model.bias_instability_deg_per_h = 0.01;
  cases[2].c_b = 1e-4;
  SimulationSettings settings;
  settings.duration_s = 1000.0;
  settings.rate_hz = 10.0;
  settings.scale_arcsec = 1e-6;
  MethodOptions o;
  o.direct_t_max_s = 20.0;
  o.bootstrap_replicates = 0;  // the points and g only
  constexpr int kRecords = 300;
  for (std::size_t ci = 0; ci < cases.size(); ++ci) {
    Simulator sim(cases[ci].model, settings);
    PhaseSeries x;
    std::vector<double> sum, sum2;
    DirectNResult r;
    for (int k = 0; k < kRecords; ++k) {
      sim.run(1000 + static_cast<std::uint64_t>(k), x);
      r = direct_n(x, o);
      sum.resize(r.points.size(), 0.0);
      sum2.resize(r.points.size(), 0.0);
      for (std::size_t i = 0; i < r.points.size(); ++i) {
        sum[i] += r.points[i].var_arcsec2;
        sum2[i] += r.points[i].var_arcsec2 * r.points[i].var_arcsec2;
      }
    }
    ASSERT_GE(r.points.size(), 4u);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      const double mean = sum[i] / kRecords;
      const double se = std::sqrt((sum2[i] / kRecords - mean * mean) / (kRecords - 1));
      const auto& g = r.basis[i];
      const double expect = g.q * cases[ci].c_q + g.n * cases[ci].c_n + g.b * cases[ci].c_b;
      EXPECT_NEAR(mean, expect, 4.0 * se + 1e-3 * expect) << "case " << ci << ", t = " << r.points[i].t_s << " s";
    }
  }
}

TEST(CrossChecksCli, ShippedRunCarriesTheUnbiasedEstimatorsInTextAndJson) {
  const std::string run = test::source_path("data/gl2d/gl2d_0C.csv.gz").string();
  const auto text = test::run_cli({"analyze", run});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("N direct (overlapping angle increments"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("N straight line (paper)"), std::string::npos);
  EXPECT_NE(text.out.find("B from 100-s averages"), std::string::npos);
  EXPECT_NE(text.out.find("biased: estimates sigma(tau_min)/0.6643"), std::string::npos);
  EXPECT_EQ(text.out.find("vs B (fit)"), std::string::npos);  // the raw spread is no estimate of B

  const auto js = test::run_cli({"analyze", run, "--json"});
  ASSERT_EQ(js.status, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  const auto& m = j.at("methods");
  // The shipped run's truth (scripts/make-gl2d-data.sh): N 0.00081 °/√h, B 0.0073 °/h.
  const auto& n = m.at("N_direct");
  EXPECT_LE(n.at("low95").get<double>(), 0.00081);
  EXPECT_GE(n.at("high95").get<double>(), 0.00081);
  const auto& b = m.at("B_100s");
  EXPECT_LE(b.at("low95").get<double>(), 0.0073);
  EXPECT_GE(b.at("high95").get<double>(), 0.0073);
  EXPECT_GT(b.at("edf").get<double>(), 1.0);
  EXPECT_GT(m.at("N_straight_line_paper").at("bias_factor").get<double>(), 1.2);
  EXPECT_FALSE(m.at("spread_100s").contains("discrepancy_sigma"));
  EXPECT_GT(m.at("spread_100s").at("expected").get<double>(), 0.0);
  const auto& s = j.at("slope_readout");
  EXPECT_LE(s.at("tau_min_s").get<double>(), j.at("duration_s").get<double>() / 10.0);
  EXPECT_GE(s.at("B_bias_factor").get<double>(), 1.0);
  EXPECT_LT(s.at("B_low95").get<double>(), s.at("B_high95").get<double>());

  // Saved results are read back: `report` of the JSON works with the new keys.
  test::TempDir dir;
  const auto saved = dir.write("run.json", js.out);
  const auto rep = test::run_cli({"report", saved.string(), "-o", (dir.path() / "r.html").string()});
  EXPECT_EQ(rep.status, 0) << rep.err;
}

TEST(Discrepancy, InSigma) {
  EXPECT_NEAR(discrepancy_sigma(3, 3, -1, 4), 0.8, 1e-12);
  EXPECT_EQ(discrepancy_sigma(1, 0, 1, 0), 0.0);
}

}  // namespace
}  // namespace rwcalc
