// Unit tests of the five-term noise fit on synthetic Allan-variance points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "rwcalc/deviance.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/fit.hpp"

namespace rwcalc {
namespace {

struct Truth {
  double Q = 0.2656;  // ″ (0.92″ pulses: q/√12)
  double N = 0.0010;  // °/√h
  double B = 0.0060;  // °/h
  double K = 0.0005;  // °/h/√h
  double R = 0.0;     // °/h²
  [[nodiscard]] double var(double tau) const {
    double v = 0;
    const double vals[5] = {Q, N, B, K, R};
    for (int i = 0; i < kTermCount; ++i) v += c_from_coefficient(kAllTerms[i], vals[i]) * term_basis(kAllTerms[i], tau);
    return v;
  }
  [[nodiscard]] double coef(Term t) const {
    const double vals[5] = {Q, N, B, K, R};
    return vals[static_cast<int>(t)];
  }
};

/// Octave points of a record of length T at τ0 = 2.5 ms with EDF ≈ 1.2·T/τ (capped), exact model.
std::vector<FitPoint> octave_points(const Truth& tr, double T = 7200.0, double tau0 = 0.0025) {
  std::vector<FitPoint> pts;
  for (double m = 1; m * tau0 <= T / 2.5; m *= 2) {
    const double tau = m * tau0;
    pts.push_back({tau, tr.var(tau), std::min(1.0e5, 1.2 * T / tau)});
  }
  return pts;
}

/// The same with independent scaled-χ² scatter (ν σ̂²/σ² ~ χ²_ν).
std::vector<FitPoint> noisy_points(const Truth& tr, std::mt19937_64& rng, double T = 7200.0) {
  auto pts = octave_points(tr, T);
  for (auto& p : pts) {
    std::chi_squared_distribution<double> chi(p.edf);
    p.var *= chi(rng) / p.edf;
  }
  return pts;
}

TEST(FitTerms, BasisAndUnitsFollowTheIeeeReadouts) {
  // σ at τ = 1 h equals N; σ at τ = 3 h equals K; σ at √3 s equals Q; floor = 0.6643·B.
  EXPECT_NEAR(std::sqrt(c_from_coefficient(Term::N, 0.002) * term_basis(Term::N, 3600.0)), 0.002, 1e-15);
  EXPECT_NEAR(std::sqrt(c_from_coefficient(Term::K, 0.03) * term_basis(Term::K, 3.0 * 3600.0)), 0.03, 1e-15);
  EXPECT_NEAR(std::sqrt(c_from_coefficient(Term::Q, 0.5) * term_basis(Term::Q, std::sqrt(3.0))), 0.5, 1e-15);
  EXPECT_NEAR(std::sqrt(c_from_coefficient(Term::B, 1.0) * term_basis(Term::B, 77.0)), 0.66428, 1e-5);
  EXPECT_NEAR(std::sqrt(c_from_coefficient(Term::R, 2.0) * term_basis(Term::R, std::sqrt(2.0) * 3600.0)), 2.0, 1e-12);
  for (Term t : kAllTerms) EXPECT_NEAR(coefficient_from_c(t, c_from_coefficient(t, 0.37)), 0.37, 1e-14);
}

TEST(Fit, RecoversExactCoefficientsFromNoiselessPoints) {
  Truth tr;
  tr.R = 2e-5;
  const auto pts = octave_points(tr);
  FitOptions all_terms;
  all_terms.select_terms = false;
  const FitResult f = fit_noise(pts, all_terms);
  // The fit's c are the truth's; each estimate is its root with the root's bias taken out, which
  // moves it up by at most 1/chi_root_mean(kRootMinEdf) (+25 %).
  for (Term t : kAllTerms) {
    SCOPED_TRACE(std::string(term_name(t)));
    const double root = coefficient_from_c(t, f.c[static_cast<int>(t)]);
    EXPECT_NEAR(root / tr.coef(t), 1.0, 1e-6);
    EXPECT_GE(f[t].estimate, root);
    EXPECT_LE(f[t].estimate, root / chi_root_mean(kRootMinEdf) * (1.0 + 1e-12));
  }
  EXPECT_NEAR(f.chi2, 0.0, 1e-8);
  EXPECT_TRUE(f[Term::N].resolved);
  EXPECT_TRUE(f[Term::Q].resolved);
  // In a 2-h record a K this small is invisible; with all five terms forced into the model the
  // floor can be traded for N + K and B is not resolved. Term selection drops K and R (reported as
  // upper bounds) and resolves B.
  EXPECT_FALSE(f[Term::K].resolved);
  const FitResult sel = fit_noise(pts);
  EXPECT_TRUE(sel[Term::B].resolved);
  EXPECT_FALSE(sel[Term::K].in_model);
  EXPECT_FALSE(sel[Term::R].in_model);
  EXPECT_GT(sel[Term::K].value, tr.K);
  EXPECT_NEAR(coefficient_from_c(Term::B, sel.c[static_cast<int>(Term::B)]) / tr.B, 1.0, 0.01);
  // A clearly present K is kept and recovered.
  Truth strong = tr;
  strong.K = 0.03;
  const FitResult fk = fit_noise(octave_points(strong));
  EXPECT_TRUE(fk[Term::K].in_model);
  EXPECT_TRUE(fk[Term::K].resolved);
  EXPECT_NEAR(coefficient_from_c(Term::K, fk.c[static_cast<int>(Term::K)]) / strong.K, 1.0, 0.01);
  // Intervals bracket the estimate and are positive.
  for (Term t : kAllTerms) {
    EXPECT_LE(f[t].low, f[t].estimate);
    EXPECT_GE(f[t].high, f[t].estimate);
    EXPECT_GE(f[t].low, 0.0);
  }
  // N and Q compete for the same short-τ points: negatively correlated.
  EXPECT_LT(f.corr_NQ, 0.0);
}

TEST(Fit, AbsentTermIsAnUpperBoundNeverZeroOrNegative) {
  Truth tr;
  tr.K = 0.0;
  tr.R = 0.0;
  const FitResult f = fit_noise(octave_points(tr));
  for (Term t : {Term::K, Term::R}) {
    SCOPED_TRACE(std::string(term_name(t)));
    EXPECT_FALSE(f[t].resolved);
    EXPECT_EQ(f[t].low, 0.0);
    EXPECT_GT(f[t].value, 0.0);        // the upper bound is reported …
    EXPECT_EQ(f[t].value, f[t].high);  // … as the value
    EXPECT_NEAR(f[t].estimate, 0.0, 1e-6 * f[t].high);
    EXPECT_TRUE(std::isfinite(f[t].sigma));
  }
  // K's bound is the 97.5 % point of the set with K; the average with the K-free set (its point mass at
  // 0) puts more than that below it.
  EXPECT_GE(f.cdf(Term::K, f[Term::K].value), 0.975 - 0.01);
  EXPECT_NEAR(f.cdf(Term::R, f[Term::R].value), 0.975, 0.01);
}

TEST(Fit, CoefficientsAreAveragedOverTheSetsWithAndWithoutK) {
  // K absent: the set with K adds nothing, weight 1/(1 + e); N and B take the mixture, whose 2.5 % and
  // 97.5 % points are the interval ends.
  Truth none;
  none.K = 0.0;
  const FitResult f = fit_noise(octave_points(none));
  ASSERT_TRUE(f.k_alternative);
  EXPECT_NEAR(f.k_weight, 1.0 / (1.0 + std::exp(1.0)), 0.02);
  EXPECT_FALSE(f[Term::K].resolved);
  for (Term t : {Term::N, Term::B}) {
    SCOPED_TRACE(std::string(term_name(t)));
    ASSERT_TRUE(f[t].resolved);
    EXPECT_NEAR(f.cdf(t, f[t].low), 0.025, 2e-3);
    EXPECT_NEAR(f.cdf(t, f[t].high), 0.975, 2e-3);
  }
  // B with K free reaches lower than B without it: the averaged interval does too.
  const FitResult sel = [] {
    FitOptions o;
    o.select_terms = false;
    o.enabled = {true, true, true, false, false};
    Truth t;
    t.K = 0.0;
    return fit_noise(octave_points(t), o);
  }();
  EXPECT_LT(f[Term::B].low, sel[Term::B].low);

  // K well above its detection limit: the set without K has no weight and K is resolved.
  Truth strong;
  strong.K = 0.1;
  const FitResult g = fit_noise(octave_points(strong));
  EXPECT_GT(g.k_weight, 0.999);
  EXPECT_TRUE(g[Term::K].resolved);
  EXPECT_NEAR(coefficient_from_c(Term::K, g.c[static_cast<int>(Term::K)]), strong.K, 1e-3 * strong.K);

  // Without the term selection nothing is averaged.
  FitOptions all;
  all.select_terms = false;
  EXPECT_FALSE(fit_noise(octave_points(none), all).k_alternative);
}

TEST(Fit, NonNegativeUnderScatterWhenTheTruthIsOnTheBoundary) {
  std::mt19937_64 rng(7);
  Truth tr;
  tr.B = 0;
  for (int rep = 0; rep < 20; ++rep) {
    const FitResult f = fit_noise(noisy_points(tr, rng));
    for (Term t : kAllTerms) {
      EXPECT_GE(f[t].estimate, 0.0);
      EXPECT_GE(f[t].low, 0.0);
      EXPECT_TRUE(std::isfinite(f[t].value) && std::isfinite(f[t].sigma) && std::isfinite(f[t].high));
    }
    EXPECT_GE(f.c.minCoeff(), 0.0);
  }
}

TEST(Fit, IntervalsCoverTheTruthForIndependentScatter) {
  // With independent χ² scatter the deviance is the exact likelihood, so dispersion 1 must give
  // about nominal coverage (the default dispersion is for correlated overlapping AV points).
  std::mt19937_64 rng(20240601);
  Truth tr;
  FitOptions o;
  o.dispersion = 1.0;
  o.edf_cap = 1e12;
  int n = 0, cov_n = 0, cov_b = 0, cov_q = 0;
  double chi2_sum = 0;
  int dof_sum = 0;
  for (int rep = 0; rep < 200; ++rep) {
    const FitResult f = fit_noise(noisy_points(tr, rng), o);
    ++n;
    cov_n += (f[Term::N].low <= tr.N && tr.N <= f[Term::N].high) ? 1 : 0;
    cov_b += (f[Term::B].low <= tr.B && tr.B <= f[Term::B].high) ? 1 : 0;
    cov_q += (f[Term::Q].low <= tr.Q && tr.Q <= f[Term::Q].high) ? 1 : 0;
    chi2_sum += f.chi2;
    dof_sum += f.dof;
  }
  EXPECT_GE(cov_n, 0.91 * n);
  EXPECT_LE(cov_n, 0.99 * n);
  EXPECT_GE(cov_b, 0.91 * n);
  EXPECT_LE(cov_b, 0.99 * n);
  EXPECT_GE(cov_q, 0.91 * n);
  // The Bartlett-corrected deviance averages its degrees of freedom.
  EXPECT_NEAR(chi2_sum / dof_sum, 1.0, 0.08);
}

TEST(Fit, ConfidenceDistributionMatchesTheIntervals) {
  std::mt19937_64 rng(3);
  const FitResult f = fit_noise(noisy_points(Truth{}, rng));
  for (Term t : {Term::N, Term::B}) {
    ASSERT_TRUE(f[t].resolved);
    EXPECT_NEAR(f.cdf(t, f[t].low), 0.025, 2e-3);
    EXPECT_NEAR(f.cdf(t, f[t].high), 0.975, 2e-3);
    EXPECT_NEAR(f.cdf(t, f[t].estimate), 0.5, 0.05);  // the estimate averages the two sets' (term-choice.md)
    EXPECT_LT(f.cdf(t, 0.5 * f[t].estimate), f.cdf(t, 0.9 * f[t].estimate));
    EXPECT_EQ(f.cdf(t, 0.0), 0.0);
  }
}

TEST(Fit, SigmaIsTheDeltaMethodStandardErrorOfResolvedTerms) {
  std::mt19937_64 rng(11);
  const FitResult f = fit_noise(noisy_points(Truth{}, rng));
  for (Term t : {Term::N, Term::B, Term::Q}) {
    const auto& c = f[t];
    // Half-width of the 95 % interval ≈ 1.96 σ (profile vs Wald, allow 40 %).
    const double half = 0.5 * (c.high - c.low);
    EXPECT_NEAR(half / (1.96 * c.sigma), 1.0, 0.4) << term_name(t);
  }
}

TEST(Fit, FitRangeAndDisabledTerms) {
  const auto pts = octave_points(Truth{});
  FitOptions o;
  o.tau_min_s = 1.0;
  o.tau_max_s = 1000.0;
  const FitResult f = fit_noise(pts, o);
  for (const auto& p : f.used) {
    EXPECT_GE(p.tau_s, 1.0);
    EXPECT_LE(p.tau_s, 1000.0);
  }
  FitOptions o2;
  o2.enabled[static_cast<int>(Term::R)] = false;
  const FitResult g = fit_noise(pts, o2);
  EXPECT_FALSE(g[Term::R].enabled);
  EXPECT_EQ(g.c[static_cast<int>(Term::R)], 0.0);
  EXPECT_NEAR(coefficient_from_c(Term::N, g.c[static_cast<int>(Term::N)]) / 0.001, 1.0, 1e-3);
}

TEST(FitErrors, TooFewPointsConstantDataAndEmptyRange) {
  auto pts = octave_points(Truth{});
  pts.resize(5);
  EXPECT_THROW(fit_noise(pts), AnalysisError);
  auto flat = octave_points(Truth{});
  for (auto& p : flat) p.var = 0.0;
  try {
    fit_noise(flat);
    FAIL() << "constant data accepted";
  } catch (const AnalysisError& e) {
    EXPECT_NE(std::string(e.what()).find("no noise"), std::string::npos);
  }
  FitOptions o;
  o.tau_min_s = 100.0;
  o.tau_max_s = 300.0;
  try {
    fit_noise(octave_points(Truth{}), o);
    FAIL() << "narrow range accepted";
  } catch (const AnalysisError& e) {
    EXPECT_NE(std::string(e.what()).find("fit range"), std::string::npos);
  }
  auto nan = octave_points(Truth{});
  nan[3].var = std::nan("");
  EXPECT_THROW(fit_noise(nan), AnalysisError);
}

TEST(SlopeReadout, ReadsTheLinesWhereOneTermDominates) {
  AllanResult a;
  const double n = 0.002, b = 0.01;
  for (double tau = 0.01; tau < 1e5; tau *= 2) {
    AllanPoint p;
    p.tau_s = tau;
    // ARW, then a floor, then RRW K = 0.05 °/h/√h.
    p.var = n * n * 3600.0 / tau + (2 * std::log(2.0) / M_PI) * b * b * 0 + 0.05 * 0.05 / 3600.0 * tau / 3.0;
    p.dev = std::sqrt(p.var);
    a.points.push_back(p);
  }
  const SlopeReadout s = slope_readout(a);
  ASSERT_TRUE(s.N.has_value());
  EXPECT_NEAR(*s.N / n, 1.0, 0.02);
  ASSERT_TRUE(s.K.has_value());
  EXPECT_NEAR(*s.K / 0.05, 1.0, 0.02);
  // With no flicker, σ_min/0.664 still "finds" a B: the documented bias (1.62·√(NK) scale).
  ASSERT_TRUE(s.B.has_value());
  EXPECT_GT(*s.B, 0.0);
}

}  // namespace
}  // namespace rwcalc

namespace rwcalc {
namespace {

/// Exact EDF of the overlapping AVAR for discrete white rate (ARW) by direct summation: z_i is the
/// difference of two adjacent m-sums of white rate, Var(Σz²) = Σ_h (M − |h|)·2γ(h)².
double brute_force_wfm_edf(std::int64_t m, std::int64_t n_phase) {
  const std::int64_t big_m = n_phase - 2 * m;
  std::vector<double> w(static_cast<std::size_t>(2 * m), 1.0);
  for (std::int64_t k = 0; k < m; ++k) w[static_cast<std::size_t>(k)] = -1.0;
  const auto len = static_cast<std::int64_t>(w.size());
  double var = 0;
  for (std::int64_t h = -(len - 1); h < len; ++h) {
    double g = 0;
    for (std::int64_t k = 0; k < len; ++k)
      if (k + h >= 0 && k + h < len) g += w[static_cast<std::size_t>(k)] * w[static_cast<std::size_t>(k + h)];
    var += static_cast<double>(big_m - std::abs(h)) * 2.0 * g * g;
  }
  const double e = static_cast<double>(big_m) * 2.0 * static_cast<double>(m);
  return 2.0 * e * e / var;
}

TEST(AvCovariance, DiagonalIsTheExactEdfForWhiteRate) {
  // 1001 phase points as in Stable32's PHASE.DAT. The model covariance is exact for discrete white
  // rate increments; Greenhall–Riley's tabulated EDFs (782, 540.7, 306.1, 166.0, 86.37, 43.35,
  // 21.24, 9.551; noise-models §4.2) assume a slightly different continuous-time model at small m
  // and agree with the exact values from m ≈ 32 on.
  const std::array<double, 8> greenhall{782.0, 540.7, 306.1, 166.0, 86.37, 43.35, 21.24, 9.551};
  std::vector<FitPoint> pts;
  Eigen::Matrix<double, kTermCount, 1> c = Eigen::Matrix<double, kTermCount, 1>::Zero();
  c[1] = 2.0;  // N² in (°/h)²·s
  for (int k = 0; k < 8; ++k) {
    const std::int64_t m = std::int64_t{1} << k;
    const double tau = static_cast<double>(m);
    pts.push_back({tau, c[1] / tau, 0, m, 1001 - 2 * m});
  }
  const Eigen::MatrixXd cov = av_covariance(pts, c);
  for (int k = 0; k < 8; ++k) {
    const double nu = 2.0 * pts[k].var * pts[k].var / cov(k, k);
    EXPECT_NEAR(nu / brute_force_wfm_edf(pts[k].m, 1001), 1.0, 0.01) << "m = " << pts[k].m;
    if (pts[k].m >= 32) {
      EXPECT_NEAR(nu / greenhall[static_cast<std::size_t>(k)], 1.0, 0.04) << "m = " << pts[k].m;
    }
  }
  // Neighbouring octaves are positively correlated, distant ones much less.
  const double r01 = cov(3, 4) / std::sqrt(cov(3, 3) * cov(4, 4));
  const double r03 = cov(3, 6) / std::sqrt(cov(3, 3) * cov(6, 6));
  EXPECT_GT(r01, 0.2);
  EXPECT_LT(r03, r01);
}

TEST(AvCovariance, WhiteAngleNoiseMatchesItsClosedForm) {
  // White angle noise (Q): σ̂² = Σz²/(2τ²M) with z a fixed-weight sum of 3 samples, lag-structured:
  // Var(z) = 6Q², Cov lag m: −4Q², lag 2m: Q². Var(σ̂²) = 2(36 + 2·16 + 2·1)Q⁴·M/(4τ⁴M²) for M ≫ m.
  std::vector<FitPoint> pts;
  Eigen::Matrix<double, kTermCount, 1> c = Eigen::Matrix<double, kTermCount, 1>::Zero();
  c[0] = 0.5;
  const std::int64_t m = 4, terms = 100000;
  const double tau = 0.01;
  pts.push_back({tau, 3 * c[0] / (tau * tau), 0, m, terms});
  const Eigen::MatrixXd cov = av_covariance(pts, c);
  const double expect = 2.0 * (36 + 32 + 2) * c[0] * c[0] / (4 * std::pow(tau, 4) * terms);
  EXPECT_NEAR(cov(0, 0) / expect, 1.0, 1e-3);
}

TEST(AvCovariance, WhiteAngleCorrelationReachesDistantOctaves) {
  // White angle noise: z at m = 1 and at M = 64 share single samples; each z_M sample meets three
  // z_1 terms, Σ Cov² = s⁴·(1 + 4 + 1)·(1 + 4 + 1) per z_M term, so Cov(σ̂²_1, σ̂²_M) =
  // 2·36·s⁴/(4 τ1² τM² n) and the correlation is 72/140 ≈ 0.51 however far apart the octaves are.
  Eigen::Matrix<double, kTermCount, 1> c = Eigen::Matrix<double, kTermCount, 1>::Zero();
  c[0] = 0.3;
  const double tau0 = 0.01;
  const std::int64_t n = 200000;
  std::vector<FitPoint> pts;
  for (std::int64_t m : {std::int64_t{1}, std::int64_t{64}})
    pts.push_back({static_cast<double>(m) * tau0, 3 * c[0] / std::pow(static_cast<double>(m) * tau0, 2), 0, m, n});
  const Eigen::MatrixXd cov = av_covariance(pts, c);
  const double ta = pts[0].tau_s, tb = pts[1].tau_s;
  const double expect = 72.0 * c[0] * c[0] / (4 * ta * ta * tb * tb * static_cast<double>(n));
  EXPECT_NEAR(cov(0, 1) / expect, 1.0, 0.01);
  EXPECT_NEAR(cov(0, 1) / std::sqrt(cov(0, 0) * cov(1, 1)), 72.0 / 140.0, 0.01);
}

TEST(Fit, ModelErrorFloorOnlyWhereTheResidualsCallForIt) {
  Truth tr;
  // Points that follow the model: no floor, full weight.
  const FitResult exact = fit_noise(octave_points(tr));
  EXPECT_GE(exact.options.edf_cap, 1e11);
  // A ±1 % ripple on σ² (a model defect far above the sampling scatter of the 10⁵-EDF short-τ
  // points): a floor is estimated (the Paule–Mandel sum spreads it over all residual degrees of
  // freedom, so it comes out below the ripple), and the interval of Q, which those points
  // determine, widens accordingly.
  auto pts = octave_points(tr);
  for (std::size_t k = 0; k < pts.size(); ++k) pts[k].var *= (k % 2 == 0 ? 1.01 : 0.99);
  const FitResult rippled = fit_noise(pts);
  const double s = std::sqrt(2.0 / rippled.options.edf_cap);  // relative floor on σ²
  std::printf("floor %.4f; Q interval %g (exact %g)\n", s, rippled[Term::Q].high - rippled[Term::Q].low,
              exact[Term::Q].high - exact[Term::Q].low);
  EXPECT_GT(s, 0.003);
  EXPECT_LE(s, 0.0142);
  EXPECT_GT(rippled[Term::Q].high - rippled[Term::Q].low, 1.3 * (exact[Term::Q].high - exact[Term::Q].low));
  // A fixed floor is used as given.
  FitOptions fixed;
  fixed.edf_cap = 5e3;
  EXPECT_EQ(fit_noise(pts, fixed).options.edf_cap, 5e3);
}

}  // namespace
}  // namespace rwcalc
