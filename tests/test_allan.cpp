// Properties of the Allan engine that need no reference file: exactness and offset invariance of
// the integer path, agreement with the textbook definitions, τ grids, limits and error paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "rwcalc/allan.hpp"
#include "rwcalc/allan_report.hpp"
#include "rwcalc/error.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

/// Cumulative counts from per-sample increments, starting at `offset` (wrapping like a counter).
PhaseSeries counts_from(const std::vector<std::int64_t>& inc, std::int64_t offset, double q = 0.92,
                        double tau0 = 0.0025) {
  PhaseSeries s;
  s.tau0_s = tau0;
  s.arcsec_per_count = q;
  s.counts.resize(inc.size() + 1);
  auto run = static_cast<std::uint64_t>(offset);
  s.counts[0] = offset;
  for (std::size_t i = 0; i < inc.size(); ++i) {
    run += static_cast<std::uint64_t>(inc[i]);
    s.counts[i + 1] = static_cast<std::int64_t>(run);
  }
  return s;
}

std::vector<std::int64_t> random_increments(std::size_t n, std::int64_t spread, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> d(-spread, spread);
  std::vector<std::int64_t> v(n);
  for (auto& x : v) x = d(rng);
  return v;
}

/// Textbook definitions, directly from the phase, in long double.
long double brute_force(const PhaseSeries& x, std::int64_t m, Estimator est) {
  const auto n = static_cast<std::int64_t>(x.points());
  auto ph = [&](std::int64_t i) { return static_cast<long double>(x.diff(static_cast<std::size_t>(i), 0)); };
  const long double tau = static_cast<long double>(m) * x.tau0_s;
  long double sum = 0;
  std::int64_t terms = 0;
  if (est == Estimator::Modified) {
    for (std::int64_t j = 0; j + 3 * m <= n; ++j, ++terms) {
      long double s = 0;
      for (std::int64_t i = j; i < j + m; ++i) s += ph(i + 2 * m) - 2 * ph(i + m) + ph(i);
      sum += s * s;
    }
    return sum / (2.0L * m * m * tau * tau * terms);
  }
  const bool overlapping = est == Estimator::Overlapping || est == Estimator::OverlappingHadamard;
  const std::int64_t stride = overlapping ? 1 : m;
  if (is_hadamard(est)) {
    for (std::int64_t k = 0; k + 3 * m < n; k += stride, ++terms) {
      const long double d = ph(k + 3 * m) - 3 * ph(k + 2 * m) + 3 * ph(k + m) - ph(k);
      sum += d * d;
    }
    return sum / (6.0L * tau * tau * terms);
  }
  for (std::int64_t k = 0; k + 2 * m < n; k += stride, ++terms) {
    const long double d = ph(k + 2 * m) - 2 * ph(k + m) + ph(k);
    sum += d * d;
  }
  return sum / (2.0L * tau * tau * terms);
}

TEST(AllanCounts, OffsetNear2To62GivesBitIdenticalResults) {
  const auto inc = random_increments(20000, 3, 1);
  const PhaseSeries at_zero = counts_from(inc, 0);
  for (std::int64_t offset : {std::int64_t{1} << 62, (std::int64_t{1} << 62) + 123456789,
                              std::numeric_limits<std::int64_t>::max() - 5000}) {  // last one wraps
    const PhaseSeries shifted = counts_from(inc, offset);
    for (Estimator est : {Estimator::Overlapping, Estimator::NonOverlapping, Estimator::Modified}) {
      AllanOptions o;
      o.estimator = est;
      o.grid = TauGrid::parse("dense:5");
      const AllanResult a = compute_allan(at_zero, o), b = compute_allan(shifted, o);
      ASSERT_EQ(a.points.size(), b.points.size());
      for (std::size_t i = 0; i < a.points.size(); ++i) {
        SCOPED_TRACE(std::string(to_string(est)) + " m " + std::to_string(a.points[i].m));
        EXPECT_EQ(a.points[i].var, b.points[i].var);  // to the last bit
        EXPECT_EQ(a.points[i].alpha, b.points[i].alpha);
        EXPECT_EQ(a.points[i].dev_low, b.points[i].dev_low);
        EXPECT_EQ(a.points[i].dev_high, b.points[i].dev_high);
      }
    }
  }
}

TEST(AllanCounts, MatchesTextbookDefinitionsAndFloatingPath) {
  const auto inc = random_increments(3000, 2, 2);
  const PhaseSeries c = counts_from(inc, 42);
  PhaseSeries v;
  v.tau0_s = c.tau0_s;
  for (std::size_t i = 0; i < c.points(); ++i) v.values.push_back(c.diff(i, 0));
  for (Estimator est : {Estimator::Overlapping, Estimator::NonOverlapping, Estimator::Modified,
                        Estimator::OverlappingHadamard, Estimator::NonOverlappingHadamard}) {
    for (std::int64_t m : {std::int64_t{1}, std::int64_t{2}, std::int64_t{3}, std::int64_t{7}, std::int64_t{64},
                           std::int64_t{500}, max_cluster_size(est, c.points())}) {
      SCOPED_TRACE(std::string(to_string(est)) + " m " + std::to_string(m));
      const long double want = brute_force(c, m, est);
      EXPECT_NEAR(allan_variance(c, m, est) / static_cast<double>(want), 1.0, 1e-13);
      EXPECT_NEAR(allan_variance(v, m, est) / static_cast<double>(want), 1.0, 1e-11);
    }
  }
}

// A rate that drifts linearly is a quadratic phase, whose third differences vanish: the Hadamard
// variance of noise plus any drift is the noise's, to the last bit on counts, while the Allan
// variance grows with the drift.
TEST(AllanCounts, HadamardIsBlindToALinearRateDrift) {
  auto inc = random_increments(20000, 3, 7);
  const PhaseSeries plain = counts_from(inc, 0);
  for (std::size_t i = 0; i < inc.size(); ++i) inc[i] += static_cast<std::int64_t>(i) / 50;  // a ramp
  const PhaseSeries drifting = counts_from(inc, 0);
  for (Estimator est : {Estimator::OverlappingHadamard, Estimator::NonOverlappingHadamard})
    for (std::int64_t m : {std::int64_t{50}, std::int64_t{1000}, std::int64_t{6000}}) {
      // The ramp's steps are whole counts every 50 samples: exactly quadratic at multiples of 50.
      EXPECT_EQ(allan_variance(drifting, m, est), allan_variance(plain, m, est)) << to_string(est) << " m " << m;
    }
  EXPECT_GT(allan_variance(drifting, 6000, Estimator::Overlapping),
            10 * allan_variance(plain, 6000, Estimator::Overlapping));
}

TEST(AllanCounts, LargeSecondDifferencesTakeTheExact128BitPath) {
  // Increments of ±2^40 give second differences far beyond the 2^21 fast-path limit.
  const auto inc = random_increments(5000, std::int64_t{1} << 40, 3);
  const PhaseSeries c = counts_from(inc, -(std::int64_t{1} << 62), 1.0, 1.0);
  for (std::int64_t m : {1, 4, 33, 1000}) {
    const long double want = brute_force(c, m, Estimator::Overlapping);
    EXPECT_NEAR(allan_variance(c, m, Estimator::Overlapping) / static_cast<double>(want), 1.0, 1e-15) << m;
  }
}

/// Σ (C[k+2m] − 2C[k+m] + C[k])² exactly in 128 bits, scaled as the engine scales it.
double exact_oavar(const PhaseSeries& x, std::int64_t m) {
  __extension__ typedef unsigned __int128 u128;
  __extension__ typedef __int128 i128;
  const auto n = static_cast<std::int64_t>(x.points()) - 2 * m;
  u128 s = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    const auto c = [&](std::int64_t i) { return static_cast<i128>(x.counts[static_cast<std::size_t>(i)]); };
    const i128 d = c(k + 2 * m) - 2 * c(k + m) + c(k);
    s += static_cast<u128>(d * d);
  }
  const double tau = static_cast<double>(m) * x.tau0_s;
  return static_cast<double>(s) * (x.arcsec_per_count * x.arcsec_per_count) /
         (2.0 * tau * tau * static_cast<double>(n));
}

TEST(AllanCounts, EveryCountRangeGivesTheExactSum) {
  // Count ranges from small to beyond 2^30, each record long enough for several blocks; the
  // extreme one alternates ±(2^24 − 1), so every |d| is 4·(2^24 − 1), beyond the blocks' 64-bit
  // fast path.
  const std::int64_t v24 = (std::int64_t{1} << 24) - 1;
  std::vector<PhaseSeries> records;
  {
    PhaseSeries s;
    s.tau0_s = 0.0025;
    s.arcsec_per_count = 0.92;
    for (int i = 0; i < 20011; ++i) s.counts.push_back(1000 + (i == 0 ? 0 : i % 2 ? v24 : -v24));
    records.push_back(s);
  }
  for (std::int64_t limit : {v24 - 7, v24 + 9, (std::int64_t{1} << 29) + 5, (std::int64_t{1} << 30) + 5}) {
    std::mt19937_64 rng(static_cast<unsigned>(limit));
    std::uniform_int_distribution<std::int64_t> d(-limit, limit);
    PhaseSeries s;
    s.tau0_s = 0.0025;
    s.arcsec_per_count = 0.92;
    s.counts.push_back(-77);
    for (int i = 1; i < 20011; ++i) s.counts.push_back(-77 + (i % 97 ? d(rng) : (i % 2 ? limit - 1 : 1 - limit)));
    records.push_back(s);
  }
  for (std::size_t r = 0; r < records.size(); ++r) {
    for (std::int64_t m : {1, 2, 3, 5, 16, 17, 100, 4097, 9000}) {
      SCOPED_TRACE("record " + std::to_string(r) + " m " + std::to_string(m));
      EXPECT_EQ(allan_variance(records[r], m, Estimator::Overlapping), exact_oavar(records[r], m));
    }
    // A whole grid at once (one sweep over the data), on one to three threads.
    for (const char* threads : {"1", "2", "3"}) {
      const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
      AllanOptions o;
      o.grid = TauGrid::parse("dense:7");
      const AllanResult a = compute_allan(records[r], o);
      ASSERT_GT(a.points.size(), 20u);
      for (const AllanPoint& p : a.points) {
        SCOPED_TRACE("record " + std::to_string(r) + " grid m " + std::to_string(p.m) + " threads " + threads);
        EXPECT_EQ(p.var, exact_oavar(records[r], p.m));
        EXPECT_EQ(p.n, static_cast<std::int64_t>(records[r].points()) - 2 * p.m);
      }
    }
  }
}

TEST(AllanCounts, WhiteAngleNoiseHasTheExpectedLevel) {
  // A white angle θ_k uniform on {−1, 0, 1} counts (σθ² = 2/3): its second difference has variance
  // 6σθ² at every m, so AVAR = 3σθ²/τ² (quantization-like slope −1 in ADEV).
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int> d(-1, 1);
  PhaseSeries s;
  s.tau0_s = 1.0;
  s.arcsec_per_count = 1.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) s.counts.push_back(d(rng));
  const double sigma_theta2 = 2.0 / 3.0;
  for (std::int64_t m : {1, 10, 100}) {
    const double want = 3.0 * sigma_theta2 / static_cast<double>(m * m);
    EXPECT_NEAR(allan_variance(s, m, Estimator::Overlapping) / want, 1.0, 0.02) << m;
  }
}

TEST(AllanEngine, ThreadCountDoesNotChangeTheResult) {
  const PhaseSeries c = counts_from(random_increments(50000, 5, 5), 7);
  PhaseSeries v;  // the same record as floating phase
  v.tau0_s = c.tau0_s;
  for (std::int64_t k : c.counts) v.values.push_back(static_cast<double>(k) * c.arcsec_per_count);
  for (const PhaseSeries* x : {&c, static_cast<const PhaseSeries*>(&v)}) {
    for (const char* grid : {"dense:10", "all"}) {
      for (auto est : {Estimator::Overlapping, Estimator::NonOverlapping, Estimator::Modified}) {
        AllanOptions o;
        o.grid = TauGrid::parse(grid);
        o.estimator = est;
        if (est == Estimator::Modified && o.grid.kind == TauGrid::Kind::All) o.grid.max_m = 300;
        AllanResult one, two;
        {
          const rwcalc::test::ScopedEnv env("RWCALC_THREADS", "1");
          one = compute_allan(*x, o);
        }
        {
          const rwcalc::test::ScopedEnv env("RWCALC_THREADS", "2");
          two = compute_allan(*x, o);
        }
        ASSERT_EQ(one.points.size(), two.points.size());
        EXPECT_EQ(one.fft_from_m, two.fft_from_m);
        for (std::size_t i = 0; i < one.points.size(); ++i) {
          SCOPED_TRACE(std::string(grid) + " m " + std::to_string(one.points[i].m));
          EXPECT_EQ(one.points[i].var, two.points[i].var);
          EXPECT_EQ(one.points[i].alpha, two.points[i].alpha);
          EXPECT_EQ(one.points[i].edf, two.points[i].edf);
          EXPECT_EQ(one.points[i].dev_low, two.points[i].dev_low);
          EXPECT_EQ(one.points[i].dev_high, two.points[i].dev_high);
        }
      }
    }
  }
}

TEST(TauGrids, OctaveDecadeDenseAllAndLimits) {
  const std::size_t n = 1001;  // m ≤ 500 for AVAR, ≤ 333 for MVAR
  EXPECT_EQ(max_cluster_size(Estimator::Overlapping, n), 500);
  EXPECT_EQ(max_cluster_size(Estimator::Modified, n), 333);
  EXPECT_EQ(term_count(Estimator::Overlapping, 500, n), 1);
  EXPECT_EQ(term_count(Estimator::NonOverlapping, 2, n), 499);
  EXPECT_EQ(term_count(Estimator::Modified, 333, n), 3);
  EXPECT_EQ(max_cluster_size(Estimator::Overlapping, 2), 0);
  using V = std::vector<std::int64_t>;
  EXPECT_EQ(cluster_sizes(TauGrid::parse("octave"), Estimator::Overlapping, n, 1.0),
            (V{1, 2, 4, 8, 16, 32, 64, 128, 256}));
  EXPECT_EQ(cluster_sizes(TauGrid::parse("decade"), Estimator::Overlapping, n, 1.0),
            (V{1, 2, 4, 10, 20, 40, 100, 200, 400}));
  const V dense = cluster_sizes(TauGrid::parse("dense:20"), Estimator::Overlapping, n, 1.0);
  EXPECT_TRUE(std::is_sorted(dense.begin(), dense.end()));
  EXPECT_EQ(std::adjacent_find(dense.begin(), dense.end()), dense.end());  // distinct
  EXPECT_EQ(dense.front(), 1);
  EXPECT_LE(dense.back(), 500);
  EXPECT_GT(dense.size(), 40u);
  EXPECT_EQ(cluster_sizes(TauGrid::parse("all"), Estimator::Modified, n, 1.0).size(), 333u);
  TauGrid capped = TauGrid::parse("octave");
  capped.max_m = 100;
  EXPECT_EQ(cluster_sizes(capped, Estimator::Overlapping, n, 1.0).back(), 64);
}

TEST(TauGrids, ExplicitSecondsMustBeWholeSamplesAndInRange) {
  const TauGrid g = TauGrid::parse("0.01, 1,0.0025");
  EXPECT_EQ(cluster_sizes(g, Estimator::Overlapping, 100001, 0.0025), (std::vector<std::int64_t>{1, 4, 400}));
  EXPECT_THROW(cluster_sizes(TauGrid::parse("0.003"), Estimator::Overlapping, 100001, 0.0025), UsageError);
  EXPECT_THROW(cluster_sizes(TauGrid::parse("1000"), Estimator::Overlapping, 100001, 0.0025), UsageError);
  for (const char* bad : {"", "fast", "1,,2", "1,x", "-1", "0", "dense:0", "dense:x", "nan", "inf"})
    EXPECT_THROW(TauGrid::parse(bad), UsageError) << bad;
}

TEST(AllanEngine, ErrorPaths) {
  PhaseSeries two;
  two.values = {0.0, 1.0};
  EXPECT_THROW(compute_allan(two), AnalysisError);
  PhaseSeries ok;
  ok.values = {0.0, 1.0, 0.5, 2.0, 1.0};
  AllanOptions o;
  o.confidence = 1.0;
  EXPECT_THROW(compute_allan(ok, o), UsageError);
  o.confidence = 0.683;
  o.noise_id = false;
  o.alpha = 5;
  EXPECT_THROW(compute_allan(ok, o), UsageError);
  EXPECT_THROW(parse_estimator("tdev"), UsageError);
  EXPECT_EQ(parse_estimator("mdev"), Estimator::Modified);
}

TEST(AllanEngine, JsonCarriesUnitAndEveryPointField) {
  const PhaseSeries c = counts_from(random_increments(5000, 2, 6), 0);
  const nlohmann::json j = to_json(compute_allan(c));
  EXPECT_EQ(j.at("unit"), "deg/h");
  EXPECT_EQ(j.at("estimator"), "oadev");
  EXPECT_DOUBLE_EQ(j.at("tau0_s").get<double>(), 0.0025);
  ASSERT_FALSE(j.at("points").empty());
  for (const auto& p : j.at("points")) {
    for (const char* key : {"af", "tau_s", "n", "alpha", "edf", "dev", "dev_low", "dev_high"})
      EXPECT_TRUE(p.contains(key)) << key;
    EXPECT_LT(p.at("dev_low").get<double>(), p.at("dev").get<double>());
    EXPECT_GT(p.at("dev_high").get<double>(), p.at("dev").get<double>());
  }
}

}  // namespace
}  // namespace rwcalc

namespace rwcalc {
namespace {

TEST(AllanReport, TableAndCsvCarryUnitsHeaderAndOneRowPerTau) {
  PhaseSeries c;
  c.tau0_s = 0.0025;
  std::mt19937_64 rng(8);
  std::uniform_int_distribution<int> d(0, 2);
  std::int64_t run = 0;
  for (int i = 0; i < 20001; ++i) c.counts.push_back(run += d(rng));
  const AllanResult r = compute_allan(c);
  const std::string table = format_allan_table(r, {"run.txt", 20000, 400.0, "default"});
  for (const char* s : {"run.txt", "overlapping Allan", "confidence: 0.683", "1″/s = 1 °/h", "samples: 20000",
                        "rate: 400 Hz (default)", "AF", "τ (s)", "terms", "EDF", "σ_min", "σ_max", "°/h"})
    EXPECT_NE(table.find(s), std::string::npos) << s << "\n" << table;
  EXPECT_EQ(table.find("nan"), std::string::npos);
  const std::string csv = format_allan_csv(r);
  EXPECT_TRUE(csv.starts_with("af,tau_s,n,alpha,edf,dev_low_deg_h,dev_deg_h,dev_high_deg_h\n")) << csv;
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), r.points.size() + 1);
  PhaseSeries clock;
  clock.kind = PhaseKind::Clock;
  clock.tau0_s = 1;
  for (int i = 0; i < 100; ++i) clock.values.push_back(std::sin(i * 0.7) * 1e-9);
  const AllanResult rc = compute_allan(clock);
  EXPECT_EQ(unit_label(rc), "input units/s");
  EXPECT_NE(format_allan_table(rc, {"clock.txt", 100, 1.0, ""}).find("input units per second"), std::string::npos);
  EXPECT_TRUE(format_allan_csv(rc).starts_with("af,tau_s,n,alpha,edf,dev_low_1,dev_1,dev_high_1\n"));
}

}  // namespace
}  // namespace rwcalc
