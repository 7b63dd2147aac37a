// The lag-1 autocorrelation of the noise identification on the int32 view of exact counts is
// formed from exact integer sums (Σz, Σz², Σz_k·z_{k+1}). Checked here against a long-double
// two-pass reference (mean first, then the centred sums), and the AVX2 kernel against the
// one-term-at-a-time integer path, which must agree bit for bit (same exact sums, same final
// rounding).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "allan/noise_id.hpp"

namespace {

/// Long-double two-pass r1 of the level-th difference of p(k) = v[k·stride], k < count.
double reference_r1(const std::vector<std::int32_t>& v, std::size_t stride, std::size_t count, int level) {
  if (count <= static_cast<std::size_t>(level) + 1) return 0.0;
  std::vector<long double> z(count);
  for (std::size_t k = 0; k < count; ++k) z[k] = static_cast<long double>(v[k * stride]);
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

/// Offsets C_k − C_0 of a simulated count record of the given kind, scaled so that the largest
/// |offset| is about `range`.
std::vector<std::int32_t> record(std::size_t n, int kind, double range, std::uint64_t seed) {
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
  std::vector<std::int32_t> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::int32_t>(std::llround((v[i] - v[0]) * scale));
  return out;
}

// Tolerance: |r1 − reference| ≤ 1e-12. Both are within a few units of 1e-16 of the exact r1 for
// these lengths; a wrong sum, lane, tail or overflow moves r1 by far more.
constexpr double kTol = 1e-12;

TEST(NoiseIdExact, Lag1MatchesLongDoubleReferenceAndVectorEqualsScalar) {
  int compared = 0;
  std::uint64_t seed = 5;
  for (std::size_t n : {std::size_t{7}, std::size_t{38}, std::size_t{1031}, std::size_t{40001},
                        std::size_t{200002}}) {
    for (int kind = 0; kind < 5; ++kind) {
      // Below 2^24 (the vector kernel's domain) at several scales, including small offsets.
      for (double range : {60.0, 3.0e4, 1.6e7}) {
        const auto v = record(n, kind, range, ++seed);
        for (std::size_t stride : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{7}, std::size_t{64}}) {
          const std::size_t count = (n - 1) / stride + 1;
          for (int level = 0; level <= 3; ++level) {
            for (bool pair : {false, true}) {
              double rv[2], rs[2];
              rwcalc::detail::lag1_exact(v.data(), stride, count, level, true, pair, rv);
              rwcalc::detail::lag1_exact(v.data(), stride, count, level, false, pair, rs);
              EXPECT_EQ(rv[0], rs[0]) << "n " << n << " kind " << kind << " stride " << stride << " level " << level;
              EXPECT_NEAR(rv[0], reference_r1(v, stride, count, level), kTol)
                  << "n " << n << " kind " << kind << " range " << range << " stride " << stride << " level " << level;
              if (pair) {
                EXPECT_EQ(rv[1], rs[1]) << "n " << n << " kind " << kind << " level " << level + 1;
                if (level < 3) {
                  EXPECT_NEAR(rv[1], reference_r1(v, stride, count, level + 1), kTol);
                }
              }
              ++compared;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 1000);
}

// Offsets up to 2^31 − 1 (outside the vector kernel's domain): the integer path's 128-bit
// totals, with level-3 differences near 2^34, still give the reference r1.
TEST(NoiseIdExact, Lag1ExactOnFullInt32Range) {
  std::uint64_t seed = 91;
  for (int kind = 0; kind < 5; ++kind) {
    const auto v = record(100003, kind, 2147483000.0, ++seed);
    for (std::size_t stride : {std::size_t{1}, std::size_t{5}}) {
      const std::size_t count = (v.size() - 1) / stride + 1;
      for (int level = 0; level <= 3; ++level) {
        double r[2];
        rwcalc::detail::lag1_exact(v.data(), stride, count, level, false, false, r);
        EXPECT_NEAR(r[0], reference_r1(v, stride, count, level), kTol) << "kind " << kind << " level " << level;
      }
    }
  }
}

// The cases r1 = 0 by definition: too few points for the level, and a constant difference.
TEST(NoiseIdExact, Lag1DegenerateCases) {
  const std::vector<std::int32_t> ramp = {0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33};
  for (bool vector : {false, true}) {
    double r[2];
    rwcalc::detail::lag1_exact(ramp.data(), 1, ramp.size(), 1, vector, false, r);  // z constant: Σ(z − z̄)² = 0
    EXPECT_EQ(r[0], 0.0);
    rwcalc::detail::lag1_exact(ramp.data(), 1, 3, 2, vector, false, r);  // one point at level 2
    EXPECT_EQ(r[0], 0.0);
    rwcalc::detail::lag1_exact(ramp.data(), 1, ramp.size(), 0, vector, false, r);  // a line: r1 near 1
    EXPECT_NEAR(r[0], reference_r1(ramp, 1, ramp.size(), 0), kTol);
  }
}

}  // namespace

namespace {

// The start pass computes the first two levels of every small m in one pass over the view, split
// over threads: its r1 must be those of lag1_exact at each m, bit for bit (exact sums), for both
// domains, on one and two threads, at lengths that leave every tail size.
TEST(NoiseIdExact, StartPassEqualsPerTauSums) {
  std::uint64_t seed = 300;
  int compared = 0;
  for (std::size_t n : {std::size_t{1001}, std::size_t{65539}, std::size_t{300007}}) {
    for (int kind = 0; kind < 5; ++kind) {
      const auto v = record(n, kind, 1.0e6, ++seed);
      rwcalc::PhaseSeries x;
      x.counts.reserve(n);
      for (std::int32_t c : v) x.counts.push_back(c);  // C_k − C_0 = the view
      const std::vector<std::int64_t> ms = {1, 2, 3, 4, 5, 7, 8, 16, 33, 64, 128, 256, 512, 1024};
      for (auto domain : {rwcalc::NoiseIdDomain::Phase, rwcalc::NoiseIdDomain::Frequency}) {
        const int base = domain == rwcalc::NoiseIdDomain::Phase ? 0 : 1;
        for (unsigned threads : {1u, 2u}) {
          const auto start = rwcalc::detail::lag1_start_pass(x, ms.data(), ms.size(), domain, v.data(), true, threads);
          if (start.empty()) GTEST_SKIP() << "no AVX2 on this processor";
          ASSERT_EQ(start.size(), 2 * ms.size());
          for (std::size_t j = 0; j < ms.size(); ++j) {
            const auto m = static_cast<std::size_t>(ms[j]);
            const std::size_t count = (n - 1) / m + 1;
            if (m > 256 || count - static_cast<std::size_t>(base) < 30) {
              EXPECT_TRUE(std::isnan(start[2 * j])) << "m " << m;
              continue;
            }
            double r[2];
            rwcalc::detail::lag1_exact(v.data(), m, count, base, false, true, r);
            EXPECT_EQ(start[2 * j], r[0]) << "n " << n << " kind " << kind << " m " << m << " threads " << threads;
            EXPECT_EQ(start[2 * j + 1], r[1]) << "n " << n << " kind " << kind << " m " << m << " threads " << threads;
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 300);
}

}  // namespace
