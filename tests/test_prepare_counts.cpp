// The int32 view of exact counts (detail::prepare_counts): its offsets C_k − C_0, the range flags
// that choose the exact kernels, and the limit beyond which no view is kept, against a plain
// computation here — on the vector path (AVX2, where the processor has it) and the scalar path for
// every length around the vector width, on one and two threads, for counts near each limit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "allan/allan_kernels.hpp"
#include "rwcalc/series.hpp"

namespace {

using rwcalc::detail::prepare_counts;

struct Expected {
  bool kept;
  bool small29;
  bool small24;
};

Expected expected_flags(const std::vector<std::int64_t>& c) {
  std::int64_t lo = 0, hi = 0;
  for (std::int64_t v : c) {
    const auto r = static_cast<std::int64_t>(static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(c[0]));
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  constexpr std::int64_t k30 = std::int64_t{1} << 30;
  if (!(lo > -k30 && hi < k30)) return {false, false, false};  // no view: the flags do not matter
  const std::int64_t top = std::max(-lo, hi);
  return {true, top < (std::int64_t{1} << 29), top < (std::int64_t{1} << 24)};
}

void check(const std::vector<std::int64_t>& c, unsigned threads, const char* what) {
  SCOPED_TRACE(what);
  SCOPED_TRACE(::testing::Message() << "n = " << c.size() << ", threads = " << threads);
  const auto p = prepare_counts(c, false, threads);
  const Expected e = expected_flags(c);
  ASSERT_EQ(!p.rel32.empty(), e.kept);
  if (!e.kept) return;
  EXPECT_EQ(p.small29, e.small29);
  EXPECT_EQ(p.small24, e.small24);
  ASSERT_EQ(p.rel32.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    const auto r = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[i]) - static_cast<std::uint64_t>(c[0]));
    ASSERT_EQ(p.rel32[i], static_cast<std::int32_t>(r)) << "at " << i;
  }
}

std::vector<std::int64_t> walk(std::size_t n, std::int64_t start, std::int64_t step, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> d(-step, step);
  std::vector<std::int64_t> c(n);
  std::int64_t acc = start;
  for (auto& v : c) {
    v = acc;
    acc += d(rng);
  }
  return c;
}

TEST(PrepareCounts, OffsetsAndFlagsForEveryTailLength) {
  // Lengths around the eight offsets the vector pass takes per step: every tail, and a start far
  // from zero (only the offsets from C_0 matter).
  for (std::size_t n = 1; n <= 41; ++n) {
    check(walk(n, 0, 3, n), 1, "small steps from 0");
    check(walk(n, std::int64_t{1} << 40, 1000, n + 100), 1, "large start");
    check(walk(n, -(std::int64_t{1} << 50), 1 << 26, n + 200), 1, "steps near 2^26");
  }
}

TEST(PrepareCounts, LimitsOfTheViewAndOfTheKernels) {
  // One offset exactly at, and one past, each limit, placed in the vector part and in the tail,
  // on either side of zero: the flags must switch exactly there.
  for (std::int64_t limit : {std::int64_t{1} << 24, std::int64_t{1} << 29, std::int64_t{1} << 30}) {
    for (std::int64_t delta : {-1, 0}) {
      for (std::int64_t sign : {1, -1}) {
        for (std::size_t at : {std::size_t{3}, std::size_t{17}, std::size_t{22}}) {
          std::vector<std::int64_t> c = walk(23, 5, 2, at);
          c[at] = c[0] + sign * (limit + delta);
          check(c, 1, "one offset at a limit");
        }
      }
    }
  }
  // Wide offsets whose low 32 bits look small: dropped by their true range, not their int32 image.
  std::vector<std::int64_t> c = walk(40, 0, 2, 9);
  c[11] = c[0] + (std::int64_t{1} << 32) + 1;
  check(c, 1, "2^32 + 1 wraps to 1 in int32");
  c[11] = std::numeric_limits<std::int64_t>::min();
  check(c, 1, "most negative int64");
}

TEST(PrepareCounts, LongRecordOnTwoThreads) {
  // Above 2^20 points the two halves are prepared on two threads; the halves meet at an odd place.
  const auto c = walk((std::size_t{1} << 20) + 12345, -77, 1, 42);
  check(c, 2, "2 threads");
  check(c, 1, "1 thread");
  auto wide = c;
  wide[wide.size() - 3] = wide[0] - (std::int64_t{1} << 30);  // past the limit in the second half
  check(wide, 2, "past the limit in the second half");
}

// Σ (C[k+2m] − 2C[k+m] + C[k])² over k < P − 2m, straight from the 64-bit counts.
rwcalc::detail::u128 plain_sumsq(const std::vector<std::int64_t>& c, std::int64_t m) {
  rwcalc::detail::u128 s = 0;
  for (std::size_t k = 0; k + 2 * static_cast<std::size_t>(m) < c.size(); ++k) {
    const auto d = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[k + 2 * m]) -
                                             2 * static_cast<std::uint64_t>(c[k + m]) + static_cast<std::uint64_t>(c[k]));
    s += static_cast<rwcalc::detail::u128>(static_cast<rwcalc::detail::i128>(d) * d);
  }
  return s;
}

rwcalc::PhaseSeries series_of(std::vector<std::int64_t> c) {
  rwcalc::PhaseSeries x;
  x.kind = rwcalc::PhaseKind::Gyro;
  x.tau0_s = 0.0025;
  x.arcsec_per_count = 1e-4;
  x.counts = std::move(c);
  return x;
}

TEST(PrepareSecondDifferences, AFastRateGetsTheNarrowViewAndTheSameSums) {
  using rwcalc::detail::prepare_second_differences;
  // A record of a fine pulse: ~3·10^4 pulses per sample (offsets past 2^30 after 35 000 samples)
  // and a wandering rate; its start far from 0, rising and falling.
  const std::int64_t ms[] = {1, 2, 7, 64, 1000, 9000};
  for (const std::int64_t rate : {std::int64_t{30011}, std::int64_t{-30011}}) {
    std::vector<std::int64_t> c = walk(40001, std::int64_t{1} << 50, 40, 7);
    for (std::size_t k = 0; k < c.size(); ++k) c[k] += rate * static_cast<std::int64_t>(k) + static_cast<std::int64_t>(k * k / 5000);
    const auto x = series_of(c);
    ASSERT_EQ(prepare_counts(x, false).view, nullptr) << "the plain offsets are too wide";
    const auto p = prepare_second_differences(x);
    ASSERT_NE(p.view, nullptr);
    EXPECT_TRUE(p.small24);
    std::vector<rwcalc::detail::u128> swept(std::size(ms));
    const auto np = static_cast<std::int64_t>(c.size());
    for (std::size_t i = 0; i < std::size(ms); ++i) {
      const auto want = plain_sumsq(c, ms[i]);
      EXPECT_TRUE(rwcalc::detail::second_diff_sumsq(p, np - 2 * ms[i], ms[i], 1) == want) << ms[i];
      if (rwcalc::detail::second_diff_sumsq_sweep(p, c.size(), ms, std::size(ms), 0, 1, swept.data())) {
        EXPECT_TRUE(swept[i] == want) << ms[i];
      }
    }
  }
}

TEST(PrepareSecondDifferences, NarrowCountsAndAWideWanderAreLeftAsTheyAre) {
  using rwcalc::detail::prepare_second_differences;
  // Narrow offsets: the plain view, C_k − C_0.
  const auto small = walk(5000, 12345, 3, 1);
  const auto sx = series_of(small);
  const auto p = prepare_second_differences(sx);
  ASSERT_NE(p.view, nullptr);
  for (std::size_t k = 0; k < small.size(); ++k) ASSERT_EQ(p.view[k], small[k] - small[0]) << k;
  // A wander of 2^31 pulses away from the line through the ends: no view, the 64-bit sums.
  std::vector<std::int64_t> wide = walk(5000, 0, 3, 2);
  for (std::size_t k = 0; k < wide.size(); ++k)
    wide[k] += static_cast<std::int64_t>(std::sin(static_cast<double>(k) * 6.283 / 5000.0) * 2147483648.0);
  const auto wx = series_of(wide);  // the prepared counts point into it
  const auto w = prepare_second_differences(wx);
  EXPECT_EQ(w.view, nullptr);
  for (const std::int64_t m : {1, 3, 1000})
    EXPECT_TRUE(rwcalc::detail::second_diff_sumsq(w, 5000 - 2 * m, m, 1) == plain_sumsq(wide, m)) << m;
}

}  // namespace
