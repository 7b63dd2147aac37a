// The `--tau all` grid on long records: sums from m = fft_from_m on come from FFT autocorrelations;
// they must agree with the exact kernel to ~1e-12, and everything below must stay bit-identical.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "rwcalc/allan.hpp"

namespace {

using namespace rwcalc;

// Pulse counts of a gyro-like record: Earth-rate drift, white angle noise quantised to pulses,
// a random-walk rate and a constant offset of the counter.
PhaseSeries gyro_counts(std::size_t points, double pulses_per_sample, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> white(0.0, 3.0), walk(0.0, 0.002);
  PhaseSeries x;
  x.tau0_s = 0.0025;
  x.arcsec_per_count = 0.92;
  x.counts.resize(points);
  double angle = 0, rate = pulses_per_sample;
  for (std::size_t k = 0; k < points; ++k) {
    rate += walk(rng);
    angle += rate;
    x.counts[k] = 1'000'000'007 + static_cast<std::int64_t>(std::floor(angle + white(rng)));
  }
  return x;
}

void expect_matches_exact(const PhaseSeries& x, double rel_tol) {
  AllanOptions o;
  o.grid = TauGrid::parse("all");
  const AllanResult all = compute_allan(x, o);
  ASSERT_EQ(all.points.size(), static_cast<std::size_t>(max_cluster_size(Estimator::Overlapping, x.points())));
  ASSERT_GT(all.fft_from_m, 1);
  // Below the threshold: the exact kernel, bit for bit.
  for (std::int64_t m : {std::int64_t{1}, std::int64_t{2}, std::int64_t{37}, all.fft_from_m - 1}) {
    const AllanPoint& p = all.points[static_cast<std::size_t>(m - 1)];
    EXPECT_EQ(p.var, allan_variance(x, m, Estimator::Overlapping)) << "m " << m;
  }
  // At and above: within rel_tol of the exact sum, over the whole range up to N/2.
  double worst = 0;
  const auto top = static_cast<std::int64_t>(all.points.size());
  for (std::int64_t m = all.fft_from_m; m <= top; m = m + 1 + m / 7) {
    const AllanPoint& p = all.points[static_cast<std::size_t>(m - 1)];
    ASSERT_EQ(p.m, m);
    const double exact = allan_variance(x, m, Estimator::Overlapping);
    ASSERT_GT(exact, 0);
    worst = std::max(worst, std::fabs(p.var / exact - 1));
  }
  const AllanPoint& last = all.points.back();
  worst = std::max(worst, std::fabs(last.var / allan_variance(x, last.m, Estimator::Overlapping) - 1));
  EXPECT_LT(worst, rel_tol);
  ::testing::Test::RecordProperty("worst_relative_departure", std::to_string(worst));
}

TEST(AllanAll, FftSumsAgreeWithTheExactKernelOnAGyroRecord) {
  expect_matches_exact(gyro_counts(40'001, 0.03, 11), 1e-10);
}

TEST(AllanAll, StrongDriftIsRemovedBeforeTheTransform) {
  // 10^4 pulses per sample: the counts reach 4·10^8, where a raw Σx² would swamp the second differences.
  expect_matches_exact(gyro_counts(40'001, 1.0e4, 12), 1e-10);
}

TEST(AllanAll, FloatingPhaseTakesTheSamePath) {
  const PhaseSeries c = gyro_counts(40'001, 0.5, 13);
  PhaseSeries v;
  v.tau0_s = c.tau0_s;
  v.values.resize(c.counts.size());
  for (std::size_t k = 0; k < c.counts.size(); ++k) v.values[k] = 0.92 * static_cast<double>(c.counts[k] - c.counts[0]);
  expect_matches_exact(v, 1e-10);
}

TEST(AllanAll, ShortRecordsAndOtherGridsStayExact) {
  const PhaseSeries x = gyro_counts(4'001, 0.03, 14);
  AllanOptions o;
  o.grid = TauGrid::parse("all");
  EXPECT_EQ(compute_allan(x, o).fft_from_m, 0);
  const PhaseSeries big = gyro_counts(40'001, 0.03, 15);
  o.grid = TauGrid::parse("dense");
  EXPECT_EQ(compute_allan(big, o).fft_from_m, 0);
}

}  // namespace
