// The likelihood of the block means (src/diagnose/gls.cpp) and the effects' scans
// (src/diagnose/effects.cpp): known covariances, the whitening, the levels' profile, the null laws'
// bounds and known effects recovered.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "diagnose/effects.hpp"
#include "diagnose/fast_line.hpp"
#include "diagnose/gain.hpp"
#include "diagnose/gls.hpp"
#include "diagnose/level_spread.hpp"
#include "diagnose/signal.hpp"
#include "independent_gyro.hpp"
#include "rwcalc/normal_quantile.hpp"
#include "rwcalc/simulate.hpp"

using namespace rwcalc;
using namespace rwcalc::diag;

namespace {

/// Block means of a simulated record (20 Hz: the tests stay quick).
Blocks blocks_of(const NoiseModel& m, double duration, std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = duration;
  s.rate_hz = 20;
  s.scale_arcsec = 1e-4;
  NoiseModel mm = m;
  mm.readout = ReadoutMode::White;
  Simulator sim(mm, s);
  PhaseSeries x;
  sim.run(seed, x);
  const Decimated d = decimate(x);
  Blocks b;
  b.tb = 10;
  b.y = block_rates(d, per_block_for(d, 10));
  b.z = second_differences(b.y);
  return b;
}

GlsModel null_model(const Blocks& b) {
  GlsModel h;
  h.cov = {{CovKind::Q}, {CovKind::N}, {CovKind::B}, {CovKind::K}};
  h.fit = profile(b, hypothesis_of(b, {}, h.cov), {1e-6, 0.0036, 1.1e-5, 1e-9});
  return h;
}

NoiseModel gl2d_like() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.001;
  m.bias_instability_deg_per_h = 0.005;
  return m;
}

}  // namespace

// White rate noise of AV 1/τ: block means of variance 1/tb, so z = Δ²y has variance 6/tb and
// lag-1 covariance −4/tb; white angle noise of variance 1 ″²: z = Δ³θ/tb, variance 20/tb².
TEST(DiagnoseGls, WhiteTermsHaveTheirKnownCovariances) {
  const double tb = 10;
  const auto n = term_autocov({CovKind::N}, 5, tb);
  EXPECT_NEAR(n[0], 6 / tb, 1e-12);
  EXPECT_NEAR(n[1], -4 / tb, 1e-12);
  EXPECT_NEAR(n[2], 1 / tb, 1e-12);
  EXPECT_NEAR(n[3], 0, 1e-12);
  const auto q = term_autocov({CovKind::Q}, 5, tb);
  EXPECT_NEAR(q[0], 20 / (tb * tb), 1e-12);
  EXPECT_NEAR(q[3], -1 / (tb * tb), 1e-12);
  EXPECT_EQ(q[4], 0.0);
}

// Every term's z covariance against the sample covariance of block means the simulator makes
// (the flicker's far lags by their series; the Gauss–Markov term's by its closed form).
TEST(DiagnoseGls, CovariancesMatchTheSimulator) {
  struct Case {
    NoiseModel m;
    CovTerm t;
    double level;
  };
  NoiseModel fl;
  fl.bias_instability_deg_per_h = 0.01;
  NoiseModel gm;
  gm.gauss_markov.push_back({0.01, 60});
  NoiseModel rrw;
  rrw.rrw_deg_per_h_per_sqrt_h = 0.05;
  const double k = 0.05 / 60.0;
  const std::vector<Case> cases = {{fl, {CovKind::B}, kFlickerFloorPerB2 * 1e-4},
                                   {gm, {CovKind::GM, 60}, 1e-4},
                                   {rrw, {CovKind::K}, k * k / 3}};
  for (const auto& c : cases) {
    double s0 = 0, s1 = 0, s4 = 0;
    std::size_t cnt = 0;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const Blocks b = blocks_of(c.m, 7200, seed);
      for (Eigen::Index i = 0; i + 4 < b.z.size(); ++i) {
        s0 += b.z(i) * b.z(i);
        s1 += b.z(i) * b.z(i + 1);
        s4 += b.z(i) * b.z(i + 4);
        ++cnt;
      }
    }
    const auto r = term_autocov(c.t, 8, 10);
    const double v = s0 / static_cast<double>(cnt);
    EXPECT_NEAR(v / (c.level * r[0]), 1.0, 0.05) << static_cast<int>(c.t.kind);
    EXPECT_NEAR(s1 / static_cast<double>(cnt) / v, r[1] / r[0], 0.03) << static_cast<int>(c.t.kind);
    EXPECT_NEAR(s4 / static_cast<double>(cnt) / v, r[4] / r[0], 0.03) << static_cast<int>(c.t.kind);
  }
}

// The flicker's far lags switch from the direct sum to its series at lag 32: the two agree there,
// and the AV of a term read from its generalised covariance is the unit AV it promises.
TEST(DiagnoseGls, FlickerSeriesJoinsTheDirectSum) {
  const auto r = term_autocov({CovKind::B}, 40, 10);
  // The series is −δ⁶ of u² ln u, ≈ 12/u⁴ (×h/2): smooth through lag 31 → 32.
  EXPECT_NEAR(r[32] / r[31], std::pow(31.0 / 32.0, 4), 2e-3);
  EXPECT_NEAR(r[33] / r[32], std::pow(32.0 / 33.0, 4), 2e-3);
  for (const CovKind k : {CovKind::N, CovKind::B, CovKind::K}) EXPECT_GT(term_autocov({k}, 3, 10)[0], 0.0);
}

// W Σ Wᵀ = I for a Toeplitz covariance, and log det Σ from the recursion equals the dense one.
TEST(DiagnoseGls, WhiteningInvertsTheCovariance) {
  const std::size_t n = 30;
  std::vector<double> r = term_autocov({CovKind::B}, n, 10);
  const auto w = term_autocov({CovKind::N}, n, 10);
  for (std::size_t i = 0; i < n; ++i) r[i] += 1e-3 * w[i];
  Eigen::MatrixXd sigma(n, n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) sigma(i, j) = r[i > j ? i - j : j - i];
  Eigen::MatrixXd W;
  const Whitened out = whiten(r, Eigen::MatrixXd::Identity(n, n), &W);
  ASSERT_TRUE(out.ok);
  EXPECT_LT((W * sigma * W.transpose() - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_NEAR(out.logdet, std::log(sigma.determinant()), 1e-6 * std::abs(out.logdet));
  EXPECT_LT((out.v - W).cwiseAbs().maxCoeff(), 1e-12);
}

// The profile recovers the flicker level of simulated records (mean of 6: one 2-h record
// determines it to about ±50 %).
TEST(DiagnoseGls, ProfileRecoversTheFlickerLevel) {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.0005;
  m.bias_instability_deg_per_h = 0.01;
  const double b2 = kFlickerFloorPerB2 * 1e-4;
  double sum = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Blocks b = blocks_of(m, 7200, seed);
    sum += null_model(b).fit.level[2] / b2;
  }
  EXPECT_NEAR(sum / 6, 1.0, 0.3);
}

// The bounds: no searched curve leaves the single test's χ² law; a longer curve needs a larger
// statistic; the threshold is where the bound equals α.
TEST(DiagnoseGls, ScanBoundsReduceToTheSingleTest) {
  EXPECT_NEAR(scan_p(9.21034, 2, 0), 0.01, 1e-6);
  EXPECT_NEAR(scan_p(6.634897, 1, 0), 0.01, 1e-6);
  EXPECT_GT(scan_threshold(0.01, 2, 100), scan_threshold(0.01, 2, 10));
  EXPECT_NEAR(scan_p(scan_threshold(0.01, 1, 30), 1, 30), 0.01, 1e-9);
}

// A slow line of 4 cycles at 6× the flicker floor: named at its frequency and amplitude, its
// intervals holding the truth; nothing in a clean record of the same noise.
TEST(DiagnoseGls, SlowLineFoundAndEstimated) {
  NoiseModel m = gl2d_like();
  const double f = 4.0 / 7200, amp = 6 * 0.6643 * 0.005;
  m.sinusoids.push_back({f, amp, 0.3});
  const Blocks b = blocks_of(m, 7200, 5);
  const GlsModel h = null_model(b);
  const Candidate c = search_slow_line(b, h, 0.01, 2.5 / 7200, 12.0 / 7200, Effect::Sinusoid);
  EXPECT_LT(c.p, 1e-3);
  EXPECT_GT(c.lr, c.threshold);
  const TermEstimate e = estimate_det(b, c.model).at(0);
  const Finding found{Effect::Sinusoid, e.parameters, {}};
  EXPECT_NEAR(found.parameter("frequency").value, f, 0.5 / 7200);
  EXPECT_NEAR(found.parameter("amplitude").value, amp, 0.3 * amp);
  const Blocks clean = blocks_of(gl2d_like(), 7200, 5);
  EXPECT_GT(search_slow_line(clean, null_model(clean), 0.01, 2.5 / 7200, 12.0 / 7200, Effect::Sinusoid).p, 0.01);
}

// A bias step: its time and size, the 95 % intervals around the truth.
TEST(DiagnoseGls, StepFoundAndEstimated) {
  NoiseModel m = gl2d_like();
  m.bias_steps.push_back({3000, 0.05});
  const Blocks b = blocks_of(m, 7200, 7);
  const Candidate c = search_step(b, null_model(b), 0.01);
  EXPECT_LT(c.p, 1e-3);
  const TermEstimate e = estimate_det(b, c.model).at(0);
  const Finding step{Effect::BiasStep, e.parameters, {}};
  const FindingParameter& time = step.parameter("time");
  EXPECT_NEAR(time.value, 3000, 100);
  EXPECT_NEAR(step.parameter("size").value, 0.05, 0.015);
  EXPECT_LE(time.low95, time.value);
  EXPECT_GE(time.high95, time.value);
  EXPECT_NEAR(time.standard_uncertainty, (time.high95 - time.low95) / (2.0 * kZ95), 1e-12);
}

// A warm-up transient: found, its time constant near the truth.
TEST(DiagnoseGls, TransientFound) {
  NoiseModel w = gl2d_like();
  w.warmups.push_back({0.1, 600});
  const Blocks bw = blocks_of(w, 7200, 9);
  const Candidate cw = search_transient(bw, null_model(bw), 0.01);
  EXPECT_LT(cw.p, 1e-3);
  EXPECT_NEAR(cw.model.det.back().nl, 600, 300);
}

// The extended model's gain (src/diagnose/gain.cpp): a real step gains in sample and on the held-out
// runs; a step put where there is none loses on the held-out runs in most records (its coefficient,
// fitted to the kept runs' noise, predicts the held-out ones worse than no step), and in sample
// after Akaike's charge. It fails when the held-out score ignores the kept runs' information
// about the coefficients or conditions on nothing.
TEST(DiagnoseGain, RealStepGainsSpuriousStepLoses) {
  NoiseModel m = gl2d_like();
  m.bias_steps.push_back({3000, 0.05});
  const Blocks b = blocks_of(m, 7200, 7);
  const GlsModel base = null_model(b);
  const Candidate c = search_step(b, base, 0.01);
  const LikelihoodGain real = block_gain(b, base, c.model);
  EXPECT_GT(real.in_sample, 10.0);
  EXPECT_GT(real.holdout, 10.0);

  int lose_out = 0, lose_in = 0;
  const int records = 12;
  for (int i = 0; i < records; ++i) {
    const Blocks clean = blocks_of(gl2d_like(), 7200, 100 + static_cast<std::uint64_t>(i));
    const GlsModel h0 = null_model(clean);
    GlsModel spurious;
    spurious.cov = h0.cov;
    spurious.det = {{Effect::BiasStep, 1000.0 + 400.0 * i}};
    refit(clean, spurious, h0, 0);
    const LikelihoodGain g = block_gain(clean, h0, spurious);
    lose_out += g.holdout < 0;
    lose_in += g.in_sample < 0;
  }
  std::cout << "real step: gain " << real.in_sample << " in sample, " << real.holdout
            << " held out; spurious steps lose " << lose_in << " and " << lose_out << " of " << records << "\n";
  EXPECT_GE(lose_out, records * 3 / 4) << lose_out << " of " << records;
  EXPECT_GE(lose_in, records * 3 / 4) << lose_in << " of " << records;
}

// A line above the block means' band, fitted on one half of the rate samples, predicts the other
// half: positive gain for a real line, negative in most records for a line put where there is none.
TEST(DiagnoseGain, FastLineHoldoutKnowsARealLineFromNoise) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double dt = 0.05, f = 0.37;
  const std::size_t n = 1 << 16;
  std::vector<double> y(n), pure(n);
  for (std::size_t k = 0; k < n; ++k) {
    pure[k] = noise(rng);
    y[k] = pure[k] + 0.05 * std::cos(2 * kPi * f * (static_cast<double>(k) + 0.5) * dt + 1.0);
  }
  const FastLine found = fast_line_search(y, dt, 0.05, 9.0, 0.01);
  ASSERT_LT(found.p, 1e-3);
  EXPECT_NEAR(found.f_hz, f, 1e-3);
  EXPECT_GT(found.lr, 20.0);
  EXPECT_GT(fast_line_holdout(y, dt, found), 10.0);
  int lose = 0;
  for (int i = 0; i < 12; ++i) {
    FastLine spurious = found;
    spurious.f_hz = 1.1 + 0.53 * i;
    lose += fast_line_holdout(pure, dt, spurious) < 0;
  }
  std::cout << "spurious lines lose " << lose << " of 12\n";
  EXPECT_GE(lose, 9) << lose << " of 12";
}

// One white level read from n values: Whittle's information is (n − 1)/(2ℓ²) (the zero frequency,
// where every term of z is nil, left out), so a variance proportional to the level has n − 1
// degrees of freedom, and one that does not move with the levels has infinitely many.
TEST(DiagnoseLevelSpread, WhiteLevelHasTheInformationOfEveryValue) {
  Blocks b;
  b.y.assign(403, 0.0);
  b.z = second_differences(b.y);
  Hypothesis h;
  h.terms = {{CovKind::Q}};
  const double level = 2.5, n = static_cast<double>(b.n());
  const LevelSpread s = level_spread(b, h, {level});
  EXPECT_NEAR(s.cov(0, 0) / (2 * level * level / (n - 1)), 1.0, 1e-9);
  EXPECT_NEAR(effective_dof(s, [](const std::vector<double>& lv) { return 3 * lv[0]; }), n - 1, 1e-6 * n);
  EXPECT_TRUE(std::isinf(effective_dof(s, [](const std::vector<double>&) { return 3.0; })));
}

// A known level (a counter's) is not estimated: its row is zero, the other level keeps its spread.
TEST(DiagnoseLevelSpread, KnownLevelHasNoSpread) {
  Blocks b;
  b.y.assign(203, 0.0);
  b.z = second_differences(b.y);
  Hypothesis h;
  h.terms = {{CovKind::Q}, {CovKind::N}};
  h.terms[1].known_level = 0.01;
  const LevelSpread s = level_spread(b, h, {0.02, 0.01});
  EXPECT_GT(s.cov(0, 0), 0);
  EXPECT_EQ(s.cov(1, 1), 0);
  EXPECT_EQ(s.cov(0, 1), 0);
}

// The stated spread is the levels' scatter over records of a generator that shares no code with
// rwcalc (tests/independent_gyro.hpp): white rate noise and a dithered counter (white angle noise of
// q²/6), comparable shares of Var z, profiled on 100 one-hour records; each level's standard deviation
// across them within 20 % of the stated one (the sample's own is ±7 %).
TEST(DiagnoseLevelSpread, StatedSpreadIsTheScatterOverRecords) {
  test::IndependentSettings set;
  set.seconds = 3600;
  set.rate_hz = 10;
  set.dither = true;
  const std::vector<double> truth = {set.q_arcsec * set.q_arcsec / 6, 0.0036};
  std::vector<std::vector<double>> fitted(2);
  Eigen::Vector2d stated = Eigen::Vector2d::Zero();
  const int records = 100;
  for (int i = 0; i < records; ++i) {
    const Recording rec = test::independent_record({0.001, 0, 0}, set, 900 + static_cast<std::uint64_t>(i));
    const Decimated d = decimate(rec.phase);
    Blocks b;
    b.y = block_rates(d, per_block_for(d, 10));
    b.z = second_differences(b.y);
    const Hypothesis h = hypothesis_of(b, {}, {{CovKind::Q}, {CovKind::N}});
    const Profile p = profile(b, h, truth);
    const LevelSpread s = level_spread(b, h, p.level);
    for (int t = 0; t < 2; ++t) {
      fitted[static_cast<std::size_t>(t)].push_back(p.level[static_cast<std::size_t>(t)]);
      stated(t) += std::sqrt(s.cov(t, t)) / records;
    }
  }
  for (int t = 0; t < 2; ++t) {
    const auto& v = fitted[static_cast<std::size_t>(t)];
    double mean = 0, ss = 0;
    for (const double x : v) mean += x / records;
    for (const double x : v) ss += (x - mean) * (x - mean);
    const double sd = std::sqrt(ss / (records - 1));
    std::cout << fmt::format("level {}: mean {:.4g} (truth {:.4g}), scatter {:.3g}, stated {:.3g}\n", t, mean,
                             truth[static_cast<std::size_t>(t)], sd, stated(t));
    EXPECT_NEAR(sd / stated(t), 1.0, 0.2) << t;
  }
}

// Student's t²: the χ²₁ cutoff for many degrees of freedom, t²(0.975, 10) = 2.228139² for ten.
TEST(DiagnoseLevelSpread, CutoffIsStudentsT) {
  EXPECT_NEAR(profile_cutoff(std::numeric_limits<double>::infinity()), 3.841458820694124, 1e-12);
  EXPECT_NEAR(profile_cutoff(10), 2.228138851986 * 2.228138851986, 1e-9);
  EXPECT_NEAR(profile_cutoff(1e5), 3.841458820694124, 1e-3);
}

// A counter's sawtooth advancing by a fraction s of a pulse a block, noiseless, has the correlation
// 1 − 6s(1 − s) at one block (s = ½: −½, s = ¼: −⅛); noise in the advance damps it toward white.
TEST(DiagnoseGls, CounterSawtoothHasItsKnownCorrelation) {
  const auto c_half = counter_correlation(std::vector<double>(50, 0.5), 0.0, 3);
  const auto c_quarter = counter_correlation(std::vector<double>(50, 0.25), 0.0, 3);
  ASSERT_GE(c_half.size(), 2U);
  EXPECT_NEAR(c_half[1], -0.5, 0.01);
  EXPECT_NEAR(c_quarter[1], -0.125, 0.01);
  const auto c_noisy = counter_correlation(std::vector<double>(50, 0.25), 0.05, 3);
  EXPECT_GT(c_noisy[1], c_quarter[1]);
  EXPECT_LT(std::abs(c_noisy[1]), 0.125);
  // Uncorrelated, the term is white angle noise: Q's covariance.
  CovTerm white{CovKind::Counter};
  white.correlation = std::make_shared<const std::vector<double>>(std::vector<double>{1.0});
  const auto rc = term_autocov(white, 8, 10), rq = term_autocov({CovKind::Q}, 8, 10);
  for (std::size_t m = 0; m < 8; ++m) EXPECT_NEAR(rc[m], rq[m], 1e-15) << m;
}
