// Unit tests of the cross-checks: direct N and the spread of 100-s mean rates.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rwcalc/fit.hpp"
#include "rwcalc/methods.hpp"

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
    EXPECT_NEAR(r.intercept_arcsec2, 0.0, 5.0 * 60 * 60 * 0.05 * 0.05);  // no white angle noise
    // The regression's slope is N² in ″²/s, the points are the ones it was fitted to.
    EXPECT_NEAR(std::sqrt(r.slope_arcsec2_per_s) / 60.0, r.N.value, 1e-12 * r.N.value);
    ASSERT_GE(r.points.size(), 3u);
    // At t = 1 s (1800 intervals, 3 % standard error) the line passes through the point.
    EXPECT_NEAR(r.points.front().var_arcsec2 / (r.intercept_arcsec2 + r.slope_arcsec2_per_s * r.points.front().t_s),
                1.0, 0.2);
  }
  EXPECT_GE(inside, 8);
}

TEST(DirectN, WhiteAngleNoiseAndQuantizationGoIntoTheIntercept) {
  // 1″ rms white angle noise (a dither residue) before 0.92″ pulse quantization: the angle
  // variance gains the constant 2(σφ² + q²/12) and the slope still gives N.
  const double q = 0.92;
  const double sphi = 1.0;
  PhaseSeries x = arw(0.02, 12.43, 3600.0, 100.0, 42);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (auto& v : x.values) v += sphi * g(rng);
  const DirectNResult r = direct_n(quantize(x, q));
  ASSERT_TRUE(r.N.valid);
  EXPECT_LT(std::abs(r.N.value - 0.02), 4.0 * r.N.sigma);
  const double a = 2.0 * (sphi * sphi + q * q / 12.0);
  EXPECT_NEAR(r.intercept_arcsec2, a, 0.3 * a);
}

TEST(DirectN, TooShortIsInvalidNotAnError) {
  const PhaseSeries x = arw(0.05, 0, 20.0, 100.0, 1);
  const DirectNResult r = direct_n(x);
  EXPECT_FALSE(r.N.valid);
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

TEST(Discrepancy, InSigma) {
  EXPECT_NEAR(discrepancy_sigma(3, 3, -1, 4), 0.8, 1e-12);
  EXPECT_EQ(discrepancy_sigma(1, 0, 1, 0), 0.0);
}

}  // namespace
}  // namespace rwcalc
