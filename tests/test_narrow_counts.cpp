// Exact counts held in 32 bits (PhaseSeries::counts32): when the reader keeps a pulse file so,
// when it falls back to 64 bits, and that every estimator gives the same bits from either form.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/outliers.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;

ReadOptions one_thread() {
  ReadOptions o;
  o.threads = 1;
  return o;
}

// `n` pulse lines with small counts (a walk around 3 pulses per sample), and their sums C_0 … C_n.
std::string pulse_text(std::size_t n, std::uint64_t seed, std::vector<std::int64_t>& sums) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> d(-2, 8);
  std::string text;
  sums.assign(1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int c = d(rng);
    text += std::to_string(c) + "\n";
    sums.push_back(sums.back() + c);
  }
  return text;
}

// The same series with its counts in 64 bits.
PhaseSeries widened(const PhaseSeries& x) {
  PhaseSeries w = x;
  w.counts = x.wide_counts();
  w.counts32.clear();
  return w;
}

TEST(NarrowCounts, OneThreadReadOfAPulseFileKeepsThirtyTwoBits) {
  std::vector<std::int64_t> sums;
  const std::string text = "# scale_arcsec_per_pulse: 0.92\npulses\n" + pulse_text(5000, 1, sums);
  const Recording r = read_recording_text(text, "p.csv", one_thread());
  ASSERT_TRUE(r.phase.narrow());
  EXPECT_TRUE(r.phase.counts.empty());
  EXPECT_EQ(r.phase.wide_counts(), sums);
  EXPECT_EQ(r.phase.points(), sums.size());
  EXPECT_EQ(r.phase.count(4321), sums[4321]);
  EXPECT_DOUBLE_EQ(r.phase.diff(10, 3), static_cast<double>(sums[10] - sums[3]) * 0.92);
  EXPECT_EQ(r.samples, 5000u);
  EXPECT_EQ(r.line_of_rate(0), 3u);
  EXPECT_EQ(r.line_of_rate(4999), 5002u);
}

TEST(NarrowCounts, LongFilesOnTwoThreadsNarrowOrSplitWhenTheyCannot) {
  std::vector<std::int64_t> sums;
  std::string text = pulse_text(700000, 2, sums);  // > 1 MB: two parts if not kept in 32 bits
  ReadOptions two;
  two.threads = 2;
  const Recording a = read_recording_text(text, "long.csv", two);
  ASSERT_TRUE(a.phase.narrow());
  EXPECT_EQ(a.phase.wide_counts(), sums);
  // A comment near the end: the 32-bit read gives up there, and the text is read in two parts
  // (64 bits), the same record as one thread's read.
  text.insert(text.find('\n', text.size() - 40) + 1, "# end of test\n");
  const Recording wide = read_recording_text(text, "long.csv", two);
  const Recording one = read_recording_text(text, "long.csv", one_thread());
  EXPECT_FALSE(wide.phase.narrow());
  EXPECT_FALSE(one.phase.narrow());
  EXPECT_EQ(wide.phase.counts, one.phase.counts);
  EXPECT_EQ(wide.line_runs, one.line_runs);
  EXPECT_EQ(wide.samples, 700000u);
}

TEST(NarrowCounts, CountsBeyondThirtyBitsFallBackToSixtyFour) {
  // 120 lines of 9 999 999: Σ|c| passes 2^30 at line 108.
  std::string text;
  std::vector<std::int64_t> sums{0};
  for (int i = 0; i < 120; ++i) {
    text += i % 2 ? "-9999999\n" : "9999999\n";
    sums.push_back(sums.back() + (i % 2 ? -9999999 : 9999999));
  }
  std::string big;
  std::vector<std::int64_t> big_sums{0};
  for (int i = 0; i < 120; ++i) {
    big += "9999999\n";
    big_sums.push_back(big_sums.back() + 9999999);
  }
  for (const auto& [t, want] : {std::pair{text, sums}, std::pair{big, big_sums}}) {
    const Recording r = read_recording_text(t, "big.csv", one_thread());
    EXPECT_FALSE(r.phase.narrow());
    EXPECT_EQ(r.phase.counts, want);
  }
}

TEST(NarrowCounts, AnyOtherLineFallsBackWithTheSameRecordAndLines) {
  std::vector<std::int64_t> sums;
  std::string text = pulse_text(3000, 3, sums);
  // A comment after line 1000 and a blank line after line 2000; the counts are unchanged.
  std::size_t pos = 0;
  for (int k = 0; k < 1000; ++k) pos = text.find('\n', pos) + 1;
  text.insert(pos, "# door opened\n");
  for (int k = 0; k < 1001; ++k) pos = text.find('\n', pos) + 1;
  text.insert(pos, "\n");
  const Recording r = read_recording_text(text, "mixed.csv", one_thread());
  EXPECT_FALSE(r.phase.narrow());
  EXPECT_EQ(r.phase.counts, sums);
  EXPECT_EQ(r.line_of_rate(999), 1000u);
  EXPECT_EQ(r.line_of_rate(1000), 1002u);
  EXPECT_EQ(r.line_of_rate(1999), 2001u);
  EXPECT_EQ(r.line_of_rate(2000), 2003u);
  EXPECT_EQ(r.line_of_rate(2999), 3002u);
  // A bad line is still reported on its own line.
  std::string bad = pulse_text(500, 4, sums);
  bad.insert(bad.find('\n', 600) + 1, "1.5\n");
  try {
    (void)read_recording_text(bad, "bad.csv", one_thread());
    FAIL() << "a fractional pulse count was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1.5"), std::string::npos) << e.what();
  }
}

TEST(NarrowCounts, EveryEstimatorAndTheWholeAnalysisGiveTheSameBits) {
  SimulationSettings s;
  s.duration_s = 1800;
  s.rate_hz = 400;
  Recording rec;
  rec.source = "sim";
  rec.rate_hz = 400;
  rec.phase = simulate(test::gl2d_model(), s);
  rec.phase.counts[20000] += 60;  // an outlier
  for (std::size_t i = 20001; i < rec.phase.counts.size(); ++i) rec.phase.counts[i] += 60;
  rec.samples = rec.phase.points() - 1;
  Recording narrow = rec;
  narrow.phase.counts32.assign(rec.phase.counts.begin(), rec.phase.counts.end());
  narrow.phase.counts.clear();
  ASSERT_TRUE(narrow.phase.narrow());

  for (const Estimator e : {Estimator::Overlapping, Estimator::Modified, Estimator::NonOverlapping})
    for (const std::int64_t m : {1, 2, 7, 64, 1000})
      EXPECT_EQ(allan_variance(narrow.phase, m, e), allan_variance(rec.phase, m, e)) << "m " << m;

  AnalysisOptions o;
  for (const char* threads : {"1", "2"}) {
    const test::ScopedEnv env("RWCALC_THREADS", threads);
    EXPECT_EQ(to_json(analyze(narrow, o)).dump(), to_json(analyze(rec, o)).dump());
  }

  const auto out = find_outliers(narrow);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.size(), find_outliers(rec).size());
  for (const OutlierAction a : {OutlierAction::Replace, OutlierAction::Remove}) {
    const PhaseSeries from_narrow = apply_outliers(narrow.phase, out, a);
    const PhaseSeries from_wide = apply_outliers(rec.phase, out, a);
    EXPECT_EQ(from_narrow.wide_counts(), from_wide.wide_counts());
  }
  EXPECT_EQ(pulse_increments(narrow.phase), pulse_increments(widened(narrow.phase)));
}

}  // namespace
