// The exact kernels of the Allan variances of counts against brute-force sums: the overlapping and
// non-overlapping second-difference sums at every length around the block size, for small and huge
// steps (blocks inside and beyond the 64-bit fast path), with any counter offset and across the
// counter's wrap-around; the sweep of a whole grid against the per-τ sums on one and two threads;
// the modified variance's numerator from prefix sums; the 16-bit sums against the exact ones; the
// floating sweep against the floating per-τ sums, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "allan/allan_kernels.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/narrow_counts.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc::detail;
using rwcalc::i128;
using rwcalc::u128;
using rwcalc::test::ScopedEnv;

/// C[k+2m] − 2C[k+m] + C[k] as the exact integer, then taken modulo 2^64 into the int64 range
/// (the counter's own arithmetic).
i128 brute_diff(const std::vector<std::int64_t>& c, std::int64_t k, std::int64_t m) {
  auto at = [&](std::int64_t i) { return static_cast<i128>(c[static_cast<std::size_t>(i)]); };
  const i128 d = at(k + 2 * m) - 2 * at(k + m) + at(k);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(d));
}

u128 brute_sumsq(const std::vector<std::int64_t>& c, std::int64_t n, std::int64_t m, std::int64_t stride) {
  u128 s = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    const i128 d = brute_diff(c, i * stride, m);
    s += static_cast<u128>(d * d);
  }
  return s;
}

std::vector<std::int64_t> walk(std::size_t n, std::int64_t step, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> inc(-step, step);
  std::vector<std::int64_t> c(n);
  std::int64_t x = 123456789;
  for (auto& v : c) v = x += inc(rng);
  return c;
}

/// The counts plus `offset` modulo 2^64 (an offset near 2^63 makes the counter wrap round).
std::vector<std::int64_t> shifted(std::vector<std::int64_t> c, std::uint64_t offset) {
  for (auto& v : c) v = static_cast<std::int64_t>(static_cast<std::uint64_t>(v) + offset);
  return c;
}

constexpr std::uint64_t kWrapping = std::uint64_t{std::numeric_limits<std::int64_t>::max()} - 5'000'000;

TEST(ExactKernels, SecondDifferenceSumsEqualTheBruteForceSum) {
  for (std::int64_t step : {std::int64_t{9}, std::int64_t{1} << 22, std::int64_t{1} << 40}) {
    for (std::size_t len :
         {std::size_t{3}, std::size_t{4}, std::size_t{17}, std::size_t{1030}, std::size_t{2051}, std::size_t{5000}}) {
      const auto c = shifted(walk(len, step, len + static_cast<std::size_t>(step % 997)), kWrapping);
      const auto np = static_cast<std::int64_t>(len);
      for (std::int64_t m = 1; 2 * m < np; m = m * 2 + 1) {
        const std::int64_t n = np - 2 * m, n_non = (np - 1) / m - 1;
        EXPECT_TRUE(second_diff_sumsq(c.data(), n, m, 1) == brute_sumsq(c, n, m, 1)) << len << " m " << m;
        EXPECT_TRUE(second_diff_sumsq(c.data(), n_non, m, m) == brute_sumsq(c, n_non, m, m)) << len << " m " << m;
      }
    }
  }
}

// A counter offset, or a counter that wraps round 2^64 during the record, changes no bit of any
// estimator (the sums are formed modulo 2^64, the pulse weight applied at the end).
TEST(ExactKernels, CounterOffsetAndWrapAroundChangeNothing) {
  const auto base = walk(20'011, 1 << 12, 3);
  for (std::uint64_t offset : {std::uint64_t{0} - (std::uint64_t{1} << 62), kWrapping, std::uint64_t{1} << 63}) {
    rwcalc::PhaseSeries a, b;
    a.counts = base;
    b.counts = shifted(base, offset);
    for (auto est : {rwcalc::Estimator::Overlapping, rwcalc::Estimator::NonOverlapping, rwcalc::Estimator::Modified})
      for (std::int64_t m : {1, 2, 7, 64, 1000, 3000})
        EXPECT_EQ(rwcalc::allan_variance(a, m, est), rwcalc::allan_variance(b, m, est)) << "m " << m;
  }
}

TEST(ExactKernels, ModifiedNumeratorMatchesTheDirectSum) {
  const auto c = shifted(walk(3001, 1 << 10, 5), kWrapping);
  const auto p = count_prefix_sums(c.data(), c.size());
  const auto np = static_cast<std::int64_t>(c.size());
  for (std::int64_t m : {1, 2, 5, 33, 1000}) {
    const std::int64_t n = np - 3 * m + 1;
    long double want = 0;
    for (std::int64_t j = 0; j < n; ++j) {
      i128 s = 0;
      for (std::int64_t i = j; i < j + m; ++i) s += brute_diff(c, i, m);
      want += static_cast<long double>(s) * static_cast<long double>(s);
    }
    EXPECT_NEAR(modified_sumsq(p.data(), n, m) / static_cast<double>(want), 1.0, 1e-13) << "m " << m;
  }
}

// The sweep of a whole grid takes each block for every τ while it is cached, stretches of the
// record in parallel: exact, so every sum is the per-τ one bit for bit on one thread and on two.
// Some blocks hold second differences beyond the 64-bit fast path, and the counter wraps round.
TEST(ExactKernels, SweepEqualsThePerTauSumsOnOneAndTwoThreads) {
  const auto w = walk(200'017, 1 << 12, 8);
  std::vector<std::int64_t> c(w.size(), w[0]);
  for (std::size_t k = 1; k < c.size(); ++k) {
    std::int64_t step = w[k] - w[k - 1];
    if (k % 5003 < 40) step += std::int64_t{1} << 28;  // second differences beyond 2^26
    c[k] = c[k - 1] + step;
  }
  c = shifted(c, kWrapping);
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(c.size()); m = m * 2 + (m % 3 == 0)) ms.push_back(m);
  for (const char* threads : {"1", "2"}) {
    const ScopedEnv env("RWCALC_THREADS", threads);
    const std::vector<u128> swept = second_diff_sumsq_sweep(c.data(), c.size(), ms);
    ASSERT_EQ(swept.size(), ms.size());
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::int64_t n = static_cast<std::int64_t>(c.size()) - 2 * ms[i];
      EXPECT_TRUE(swept[i] == second_diff_sumsq(c.data(), n, ms[i], 1)) << "threads " << threads << " m " << ms[i];
    }
  }
  const std::int64_t n1 = static_cast<std::int64_t>(c.size()) - 2;
  EXPECT_TRUE(second_diff_sumsq(c.data(), n1, 1, 1) == brute_sumsq(c, n1, 1, 1));
  EXPECT_TRUE(second_diff_sumsq(c.data(), n1, 1, 1) > (static_cast<u128>(1) << 52) * 40u) << "no wide block";
}

// The floating sweep takes each block for every τ in the per-τ kernel's lanes and order: its sums
// are the per-τ ones bit for bit, on one thread and on two, for term counts that do and do not fill
// the last group of lanes; and both are the plain sum to rounding.
TEST(FloatingKernels, SweepEqualsThePerTauSumsBitForBit) {
  std::mt19937_64 gen(7);
  std::normal_distribution<double> normal;
  std::vector<double> x(100'003);
  double walk = 1e3;
  for (double& v : x) v = (walk += normal(gen)) + 0.1 * normal(gen);
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(x.size()); m = m * 2 + (m % 3 == 0)) ms.push_back(m);
  for (const char* threads : {"1", "2"}) {
    const ScopedEnv env("RWCALC_THREADS", threads);
    const std::vector<double> swept = second_diff_sumsq_sweep(x.data(), x.size(), ms);
    ASSERT_EQ(swept.size(), ms.size());
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::int64_t m = ms[i], n = static_cast<std::int64_t>(x.size()) - 2 * m;
      EXPECT_EQ(swept[i], second_diff_sumsq(x.data(), n, m, 1)) << "threads " << threads << " m " << m;
      long double plain = 0;
      for (std::int64_t k = 0; k < n; ++k) {
        const long double d = static_cast<long double>(x[static_cast<std::size_t>(k + 2 * m)]) -
                              2.0L * x[static_cast<std::size_t>(k + m)] + x[static_cast<std::size_t>(k)];
        plain += d * d;
      }
      EXPECT_NEAR(swept[i] / static_cast<double>(plain), 1.0, 1e-11) << "m " << m;
    }
  }
}

/// Counts with small steps about a steady rate of `slope` counts per point (a trend the narrow
/// sums must take out), from an offset near the counter's wrap.
std::vector<std::int64_t> drifting(std::size_t n, std::int64_t step, std::int64_t slope, std::uint64_t seed) {
  std::vector<std::int64_t> c = walk(n, step, seed);
  for (std::size_t k = 0; k < n; ++k) c[k] += slope * static_cast<std::int64_t>(k);
  return shifted(c, kWrapping);
}

// The 16-bit sums equal the exact ones wherever the counts' bounds let them run, and they run on
// small steps under any whole trend; beyond the bound they decline (the caller sums in 64 bits).
TEST(ExactKernels, NarrowSumsAreExactWhereTheirBoundHolds) {
  for (const std::int64_t slope : {std::int64_t{0}, std::int64_t{3}, std::int64_t{-1000}}) {
    const auto c = drifting(40'000, 1, slope, 11 + static_cast<std::uint64_t>(slope < 0));
    const NarrowCounts narrow(c.data(), c.size());
    std::size_t taken = 0;
    for (std::size_t m : {std::size_t{1}, std::size_t{2}, std::size_t{64}, std::size_t{1000}, std::size_t{9000}})
      for (std::size_t k0 = 0; k0 + 2 * m < c.size(); k0 += 4567) {
        const std::size_t len = std::min<std::size_t>(NarrowCounts::kMaxTerms, c.size() - 2 * m - k0);
        const auto s = narrow.second_diff_sumsq(k0, len, m);
        if (!s) continue;
        ++taken;
        u128 want = 0;
        for (std::size_t k = k0; k < k0 + len; ++k) {
          const i128 d = brute_diff(c, static_cast<std::int64_t>(k), static_cast<std::int64_t>(m));
          want += static_cast<u128>(d * d);
        }
        EXPECT_TRUE(u128{*s} == want) << "slope " << slope << " m " << m << " k0 " << k0;
      }
    EXPECT_GT(taken, 30u) << "slope " << slope;
    for (std::size_t t : {std::size_t{1}, std::size_t{400}, std::size_t{7000}})
      for (const std::int64_t shift : {slope * static_cast<std::int64_t>(t), slope * static_cast<std::int64_t>(t) + 5})
        for (std::size_t k0 = 0; k0 + t < c.size(); k0 += 9001) {
          const std::size_t len = std::min<std::size_t>(NarrowCounts::kMaxTerms, c.size() - t - k0);
          std::int64_t s1 = 0;
          std::uint64_t s2 = 0;
          ASSERT_TRUE(narrow.increment_sums(k0, len, t, shift, s1, s2)) << "t " << t << " k0 " << k0;
          i128 w1 = 0, w2 = 0;
          for (std::size_t k = k0; k < k0 + len; ++k) {
            const auto e =
                static_cast<std::int64_t>(static_cast<std::uint64_t>(c[k + t]) - static_cast<std::uint64_t>(c[k]) -
                                          static_cast<std::uint64_t>(shift));
            w1 += e;
            w2 += static_cast<i128>(e) * e;
          }
          EXPECT_TRUE(i128{s1} == w1 && i128{s2} == w2) << "slope " << slope << " t " << t << " k0 " << k0;
        }
  }
  // Steps of 2^12 (second differences far beyond 2^11) and an increment shift far off the mean.
  const auto wide = drifting(5000, std::int64_t{1} << 12, 0, 2);
  const NarrowCounts narrow(wide.data(), wide.size());
  EXPECT_FALSE(narrow.second_diff_sumsq(0, NarrowCounts::kMaxTerms, 100));
  std::int64_t s1 = 0;
  std::uint64_t s2 = 0;
  EXPECT_FALSE(narrow.increment_sums(0, 1000, 1000, std::int64_t{1} << 40, s1, s2));
}

TEST(ExactKernels, SweepOfNothing) {
  const std::vector<std::int64_t> c{1, 2, 4};
  EXPECT_TRUE(second_diff_sumsq_sweep(c.data(), c.size(), std::span<const std::int64_t>{}).empty());
  const std::vector<std::int64_t> m1{1};
  const auto s = second_diff_sumsq_sweep(c.data(), c.size(), m1);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_TRUE(s[0] == 1u);
}

}  // namespace
