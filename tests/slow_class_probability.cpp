// Class probabilities over gyros spread across the class range (N log-uniform in 0.0003–0.004 °/√h,
// B in 0.003–0.02 °/h), 30-min records at 400 Hz from the independent generator
// (tests/independent_gyro.hpp) with a plain counter and with the GL-2D's randomised read-out: in every
// bin of stated probability of the overall class with at least 30 statements, the share right is
// within 0.07 of the mean stated probability, or within 2.5 Monte-Carlo standard errors where a bin of
// 30–150 statements cannot resolve 0.07 (docs/calibration.md). Each set has 80 records, 1600 under
// RWCALC_ACCEPTANCE=1 (tests/support/population.hpp; with 400 a bin of 150 statements is known to
// ±0.04 only, with 1600 to ±0.02); RWCALC_CLASS_RECORDS sets the count.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "independent_gyro.hpp"
#include "population.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/parallel.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

struct Statement {
  double p = 0;        // stated probability of the overall class
  bool right = false;  // the stated class is the true one
};

void check_calibration(bool dither, std::uint64_t seed0) {
  const int count = test::population("RWCALC_CLASS_RECORDS", 80, 1600);
  std::vector<Statement> out(static_cast<std::size_t>(count));
  parallel_for(out.size(), [&](std::size_t i) {
    std::mt19937_64 g(seed0 + i);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double n = 0.0003 * std::pow(0.004 / 0.0003, u(g)), b = 0.003 * std::pow(0.02 / 0.003, u(g));
    test::IndependentSettings s;
    s.dither = dither;
    s.flicker_step = 16;
    const AnalysisOptions o;
    const AnalysisResult r = analyze(test::independent_record({n, b, 0.0}, s, seed0 + 100 + i), o);
    out[i] = {r.verdict.p_class, !r.verdict.withheld && test::true_class(b, n, o.verdict.table) == r.verdict.cls};
  });
  const std::array<double, 5> edges{0.0, 0.5, 0.7, 0.9, 1.0001};
  const char* name = dither ? "GL-2D randomised read-out" : "plain counter";
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    int cnt = 0, hit = 0;
    double ps = 0, var = 0;
    for (const Statement& st : out)
      if (st.p >= edges[k] && st.p < edges[k + 1]) ++cnt, ps += st.p, var += st.p * (1.0 - st.p), hit += st.right;
    if (cnt == 0) continue;
    const double pm = ps / cnt, share = static_cast<double>(hit) / cnt;
    std::printf(
        "class probabilities, %s, %d records: stated %.2f..%.2f: %d statements, mean P %.3f, share right %.3f\n", name,
        count, edges[k], std::min(edges[k + 1], 1.0), cnt, pm, share);
    if (cnt >= 30) {
      EXPECT_NEAR(share, pm, std::max(0.07, 2.5 * std::sqrt(var) / cnt)) << name << ", bin " << k;
    }
  }
}

TEST(ClassProbability, PlainCounterAcrossTheClassRange) { check_calibration(false, 9000); }

TEST(ClassProbability, RandomisedReadoutAcrossTheClassRange) { check_calibration(true, 19000); }

}  // namespace
}  // namespace rwcalc
