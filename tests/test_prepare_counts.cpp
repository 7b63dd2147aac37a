// The int32 view of exact counts (detail::prepare_counts): its offsets C_k − C_0, the range flags
// that choose the exact kernels, and the limit beyond which no view is kept, against a plain
// computation here — on the vector path (AVX2, where the processor has it) and the scalar path for
// every length around the vector width, on one and two threads, for counts near each limit.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "../src/allan_kernels.hpp"

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

}  // namespace
