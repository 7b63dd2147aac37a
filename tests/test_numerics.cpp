// The numerics layer against known answers: the Gamma deviance and its mean (closed forms and a
// quadrature over the χ² law), the structure function (the IEEE 952 Allan variance of each term
// from it), non-negative least squares (a worked case, the Karush–Kuhn–Tucker conditions on random
// problems), golden-section minimisation (its cost and accuracy), Nelder–Mead (its minimum and how
// it says it stopped), and the exact integer sums against 128-bit brute force on both sides of the
// 64-bit path's bound.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "rwcalc/deviance.hpp"
#include "rwcalc/exact_sums.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/minimise.hpp"
#include "rwcalc/nnls.hpp"
#include "rwcalc/sample_variance.hpp"
#include "rwcalc/structure_function.hpp"

namespace {

using namespace rwcalc;

TEST(Deviance, ClosedForms) {
  EXPECT_EQ(gamma_deviance(3.0, 3.0, 7.0), 0.0);
  EXPECT_NEAR(gamma_deviance(2.0, 1.0, 10.0), 10.0 * (1.0 - std::numbers::ln2), 1e-14);
  EXPECT_NEAR(gamma_deviance(std::numbers::e, 1.0, 4.0), 4.0 * (std::numbers::e - 2.0), 1e-14);
  // Only the ratio counts.
  EXPECT_NEAR(gamma_deviance(0.5e-6, 1e-6, 3.0), gamma_deviance(0.5, 1.0, 3.0), 1e-14);
  // Near x = 1 it is ν(x − 1)²/2 to second order.
  EXPECT_NEAR(gamma_deviance(1.001, 1.0, 100.0), 100.0 * 0.5e-6, 1e-7);
}

TEST(Deviance, SignedResidual) {
  const double d = gamma_deviance(0.5, 1.0, 4.0);
  EXPECT_NEAR(deviance_residual(0.5, 1.0, 4.0), -std::sqrt(d), 1e-15);
  EXPECT_NEAR(deviance_residual(2.0, 1.0, 4.0), std::sqrt(gamma_deviance(2.0, 1.0, 4.0)), 1e-15);
  EXPECT_EQ(deviance_residual(1.0, 1.0, 4.0), 0.0);
  EXPECT_EQ(deviance_residual(0.0, 1.0, 4.0), 0.0);
  EXPECT_EQ(deviance_residual(1.0, 0.0, 4.0), 0.0);
  EXPECT_EQ(deviance_residual(1.0, -1.0, 4.0), 0.0);
  EXPECT_EQ(deviance_residual(1.0, 2.0, 0.0), 0.0);
}

TEST(Deviance, MeanMatchesTheDigammaClosedFormsAndAQuadrature) {
  const double euler = 0.57721566490153286;
  EXPECT_NEAR(gamma_deviance_mean(2.0), 2.0 * euler, 1e-14);                // −2ψ(1)
  EXPECT_NEAR(gamma_deviance_mean(1.0), euler + std::numbers::ln2, 1e-14);  // −(ψ(½) + ln 2)
  // The large-ν series meets the exact form where it takes over.
  EXPECT_NEAR(gamma_deviance_mean(1000.0), 1.0 + 1.0 / 3000.0, 1e-9);
  EXPECT_NEAR(gamma_deviance_mean(1000.5), 1.0 + 1.0 / 3001.5, 1e-9);
  // E[ν(x − 1 − ln x)] for x ~ χ²_ν/ν by Simpson's rule on the density.
  for (const double nu : {3.0, 8.0, 40.0}) {
    const boost::math::chi_squared chi2(nu);
    const int steps = 400000;
    const double hi = 25.0, h = hi / steps;  // P(χ²₃ > 75) ≈ 1e-15
    double sum = 0;
    for (int k = 1; k < steps; ++k) {
      const double x = k * h;
      sum += (k % 2 ? 4.0 : 2.0) * gamma_deviance(x, 1.0, nu) * nu * boost::math::pdf(chi2, nu * x);
    }
    EXPECT_NEAR(sum * h / 3.0, gamma_deviance_mean(nu), 1e-5) << "nu " << nu;
  }
}

TEST(Deviance, RootMeanOfAChiSquareVariance) {
  EXPECT_NEAR(chi_root_mean(1.0), std::sqrt(2.0 / std::numbers::pi), 1e-15);  // E|Z|
  EXPECT_NEAR(chi_root_mean(2.0), std::sqrt(std::numbers::pi) / 2.0, 1e-15);  // Rayleigh mean / √2
  EXPECT_NEAR(chi_root_mean(3.0), 2.0 * std::sqrt(2.0 / (3.0 * std::numbers::pi)), 1e-15);
  // 1 − 1/(4ν) + 1/(32ν²): the series where the ratio of Γs takes over, and on both sides of it.
  for (const double nu : {1e4, 1e8, 2e8})
    EXPECT_NEAR(chi_root_mean(nu), 1.0 - 1.0 / (4.0 * nu) + 1.0 / (32.0 * nu * nu), 1e-12) << nu;
  EXPECT_EQ(chi_root_mean(std::numeric_limits<double>::infinity()), 1.0);
  EXPECT_EQ(mean_unbiased_root(0.0, 1.0), 0.0);
  EXPECT_EQ(mean_unbiased_root(4.0, 0.0), 2.0);
  EXPECT_EQ(mean_unbiased_root(4.0, 2.0 * 16.0 / 0.9), 2.0);  // ν = 0.9: below kRootMinEdf
  EXPECT_DOUBLE_EQ(mean_unbiased_root(4.0, 2.0 * 16.0 / 1.0), 2.0 / chi_root_mean(1.0));
}

TEST(Deviance, UnbiasedRootIsRightOnAverage) {
  // v = c·χ²_ν/ν with its variance 2v²/ν known: √v is low by chi_root_mean(ν), the corrected root
  // is right on average (to three standard errors of 200 000 draws).
  std::mt19937_64 g(7);
  for (const double nu : {1.5, 5.0, 30.0}) {  // above kRootMinEdf
    std::chi_squared_distribution<double> chi2(nu);
    const int draws = 200000;
    double plain = 0, fixed = 0, sq = 0;
    for (int k = 0; k < draws; ++k) {
      const double v = 4.0 * chi2(g) / nu;
      const double r = mean_unbiased_root(v, 2.0 * v * v / nu);
      plain += std::sqrt(v);
      fixed += r;
      sq += r * r;
    }
    const double mean = fixed / draws, se = std::sqrt((sq / draws - mean * mean) / draws);
    EXPECT_NEAR(mean, 2.0, 3.0 * se) << "nu " << nu;
    EXPECT_LT(plain / draws, 2.0 - 10.0 * se) << "nu " << nu;  // the plain root is biased low
  }
}

TEST(StructureFunction, EachTerm) {
  const double u = 2.5;
  const auto d = term_structure_functions(u);
  EXPECT_EQ(d[0], 2.0);
  EXPECT_EQ(d[1], u);
  EXPECT_NEAR(d[2], -u * u * std::log(u) / std::numbers::pi, 1e-15);
  EXPECT_NEAR(d[3], -u * u * u / 6.0, 1e-14);
  EXPECT_NEAR(d[4], -u * u * u * u / 12.0, 1e-14);
  for (const double x : {0.0, -1.0}) {
    EXPECT_EQ(structure_function({1, 1, 1, 1, 1}, x), 0.0);
    for (double v : term_structure_functions(x)) EXPECT_EQ(v, 0.0);
  }
  // Linear in the coefficients.
  const std::array<double, 5> c{0.3, 2.0, 0.7, 1.5, 0.2};
  double sum = 0;
  for (std::size_t i = 0; i < c.size(); ++i) sum += c[i] * d[i];
  EXPECT_NEAR(structure_function(c, u), sum, 1e-13);
}

TEST(StructureFunction, GivesEachTermsAllanVariance) {
  // AV(τ) = E[(θ(2τ) − 2θ(τ) + θ(0))²]/(2τ²) = (4D(τ) − D(2τ))/(2τ²): IEEE 952's 3Q²/τ², N²/τ,
  // (2 ln 2/π)B², K²τ/3, R²τ²/2.
  for (const double tau : {0.01, 1.0, 300.0})
    for (std::size_t i = 0; i < 5; ++i) {
      std::array<double, 5> c{};
      c[i] = 1.0;
      const double av = (4.0 * structure_function(c, tau) - structure_function(c, 2.0 * tau)) / (2.0 * tau * tau);
      const double want = term_basis(kAllTerms[i], tau);
      EXPECT_NEAR(av, want, 1e-11 * want) << "term " << i << " tau " << tau;
    }
}

Eigen::MatrixXd columns(std::initializer_list<std::initializer_list<double>> cols) {
  const auto p = static_cast<Eigen::Index>(cols.size());
  const auto n = static_cast<Eigen::Index>(cols.begin()->size());
  Eigen::MatrixXd g(n, p);
  Eigen::Index c = 0;
  for (const auto& col : cols) {
    Eigen::Index r = 0;
    for (double v : col) g(r++, c) = v;
    ++c;
  }
  return g;
}

TEST(Nnls, WorkedCase) {
  // A falling line y = 3 − t: its slope would be −1, so the optimum is the mean with slope 0.
  const Eigen::MatrixXd g = columns({{1, 1, 1, 1}, {0, 1, 2, 3}});
  const Eigen::Vector4d y(3, 2, 1, 0);
  const NnlsFit f = nnls(g, y, Eigen::Vector4d::Ones(), 0b11);
  EXPECT_NEAR(f.x[0], 1.5, 1e-14);
  EXPECT_EQ(f.x[1], 0.0);
  EXPECT_NEAR(f.chi2, 5.0, 1e-13);
  // A rising one is fitted unconstrained.
  const NnlsFit up = nnls(g, Eigen::Vector4d(1, 3, 5, 7), Eigen::Vector4d::Ones(), 0b11);
  EXPECT_NEAR(up.x[0], 1.0, 1e-13);
  EXPECT_NEAR(up.x[1], 2.0, 1e-13);
  EXPECT_NEAR(up.chi2, 0.0, 1e-20);
  // Only the free columns move: the slope alone, Σty/Σt² = 34/14.
  const NnlsFit slope = nnls(g, Eigen::Vector4d(1, 3, 5, 7), Eigen::Vector4d::Ones(), 0b10);
  EXPECT_EQ(slope.x[0], 0.0);
  EXPECT_NEAR(slope.x[1], 34.0 / 14.0, 1e-14);
  // Data no non-negative combination approaches: x = 0, χ² = Σ w y².
  const NnlsFit none = nnls(g, Eigen::Vector4d(-1, -2, -1, -2), Eigen::Vector4d(1, 2, 1, 2), 0b11);
  EXPECT_EQ(none.x, Eigen::Vector2d::Zero());
  EXPECT_NEAR(none.chi2, 1 + 8 + 1 + 8, 1e-13);
  // The slope allowed either sign: the falling line itself, while a negative mean still is not.
  const NnlsFit falling = nnls(g, y, Eigen::Vector4d::Ones(), 0b11, 0b10);
  EXPECT_NEAR(falling.x[0], 3.0, 1e-13);
  EXPECT_NEAR(falling.x[1], -1.0, 1e-13);
  const NnlsFit below = nnls(g, Eigen::Vector4d(-1, -2, -3, -4), Eigen::Vector4d::Ones(), 0b11, 0b10);
  EXPECT_EQ(below.x[0], 0.0);
  EXPECT_NEAR(below.x[1], -20.0 / 14.0, 1e-13);  // Σty/Σt² through the origin
}

TEST(Nnls, MeetsTheKarushKuhnTuckerConditions) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> weight(0.2, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Index n = 12, p = 5;
    Eigen::MatrixXd g(n, p);
    Eigen::VectorXd y(n), w(n);
    for (Eigen::Index r = 0; r < n; ++r) {
      for (Eigen::Index c = 0; c < p; ++c) g(r, c) = normal(rng);
      y[r] = normal(rng);
      w[r] = weight(rng);
    }
    const unsigned free = trial % 2 ? 0b11111u : 0b10110u;
    const unsigned sign_free = trial % 4 < 2 ? 0u : 0b00110u;  // columns of either sign, in both sets
    const NnlsFit f = nnls(g, y, w, free, sign_free);
    // The gradient of ½Σw(y − Gx)²: 0 where x > 0, ≥ 0 where x = 0; fixed columns stay 0.
    const Eigen::VectorXd grad = g.transpose() * (w.asDiagonal() * (g * f.x - y));
    for (Eigen::Index i = 0; i < p; ++i) {
      if (!(free & (1u << i))) {
        EXPECT_EQ(f.x[i], 0.0);
        continue;
      }
      if (sign_free & (1u << i)) {
        EXPECT_NEAR(grad[i], 0.0, 1e-9) << "trial " << trial;
        continue;
      }
      EXPECT_GE(f.x[i], 0.0);
      if (f.x[i] > 0) {
        EXPECT_NEAR(grad[i], 0.0, 1e-9) << "trial " << trial;
      } else {
        EXPECT_GE(grad[i], -1e-9) << "trial " << trial;
      }
    }
    EXPECT_NEAR(f.chi2, (w.array() * (y - g * f.x).array().square()).sum(), 1e-12);
  }
}

// The divisor n − 1, and no digits lost to a common level far above the spread (the one-pass
// Σx² − n·x̄² would return 0 or a negative number here).
TEST(SampleVariance, UnbiasedAndFreeOfTheCommonLevel) {
  const std::vector<double> v = {2, 4, 4, 4, 5, 5, 7, 9};
  EXPECT_DOUBLE_EQ(sample_variance(v), 32.0 / 7.0);
  std::vector<double> shifted = v;
  for (double& x : shifted) x += 1e9;
  EXPECT_NEAR(sample_variance(shifted), 32.0 / 7.0, 1e-6);
}

TEST(GoldenSection, FindsTheMinimumAtItsFixedCost) {
  int evals = 0;
  const auto parabola = [&](double x) {
    ++evals;
    return (x - 2.0) * (x - 2.0);
  };
  EXPECT_NEAR(golden_min(parabola, 0.0, 5.0, 60), 2.0, 1e-7);
  EXPECT_EQ(evals, 62);
  EXPECT_NEAR(golden_min([](double x) { return std::cos(x); }, 2.0, 4.0, 60), std::numbers::pi, 1e-7);
  EXPECT_NEAR(golden_max([](double x) { return -(x + 1.0) * (x + 1.0); }, -3.0, 4.0, 60), -1.0, 1e-7);
  // A monotone function: towards the lower end, the bracket 0.618^iters of the interval.
  const double x = golden_min([](double v) { return v; }, 0.0, 1.0, 20);
  EXPECT_LT(x, std::pow(0.6180339887498949, 20));
}

TEST(NelderMead, ConvergesOnRosenbrocksValleyAndSaysSo) {
  int evals = 0;
  const auto rosenbrock = [&](const std::vector<double>& x) {
    ++evals;
    return 100.0 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1.0 - x[0], 2);
  };
  const SimplexMinimum m = nelder_mead(rosenbrock, {-1.2, 1.0}, 0.5, 5000, 1e-14);
  EXPECT_EQ(m.termination.status, TerminationStatus::Converged);
  EXPECT_EQ(m.termination.iterations, evals);
  EXPECT_LT(evals, 5000);
  EXPECT_NEAR(m.x[0], 1.0, 1e-3);
  EXPECT_NEAR(m.x[1], 1.0, 2e-3);
}

TEST(NelderMead, StopsAtItsEvaluationLimitAndSaysSo) {
  const auto bowl = [](const std::vector<double>& x) { return x[0] * x[0] + 4.0 * x[1] * x[1] + 9.0 * x[2] * x[2]; };
  const SimplexMinimum m = nelder_mead(bowl, {3.0, -2.0, 1.0}, 1.0, 12, 1e-12);
  EXPECT_EQ(m.termination.status, TerminationStatus::IterationLimit);
  EXPECT_GE(m.termination.iterations, 12);
  // The best vertex seen so far is returned, never worse than the start.
  EXPECT_LE(bowl(m.x), bowl({3.0, -2.0, 1.0}));
}

struct Brute {
  i128 sum = 0, squares = 0, lag = 0;
};

Brute brute(const std::vector<std::int64_t>& v, std::size_t n, std::size_t pairs) {
  Brute b;
  for (std::size_t i = 0; i < n; ++i) {
    b.sum += v[i];
    b.squares += static_cast<i128>(v[i]) * v[i];
  }
  for (std::size_t i = 0; i < pairs; ++i) b.lag += static_cast<i128>(v[i]) * v[i + 1];
  return b;
}

TEST(ExactSums, EqualBruteForceOnBothSidesOfThe64BitBound) {
  std::mt19937_64 rng(11);
  for (const std::int64_t bound : {std::int64_t{1} << 26, std::int64_t{1} << 40, std::int64_t{1} << 50}) {
    std::uniform_int_distribution<std::int64_t> value(-bound, bound - 1);
    for (const std::size_t n : {std::size_t{1}, std::size_t{7}, kExactBlock}) {
      std::vector<std::int64_t> v(n + 1);
      for (auto& x : v) x = value(rng);
      for (const std::size_t pairs : {n - 1, n}) {
        ExactSums s;
        const bool fast = add_exact_sums<SumKinds::WithLag>(
            n, pairs, [&v](std::size_t i) { return static_cast<std::uint64_t>(v[i]); }, s);
        const Brute b = brute(v, n, pairs);
        EXPECT_EQ(static_cast<i128>(s.sum), b.sum);
        EXPECT_EQ(static_cast<i128>(s.squares), b.squares);
        EXPECT_EQ(static_cast<i128>(s.lag), b.lag);
        if (bound == std::int64_t{1} << 26) {
          EXPECT_TRUE(fast);
        } else if (n == kExactBlock) {
          EXPECT_FALSE(fast);
        }
      }
    }
  }
}

TEST(ExactSums, BoundOfTheFastPathAndTheKindsAdded) {
  const std::int64_t lim = std::int64_t{1} << 26;
  const auto run = [](std::vector<std::int64_t> v, ExactSums& s) {
    return add_exact_sums<SumKinds::Squares>(
        v.size(), 0, [&v](std::size_t i) { return static_cast<std::uint64_t>(v[i]); }, s);
  };
  ExactSums s;
  EXPECT_TRUE(run({lim - 1, -lim}, s));
  EXPECT_FALSE(run({lim}, s));
  EXPECT_FALSE(run({-lim - 1}, s));
  // Squares only: the sum and the lag stay untouched.
  EXPECT_EQ(static_cast<i128>(s.squares), static_cast<i128>(lim - 1) * (lim - 1) + static_cast<i128>(lim) * lim +
                                              static_cast<i128>(lim) * lim + static_cast<i128>(lim + 1) * (lim + 1));
  EXPECT_EQ(s.sum, 0u);
  EXPECT_EQ(s.lag, 0u);
  // The successor read for the last pair counts towards the bound.
  std::vector<std::int64_t> v{1, 2, lim};
  ExactSums t;
  EXPECT_FALSE(add_exact_sums<SumKinds::WithLag>(
      2, 2, [&v](std::size_t i) { return static_cast<std::uint64_t>(v[i]); }, t));
  EXPECT_EQ(static_cast<i128>(t.lag), 2 + 2 * static_cast<i128>(lim));
  EXPECT_EQ(static_cast<i128>(t.sum), 3);
}

}  // namespace
