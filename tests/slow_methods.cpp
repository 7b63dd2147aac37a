// Bias and coverage of the cross-check estimators (direct N, B from the 100-s averages, σ_min)
// and the verdicts they give, on seeded full-length GL-2D-like records: 2 h at 400 Hz, 0.92″
// pulses with the white (dither-like) read-out, Moscow Earth rate, N and B drawn across the
// paper's range. 48 records, 240 under RWCALC_ACCEPTANCE=1 (the figures in docs/analysis.md;
// tests/support/population.hpp); RWCALC_METHODS_RECORDS sets the count.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <cstdlib>
#include <random>

#include "population.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

int records() { return test::population("RWCALC_METHODS_RECORDS", 48, 240, 20); }

struct Outcome {
  double n_ratio = 0, b_ratio = 0, straight_ratio = 0, straight_expected = 0, min_ratio = 0, min_expected = 0;
  bool n_in = false, b_in = false, min_in = false;
  std::array<bool, 3> right{};  // verdict right with B from fit, sigma-min, avg100
};

Outcome run_one(int i) {
  std::mt19937_64 draw(0x6d657468u + static_cast<std::uint64_t>(i));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double n = 0.0007 * std::pow(0.0013 / 0.0007, u(draw));
  const double b = 0.005 * std::pow(0.012 / 0.005, u(draw));
  SimulationSettings s;
  s.seed = 0x4d455448u + static_cast<std::uint64_t>(i);
  const Recording rec = test::simulated_gyro(n, b, s);
  Outcome o;
  const AnalysisResult r = analyze(rec);
  // The verdict with B from the fit (analyze's default), from σ_min and from the 100-s averages.
  const std::array kinds{BEstimate::Fit, BEstimate::SigmaMin, BEstimate::Avg100};
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    AnalysisOptions opt;
    opt.verdict.b_estimate = kinds[k];
    o.right[k] = test::true_class(b, n, opt.verdict.table) == verdict_under(r, opt).cls;
  }
  const auto& dn = r.direct.N;
  EXPECT_TRUE(dn.valid && r.b100.B.valid && r.b_min.B.valid) << i;
  o.n_ratio = dn.estimate / n;  // the point estimate (value is the 95 % bound when not resolved)
  o.n_in = dn.low <= n && n <= dn.high;
  o.b_ratio = r.b100.B.estimate / b;
  o.b_in = r.b100.B.low <= b && b <= r.b100.B.high;
  o.straight_ratio = r.direct.straight.value / n;
  o.straight_expected = r.direct.straight.bias_factor;
  o.min_ratio = r.b_min.B.value / b;
  o.min_expected = r.b_min.bias_factor;
  o.min_in = r.b_min.B.low <= b && b <= r.b_min.B.high;
  return o;
}

TEST(SlowMethods, UnbiasedCrossChecksCoverAndVerdictsHoldUp) {
  const int count = records();
  std::vector<Outcome> out(static_cast<std::size_t>(count));
  parallel_for(out.size(), [&](std::size_t i) { out[i] = run_one(static_cast<int>(i)); });
  double n_ratio = 0, b_ratio = 0, s_ratio = 0, s_exp = 0, m_ratio = 0, m_exp = 0;
  int n_in = 0, b_in = 0, m_in = 0;
  std::array<int, 3> right{};
  for (const auto& o : out) {
    n_ratio += o.n_ratio;
    b_ratio += o.b_ratio;
    s_ratio += o.straight_ratio;
    s_exp += o.straight_expected;
    m_ratio += o.min_ratio;
    m_exp += o.min_expected;
    n_in += o.n_in;
    b_in += o.b_in;
    m_in += o.min_in;
    for (std::size_t k = 0; k < 3; ++k) right[k] += o.right[k];
  }
  const double c = count;
  fmt::print(
      "records {}\n"
      "  direct N          mean ratio {:.3f}  coverage {:.3f}\n"
      "  B 100-s averages  mean ratio {:.3f}  coverage {:.3f}\n"
      "  straight line     mean ratio {:.3f}  (mean expected bias factor {:.3f})\n"
      "  sigma_min/0.6643  mean ratio {:.3f}  (mean expected bias factor {:.3f})  coverage of B {:.3f}\n"
      "  verdict right     fit {:.3f}  sigma-min {:.3f}  avg100 {:.3f}\n",
      count, n_ratio / c, n_in / c, b_ratio / c, b_in / c, s_ratio / c, s_exp / c, m_ratio / c, m_exp / c, m_in / c,
      right[0] / c, right[1] / c, right[2] / c);
  // Bounds: the acceptance figures (±3 %, ±5 %, 92–98 %) widened by the binomial and sampling
  // spread of `count` records (≈ 2.5 standard errors).
  const double cov_se = std::sqrt(0.95 * 0.05 / c);
  EXPECT_NEAR(n_ratio / c, 1.0, 0.03 + 2.5 * 0.12 / std::sqrt(c));
  EXPECT_NEAR(b_ratio / c, 1.0, 0.05 + 2.5 * 0.25 / std::sqrt(c));
  EXPECT_GE(n_in / c, 0.92 - 2.5 * cov_se);
  EXPECT_LE(n_in / c, 0.98 + 2.5 * cov_se);
  EXPECT_GE(b_in / c, 0.92 - 2.5 * cov_se);
  EXPECT_LE(b_in / c, 0.98 + 2.5 * cov_se);
  // The straight line's bias is what its bias factor says.
  EXPECT_NEAR(s_ratio / s_exp, 1.0, 0.1);
  const double v_se = std::sqrt(0.25 / c);
  for (std::size_t k = 1; k < 3; ++k) EXPECT_GE(right[k] / c, right[0] / c - 0.05 - 2.0 * v_se) << k;
}

}  // namespace
}  // namespace rwcalc
