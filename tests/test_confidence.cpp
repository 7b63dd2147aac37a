// Noise identification, Greenhall–Riley EDF and χ² bounds against published numbers and against
// synthetic power-law noises whose exponent is known.
#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <random>

#include "rwcalc/confidence.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc {
namespace {

TEST(Edf, GreenhallRileyOverlappingAllanOnPhaseDat) {
  // noise-models.md §4.2: α = 0, N = 1001, m = 1 … 128 (Stable32's PHASE.DAT OADEV bounds).
  const double want[] = {782.0, 540.7, 306.1, 166.0, 86.37, 43.35, 21.24, 9.551};
  std::int64_t m = 1;
  for (double w : want) {
    const double edf = edf_greenhall(0, 2, m, 1001, true, false);
    EXPECT_NEAR(edf / w, 1.0, 6e-4) << "m " << m << " edf " << edf;
    m *= 2;
  }
}

TEST(Edf, AsymptotesAndTheWhitePmClosedFormAreContinuous) {
  // Large records: J > 100 uses the tables; EDF ≈ r/a0 with r = T/τ (WFM a0 = 2/3 → 1.5 T/τ).
  const std::size_t n = 1440001;
  const double edf = edf_greenhall(0, 2, 1000, n, true, false);
  EXPECT_NEAR(edf, 2158, 2);  // noise-models.md §4.2 table (WFM, m = 1000)
  EXPECT_NEAR(edf_greenhall(-1, 2, 1000, n, true, false), 1688, 2);
  EXPECT_NEAR(edf_greenhall(-2, 2, 1000, n, true, false), 1333, 2);
  EXPECT_NEAR(edf_greenhall(2, 2, 1000, n, true, false), 7.40e5, 0.01e5);
  // EDF never exceeds the number of terms by much and is positive everywhere.
  for (int alpha = -2; alpha <= 2; ++alpha)
    for (std::int64_t m : {1, 3, 50, 200, 5000, 400000}) {
      for (bool ovl : {false, true})
        for (bool mod : {false, true}) {
          if (mod && !ovl) continue;
          const double e = edf_greenhall(alpha, 2, m, n, ovl, mod);
          EXPECT_GT(e, 0) << alpha << " " << m;
          EXPECT_TRUE(std::isfinite(e));
        }
    }
  EXPECT_THROW(edf_greenhall(-3, 1, 4, 100, true, false), AnalysisError);  // α + 2d ≤ 1
  EXPECT_EQ(edf_greenhall(0, 2, 600, 1001, true, false), 0.0);             // no term left
}

// Greenhall's basic sum for α = +1 (flicker PM), d = 2, evaluated directly in 50 decimal digits, where
// the second difference of sw at step 1/F that cancels ~2·log10(F·t) digits still leaves 30.
double edf_flicker_pm_reference(std::int64_t m, std::int64_t n_phase, bool overlapping) {
  using Big = boost::multiprecision::cpp_bin_float_50;
  const Big f = m, s = overlapping ? m : 1, mr = m, d = 2;
  auto sw = [](const Big& t) { return t == 0 ? Big(0) : Big(t * t * log(abs(t))); };
  auto sx = [&](const Big& t) { return f * f * (2 * sw(t) - sw(t - 1 / f) - sw(t + 1 / f)); };
  auto sz = [&](const Big& t) { return 6 * sx(t) - 4 * sx(t - 1) - 4 * sx(t + 1) + sx(t - 2) + sx(t + 2); };
  const Big m_terms = 1 + floor(s * (Big(n_phase) - (mr / f + mr * d)) / mr);
  const Big j_terms = std::min(m_terms, Big((d + 1) * s));
  const Big z0 = sz(0), zj = sz(j_terms / s);
  Big sum = z0 * z0 + (1 - j_terms / m_terms) * zj * zj;
  for (std::int64_t j = 1; j < static_cast<std::int64_t>(j_terms); ++j) {
    const Big z = sz(Big(j) / s);
    sum += 2 * (1 - Big(j) / m_terms) * z * z;
  }
  return static_cast<double>(z0 * z0 * m_terms / sum);
}

TEST(Edf, FlickerPmAtLargeClusterSizesKeepsFullPrecision) {
  // Non-overlapping ADEV at m = 524288 (τ = 1311 s of a 400-Hz record) with a few intervals left: the
  // direct second difference lost 11 digits in long double, and its x87 logarithm differs between
  // processors, so the EDF differed in the 8th digit from one machine to another.
  for (std::int64_t m : {1000, 524288, 2000000}) {
    for (std::int64_t intervals : {4, 9, 40}) {
      const std::int64_t n = m * intervals + 1;
      const double nonoverlapping = edf_greenhall(1, 2, m, static_cast<std::size_t>(n), false, false);
      EXPECT_NEAR(nonoverlapping / edf_flicker_pm_reference(m, n, false), 1.0, 1e-13) << m << " " << intervals;
    }
    const std::int64_t n = 2 * m + 41;  // overlapping: 41 terms (the direct sum needs J ≤ 100)
    const double overlapping = edf_greenhall(1, 2, m, static_cast<std::size_t>(n), true, false);
    EXPECT_NEAR(overlapping / edf_flicker_pm_reference(m, n, true), 1.0, 1e-13) << m;
  }
}

TEST(Chi2, IntervalBracketsTheEstimateAndNarrowsWithEdf) {
  const DevInterval a = chi2_interval(4.0, 10, 0.683);
  EXPECT_LT(a.low, 2.0);
  EXPECT_GT(a.high, 2.0);
  const DevInterval b = chi2_interval(4.0, 1e6, 0.683);
  // For large ν the relative 1-σ half-width of σ is ≈ 1/√(2ν).
  EXPECT_NEAR((b.high - b.low) / 2.0 / 2.0, 1.0 / std::sqrt(2e6), 1e-5);
  const DevInterval c = chi2_interval(4.0, 10, 0.95);
  EXPECT_LT(c.low, a.low);
  EXPECT_GT(c.high, a.high);
  EXPECT_THROW(chi2_interval(1.0, 10, 1.5), UsageError);
  const DevInterval z = chi2_interval(0.0, 10, 0.683);
  EXPECT_EQ(z.low, 0.0);
  EXPECT_EQ(z.high, 0.0);
}

/// Phase series of a pure power-law noise: white PM (α = 2), white FM (0) or random-walk FM (−2).
PhaseSeries power_law(int alpha, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  PhaseSeries s;
  s.tau0_s = 1.0;
  s.kind = PhaseKind::Clock;
  double x = 0, y = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (alpha == 2) {
      s.values.push_back(g(rng));
    } else if (alpha == 0) {
      s.values.push_back(x);
      x += g(rng);
    } else {
      s.values.push_back(x);
      y += g(rng);
      x += y;
    }
  }
  return s;
}

TEST(NoiseId, PowerLawsAreRecognisedInBothDomainsAndByB1) {
  for (int alpha : {2, 0, -2}) {
    const PhaseSeries x = power_law(alpha, 20000, 11 + static_cast<unsigned>(alpha + 2));
    for (std::int64_t m : {1, 8, 64}) {  // lag-1 ACF (≥ 30 points at τ)
      EXPECT_EQ(identify_noise(x, m, Estimator::Overlapping, NoiseIdDomain::Phase), alpha) << alpha << " m " << m;
      EXPECT_EQ(identify_noise(x, m, Estimator::Overlapping, NoiseIdDomain::Frequency), alpha) << alpha;
    }
  }
}

TEST(NoiseId, FewPointsFallBackToTheB1Ratio) {
  // 24 averages at τ: below Stable32's 30-point threshold, so the B1 ratio decides. With so few
  // points the ratio is noisy; over nine independent records most must come out right. (White and
  // flicker PM share B1's μ = −2; for MVAR the R(n) ratio separates them.)
  for (int alpha : {2, 0, -2}) {
    int right = 0;
    for (unsigned seed = 0; seed < 9; ++seed) {
      const PhaseSeries x = power_law(alpha, 24 * 50 + 1, 100 + seed);
      const Estimator est = alpha == 2 ? Estimator::Modified : Estimator::NonOverlapping;
      const int got = identify_noise(x, 50, est);
      // Random-walk FM is told from white FM, not always from flicker FM, with 24 points.
      right += alpha == -2 ? got <= -1 : got == alpha;
    }
    EXPECT_GE(right, 6) << "alpha " << alpha;
  }
}

TEST(NoiseId, ConstantDataFallBackToWhiteFm) {
  PhaseSeries s;
  s.values.assign(100, 3.0);
  EXPECT_EQ(identify_noise(s, 10, Estimator::Overlapping), 0);
}

}  // namespace
}  // namespace rwcalc

#include "rwcalc/allan.hpp"

namespace {

// The lag-1 autocorrelations of counts come from exact integer sums, those of floating phase from
// floating sums: the r1 differ by rounding only, so the same record as counts and as floating
// phase must give the same α at every τ, for phase and frequency domains, on records whose lag-1
// autocorrelations fall on every side of the thresholds (white, random-walk and integrated
// random-walk phase, mixtures); and compute_allan reports identify_noise's α.
TEST(NoiseIdentification, CountsAndFloatingPhaseGiveTheSameAlpha) {
  std::mt19937_64 rng(77);
  std::normal_distribution<double> g(0.0, 1.0);
  int compared = 0;
  for (std::size_t n : {std::size_t{5003}, std::size_t{40001}, std::size_t{200002}}) {
    for (int kind = 0; kind < 4; ++kind) {
      rwcalc::PhaseSeries x;
      x.counts.assign(1, 12345);
      double rw = 0, rrw = 0;
      for (std::size_t i = 0; i < n; ++i) {
        rw += g(rng);
        rrw += 0.01 * g(rng);
        double v = 0;
        switch (kind) {
          case 0: v = 3.0 * g(rng); break;             // white phase
          case 1: v = rw; break;                       // random-walk phase
          case 2: v = 0.3 * rw + 2.0 * g(rng); break;  // mixture near a threshold
          default: v = rw + 50.0 * rrw; break;         // with a random-walk frequency
        }
        x.counts.push_back(x.counts.front() + static_cast<std::int64_t>(std::llround(v * 8.0)));
      }
      rwcalc::PhaseSeries f;
      for (std::int64_t c : x.counts) f.values.push_back(static_cast<double>(c - x.counts.front()));
      for (auto domain : {rwcalc::NoiseIdDomain::Phase, rwcalc::NoiseIdDomain::Frequency}) {
        rwcalc::AllanOptions o;
        o.grid.kind = rwcalc::TauGrid::Kind::Dense;
        o.grid.per_decade = 10;
        o.noise_id_domain = domain;
        const auto r = rwcalc::compute_allan(x, o);
        ASSERT_GT(r.points.size(), 3u);
        for (std::size_t k = 0; k + 1 < r.points.size(); ++k) {  // the last carries the previous α
          const auto& p = r.points[k];
          EXPECT_EQ(p.alpha, rwcalc::identify_noise(x, p.m, o.estimator, domain))
              << "n " << n << " kind " << kind << " m " << p.m;
          EXPECT_EQ(p.alpha, rwcalc::identify_noise(f, p.m, o.estimator, domain))
              << "n " << n << " kind " << kind << " m " << p.m;
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(compared, 300);
}

}  // namespace
