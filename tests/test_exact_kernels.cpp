// The vector kernels against plain loops: the exact overlapping second-difference sums of counts
// (|C_k − C_0| < 2^24: AVX-512 or AVX2 where the processor has them) for every length around the
// vector widths, one τ at a time and in one sweep (and of 64-bit counts without an int32 view, in
// one sweep); and the γ² sum of the AV-point covariance
// (AVX-512 with its own logarithm) against the same sum with std::log.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "allan/allan_kernels.hpp"
#include "model/fit_kernels.hpp"

namespace {

using namespace rwcalc::detail;

u128 brute_sumsq(const std::vector<std::int64_t>& c, std::int64_t n, std::int64_t m) {
  u128 s = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const std::int64_t d = c[static_cast<std::size_t>(k + 2 * m)] - 2 * c[static_cast<std::size_t>(k + m)] +
                           c[static_cast<std::size_t>(k)];
    const auto a = static_cast<u128>(d < 0 ? -d : d);
    s += a * a;
  }
  return s;
}

std::vector<std::int64_t> walk(std::size_t n, std::int64_t step, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> inc(-step, step);
  std::vector<std::int64_t> c(n);
  std::int64_t x = 123456789;  // offsets are taken from C_0, whatever it is
  for (auto& v : c) v = x += inc(rng);
  return c;
}

TEST(ExactKernels, SecondDifferenceSumsEqualThePlainSumAtEveryLength) {
  for (std::size_t len = 3; len < 200; ++len) {
    const auto c = walk(len, 9, len);
    const PreparedCounts p = prepare_counts(c, false, 1);
    ASSERT_TRUE(p.small24);
    for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(len); m = m * 2 + 1) {
      const std::int64_t n = static_cast<std::int64_t>(len) - 2 * m;
      EXPECT_TRUE(second_diff_sumsq(p, n, m, 1) == brute_sumsq(c, n, m)) << "len " << len << " m " << m;
    }
  }
}

TEST(ExactKernels, SweepEqualsOneTauAtATimeNearTheRangeLimit) {
  // Steps up to 2^14 over 10^5 samples keep |C_k − C_0| just below 2^24 most of the way (a wide
  // walk: the squares reach 2^50 and more, so any lane overflow or lost carry shows).
  auto c = walk(100'003, 1 << 14, 7);
  const std::int64_t c0 = c[0];
  for (auto& v : c) v = c0 + std::clamp<std::int64_t>(v - c0, -(std::int64_t{1} << 24) + 1, (std::int64_t{1} << 24) - 1);
  const PreparedCounts p = prepare_counts(c, false, 2);
  ASSERT_TRUE(p.small24);
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(c.size()); m *= 2) ms.push_back(m);
  std::vector<u128> out(ms.size());
  if (!second_diff_sumsq_sweep(p, c.size(), ms.data(), ms.size(), 0, 1, out.data()))
    GTEST_SKIP() << "no vector sweep on this processor; the one-τ path is tested above";
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::int64_t n = static_cast<std::int64_t>(c.size()) - 2 * ms[i];
    EXPECT_TRUE(out[i] == brute_sumsq(c, n, ms[i])) << "m " << ms[i];
    EXPECT_TRUE(second_diff_sumsq(p, n, ms[i], 1) == out[i]) << "m " << ms[i];
  }
}

// Counts whose offsets pass 2^30 have no int32 view; their sweep takes the 64-bit kernel's blocks
// of 1024 terms for every τ at once. Steps of up to 2^19 make some blocks' second differences pass
// 2^21 (the kernel's exact floating range), so the exact 128-bit path of those blocks is taken too.
TEST(ExactKernels, WideSweepEqualsOneTauAtATime) {
  const auto w = walk(200'017, 1 << 12, 8);
  std::vector<std::int64_t> c(w.size(), w[0]);
  for (std::size_t k = 1; k < c.size(); ++k) {
    std::int64_t step = w[k] - w[k - 1];
    if (k % 5003 < 40) step += std::int64_t{1} << 19;  // second differences beyond 2^21
    if (k > 100'000) step += std::int64_t{1} << 14;    // and offsets beyond 2^30
    c[k] = c[k - 1] + step;
  }
  const PreparedCounts p = prepare_counts(c, false, 1);
  ASSERT_EQ(p.view, nullptr) << "the offsets were meant to pass 2^30";
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(c.size()); m = m * 2 + (m % 3 == 0)) ms.push_back(m);
  std::vector<u128> all(ms.size()), odd(ms.size());
  ASSERT_TRUE(second_diff_sumsq_sweep(p, c.size(), ms.data(), ms.size(), 0, 1, all.data()));
  ASSERT_TRUE(second_diff_sumsq_sweep(p, c.size(), ms.data(), ms.size(), 1, 2, odd.data()));
  bool beyond = false;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::int64_t n = static_cast<std::int64_t>(c.size()) - 2 * ms[i];
    const u128 want = second_diff_sumsq(p, n, ms[i], 1);
    EXPECT_TRUE(want == brute_sumsq(c, n, ms[i])) << "m " << ms[i];
    EXPECT_TRUE(all[i] == want) << "m " << ms[i];
    if (i % 2 == 1) {
      EXPECT_TRUE(odd[i] == want) << "m " << ms[i];
    }
    beyond = beyond || want > (static_cast<u128>(1) << 42) * static_cast<u128>(n);
  }
  EXPECT_TRUE(beyond) << "no block left the exact floating range";
}

TEST(CovarianceKernel, VectorSumAgreesWithTheScalarSum) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t n = 0; n < 40; ++n) {
    GammaPair g;
    const double ma = 1 + std::floor(u(rng) * 64), mb = ma * 4;
    const double oa[3] = {0, ma, 2 * ma}, ob[3] = {0, mb, 2 * mb}, w[3] = {1, -2, 1};
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        g.d[static_cast<std::size_t>(3 * k + l)] = oa[k] - ob[l];
        g.w[static_cast<std::size_t>(3 * k + l)] = w[k] * w[l];
      }
    g.tau0 = 0.0025;
    g.c1 = 0.3 + u(rng);
    g.c2 = u(rng) * 1e-3;
    g.c3 = u(rng) * 1e-6;
    std::vector<double> h(n), wt(n);
    for (std::size_t i = 0; i < n; ++i) {
      // Half of the centres on a kink (a structure-function argument of exactly 0) or near one.
      h[i] = i % 2 ? g.d[i % 9] : std::round((u(rng) - 0.5) * 8 * mb) + 0.5 * static_cast<double>(i % 4 == 0);
      wt[i] = 1 + std::floor(u(rng) * 100);
    }
    const double a = gamma_sq_sum(g, h.data(), wt.data(), n);
    const double b = gamma_sq_sum_scalar(g, h.data(), wt.data(), n);
    ASSERT_TRUE(std::isfinite(a)) << "n " << n;
    EXPECT_NEAR(a, b, 1e-12 * std::abs(b)) << "n " << n;
    if (n > 0) {
      EXPECT_GT(b, 0.0);
    }
  }
}

TEST(CovarianceKernel, LogarithmOverManyDecades) {
  // One term, one block, c1 = c3 = 0: the sum is (½·(c2/π)·t²·ln t)² at t = |d − h|·τ0, so the
  // vector logarithm is checked across 120 decades of t against std::log.
  GammaPair g;
  g.w[0] = 1;
  g.c2 = std::numbers::pi;
  g.tau0 = 1;
  for (double t = 1e-60; t < 1e60; t *= 7.3) {
    const double h = 0, wt = 1;
    g.d[0] = t;
    const double expect = 0.25 * std::pow(t * t * std::log(t), 2);
    EXPECT_NEAR(gamma_sq_sum(g, &h, &wt, 1) / expect, 1.0, 1e-14) << "t " << t;
  }
}

}  // namespace
