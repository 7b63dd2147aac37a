// Exact counts held in 32 bits (PhaseSeries::counts32): every estimator gives the same bits from
// either form.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "allan/allan_kernels.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/outliers.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;

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

TEST(NarrowCounts, PreparedViewIsTheCountsThemselvesWithTheSameFlags) {
  std::vector<std::int64_t> sums;
  (void)pulse_text(20000, 5, sums);
  PhaseSeries x;
  x.counts32.assign(sums.begin(), sums.end());
  const auto n = detail::prepare_counts(x, true);
  const auto w = detail::prepare_counts(sums, true);
  ASSERT_NE(n.view, nullptr);
  EXPECT_EQ(n.view, x.counts32.data());  // no copy
  EXPECT_TRUE(n.rel32.empty());
  EXPECT_EQ(n.small24, w.small24);
  EXPECT_EQ(n.small29, w.small29);
  EXPECT_EQ(n.prefix_f64, w.prefix_f64);
  // C_0 ≠ 0: the offsets are formed (|C| < 2^30, so they fit).
  PhaseSeries y;
  for (const auto c : sums) y.counts32.push_back(static_cast<std::int32_t>(c + 1000000));
  const auto m = detail::prepare_counts(y, false);
  ASSERT_NE(m.view, nullptr);
  for (std::size_t i = 0; i < sums.size(); ++i) ASSERT_EQ(m.view[i], sums[i]) << i;
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
  o.allan.threads = 1;
  EXPECT_EQ(to_json(analyze(narrow, o)).dump(), to_json(analyze(rec, o)).dump());
  o.allan.threads = 2;
  EXPECT_EQ(to_json(analyze(narrow, o)).dump(), to_json(analyze(rec, o)).dump());

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
