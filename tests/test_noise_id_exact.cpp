// The lag-1 autocorrelation of the noise identification is formed, for counts, from exact integer
// sums (Σz, Σz², Σz_k·z_{k+1}) rounded once at the end. Checked here against a long-double
// two-pass reference (mean first, then the centred sums) at every difference level and several
// decimations, over the whole range where the sums are exact and beyond it (floating sums); a
// counter offset or wrap-around changes no bit; floating phase agrees to rounding. Beyond 2^16
// decimated points the sums run over 16 spread runs of 4096 points (noise_id.hpp), checked against
// the same reference over those runs, and the types they give are those of the whole record.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "allan/noise_id.hpp"

namespace {

using rwcalc::detail::lag1_autocorrelation;

/// Long-double two-pass r1 of the level-th difference of p(k) = C[k·stride] − C[0], k < count.
double reference_r1(const std::vector<std::int64_t>& c, std::size_t stride, std::size_t count, int level) {
  if (count <= static_cast<std::size_t>(level) + 1) return 0.0;
  std::vector<long double> z(count);
  for (std::size_t k = 0; k < count; ++k)
    z[k] = static_cast<long double>(
        static_cast<std::int64_t>(static_cast<std::uint64_t>(c[k * stride]) - static_cast<std::uint64_t>(c[0])));
  for (int l = 0; l < level; ++l) {
    for (std::size_t k = 0; k + 1 < z.size(); ++k) z[k] = z[k + 1] - z[k];
    z.pop_back();
  }
  long double mean = 0;
  for (long double x : z) mean += x;
  mean /= static_cast<long double>(z.size());
  long double num = 0, den = 0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    den += (z[k] - mean) * (z[k] - mean);
    if (k + 1 < z.size()) num += (z[k] - mean) * (z[k + 1] - mean);
  }
  return den > 0 ? static_cast<double>(num / den) : 0.0;
}

/// The reference over 16 runs of 4096 consecutive points, run r starting at r·(count − 4096)/15,
/// pairs within a run, the mean over every point of the runs.
double reference_r1_runs(const std::vector<std::int64_t>& c, std::size_t stride, std::size_t count, int level) {
  constexpr std::size_t kRuns = 16, kWidth = 4096;
  std::vector<std::vector<long double>> runs;
  for (std::size_t r = 0; r < kRuns; ++r) {
    const std::size_t start = r * (count - kWidth) / (kRuns - 1);
    std::vector<long double> z(kWidth);
    for (std::size_t k = 0; k < kWidth; ++k)
      z[k] = static_cast<long double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(c[(start + k) * stride]) -
                                                                static_cast<std::uint64_t>(c[0])));
    for (int l = 0; l < level; ++l) {
      for (std::size_t k = 0; k + 1 < z.size(); ++k) z[k] = z[k + 1] - z[k];
      z.pop_back();
    }
    runs.push_back(std::move(z));
  }
  long double mean = 0, points = 0;
  for (const auto& z : runs)
    for (long double x : z) mean += x, points += 1;
  mean /= points;
  long double num = 0, den = 0;
  for (const auto& z : runs)
    for (std::size_t k = 0; k < z.size(); ++k) {
      den += (z[k] - mean) * (z[k] - mean);
      if (k + 1 < z.size()) num += (z[k] - mean) * (z[k + 1] - mean);
    }
  return den > 0 ? static_cast<double>(num / den) : 0.0;
}

/// A simulated count record of the given kind, scaled so that the largest |C_k − C_0| is about
/// `range`, with C_0 = `first`.
rwcalc::PhaseSeries record(std::size_t n, int kind, double range, std::uint64_t seed, std::int64_t first = 0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> v(n);
  double rw = 0, rrw = 0, rrw_int = 0;
  for (std::size_t i = 0; i < n; ++i) {
    rw += g(rng);
    rrw += g(rng);
    rrw_int += rrw;
    switch (kind) {
      case 0: v[i] = g(rng); break;                                  // white phase
      case 1: v[i] = rw; break;                                      // random-walk phase
      case 2: v[i] = 0.3 * rw + 2.0 * g(rng); break;                 // mixture near a threshold
      case 3: v[i] = rw + 0.02 * rrw_int; break;                     // with a random-walk frequency
      default: v[i] = static_cast<double>(i) + 0.5 * g(rng); break;  // a steady rate with white phase
    }
  }
  double top = 0;
  for (double x : v) top = std::max(top, std::fabs(x - v[0]));
  const double scale = top > 0 ? range / top : 1.0;
  rwcalc::PhaseSeries x;
  for (std::size_t i = 0; i < n; ++i)
    x.counts.push_back(static_cast<std::int64_t>(static_cast<std::uint64_t>(first) +
                                                 static_cast<std::uint64_t>(std::llround((v[i] - v[0]) * scale))));
  return x;
}

// Tolerance: |r1 − reference| ≤ 1e-12. Both are within a few units of 1e-16 of the exact r1 for
// these lengths; a wrong sum, tail or overflow moves r1 by far more.
constexpr double kTol = 1e-12;

void expect_reference(const rwcalc::PhaseSeries& x, const char* what) {
  for (std::size_t stride : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{64}}) {
    const std::size_t count = (x.points() - 1) / stride + 1;
    for (int level = 0; level <= 3; ++level)
      EXPECT_NEAR(lag1_autocorrelation(x, static_cast<std::int64_t>(stride), count, level),
                  reference_r1(x.counts, stride, count, level), kTol)
          << what << " n " << x.points() << " stride " << stride << " level " << level;
  }
}

TEST(NoiseIdExact, Lag1MatchesTheLongDoubleReference) {
  std::uint64_t seed = 5;
  for (std::size_t n : {std::size_t{7}, std::size_t{38}, std::size_t{1031}, std::size_t{40001}}) {
    for (int kind = 0; kind < 5; ++kind) {
      // Small offsets, the full int32 range (level-3 differences near 2^34, the exact sums' limit),
      // and offsets of 2^40 (beyond it: the floating sums).
      for (double range : {60.0, 1.6e7, 2147483000.0, 1.1e12}) expect_reference(record(n, kind, range, ++seed), "");
    }
  }
}

TEST(NoiseIdExact, CounterOffsetAndWrapAroundChangeNoBit) {
  const rwcalc::PhaseSeries a = record(20011, 3, 3.0e6, 17);
  for (std::int64_t first : {std::int64_t{-77}, std::numeric_limits<std::int64_t>::max() - 1'000'000}) {
    const rwcalc::PhaseSeries b = record(20011, 3, 3.0e6, 17, first);
    for (std::int64_t m : {1, 3, 50})
      for (int level = 0; level <= 3; ++level) {
        const std::size_t count = (a.points() - 1) / static_cast<std::size_t>(m) + 1;
        EXPECT_EQ(lag1_autocorrelation(a, m, count, level), lag1_autocorrelation(b, m, count, level))
            << "m " << m << " level " << level;
      }
  }
}

TEST(NoiseIdExact, FloatingPhaseAgreesToRounding) {
  const rwcalc::PhaseSeries c = record(40001, 2, 1.0e5, 23);
  rwcalc::PhaseSeries f;
  for (std::int64_t k : c.counts) f.values.push_back(static_cast<double>(k));
  for (std::int64_t m : {1, 4, 100})
    for (int level = 0; level <= 3; ++level) {
      const std::size_t count = (c.points() - 1) / static_cast<std::size_t>(m) + 1;
      EXPECT_NEAR(lag1_autocorrelation(c, m, count, level), lag1_autocorrelation(f, m, count, level), kTol);
    }
}

TEST(NoiseIdExact, BeyondTwoToTheSixteenPointsTheSumsRunOverSpreadRuns) {
  std::uint64_t seed = 91;
  for (int kind = 0; kind < 5; ++kind) {
    const rwcalc::PhaseSeries c = record(300001, kind, 1.0e6, ++seed);
    rwcalc::PhaseSeries f;
    for (std::int64_t k : c.counts) f.values.push_back(static_cast<double>(k));
    for (std::size_t stride : {std::size_t{1}, std::size_t{3}}) {
      const std::size_t count = (c.points() - 1) / stride + 1;
      for (int level = 0; level <= 3; ++level) {
        const double want = reference_r1_runs(c.counts, stride, count, level);
        const auto m = static_cast<std::int64_t>(stride);
        EXPECT_NEAR(lag1_autocorrelation(c, m, count, level), want, kTol) << "kind " << kind << " level " << level;
        EXPECT_NEAR(lag1_autocorrelation(f, m, count, level), want, 1e-9) << "kind " << kind << " level " << level;
        // The runs estimate the whole record's r1 to its sampling error (≈ 1/√65 536 = 0.004).
        EXPECT_NEAR(lag1_autocorrelation(c, m, count, level), reference_r1(c.counts, stride, count, level), 0.03)
            << "kind " << kind << " level " << level;
      }
    }
  }
}

// The cases r1 = 0 by definition: too few points for the level, and a constant difference.
TEST(NoiseIdExact, Lag1DegenerateCases) {
  rwcalc::PhaseSeries ramp;
  ramp.counts = {0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33};
  EXPECT_EQ(lag1_autocorrelation(ramp, 1, ramp.points(), 1), 0.0);  // z constant: Σ(z − z̄)² = 0
  EXPECT_EQ(lag1_autocorrelation(ramp, 1, 3, 2), 0.0);              // one point at level 2
  EXPECT_NEAR(lag1_autocorrelation(ramp, 1, ramp.points(), 0), reference_r1(ramp.counts, 1, ramp.points(), 0), kTol);
}

}  // namespace
