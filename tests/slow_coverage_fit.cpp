// Coverage of the fitted N and B intervals and calibration of the verdict probabilities, on seeded
// records from the project's simulator (exact Kasdin flicker, white dither-like read-out). Two sets
// (docs/calibration.md):
// - short: 30 min at 100 Hz with a pulse weight scaled so that the quantization/ARW/flicker
//   cross-overs sit at the same fractions of the record as in a 2-h 400 Hz GL-2D run;
// - full: 2 h at 400 Hz with the GL-2D pulse weight 0.92″ (16× the samples, so N rests on far more
//   degrees of freedom and any long-τ misfit weighs more in standardised units).
// The docs' tables come from 480 and 300 records (RWCALC_ACCEPTANCE=1 runs 480 and 60,
// tests/support/population.hpp); RWCALC_COVERAGE_RECORDS and RWCALC_COVERAGE_FULL_RECORDS set the
// counts. The bounds follow from the binomial spread at the count run.
#include <gtest/gtest.h>

#include <atomic>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <cstdlib>
#include <random>
#include <thread>

#include "population.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

struct Outcome {
  double z_n, z_b;  // probit of the confidence distribution at the truth: N(0, 1) when calibrated
  bool n_in, b_in;
  double p_class;    // probability of the stated overall class
  bool class_right;  // the true class equals the stated one
  double p_b2;       // P(B ≤ class-2 limit)
  bool b2_true;
};

/// One set of records: length, rate, pulse weight and the range N is drawn from.
struct RecordSet {
  const char* name;
  double duration_s, rate_hz, scale_arcsec, n_low, n_high;
  std::uint64_t seed;
};
// N scaled by 1/2 for the 4× shorter record keeps the ARW/flicker cross-over at T/20.
constexpr RecordSet kShort{"30-min 100-Hz", 1800.0, 100.0, 0.2, 0.0004, 0.0011, 1000};
constexpr RecordSet kFull{"2-h 400-Hz", 7200.0, 400.0, 0.92, 0.0008, 0.0022, 50000};

double probit(double p) {
  return boost::math::quantile(boost::math::normal_distribution<double>(), std::clamp(p, 1e-15, 1.0 - 1e-15));
}

Outcome run_one(const RecordSet& set, std::uint64_t seed, double n, double b) {
  SimulationSettings s;
  s.duration_s = set.duration_s;
  s.rate_hz = set.rate_hz;
  s.scale_arcsec = set.scale_arcsec;
  s.seed = seed;
  const Recording rec = test::simulated_gyro(n, b, s);
  AnalysisOptions o;
  const AnalysisResult r = analyze(rec, o);
  Outcome out{};
  out.z_n = probit(r.fit.cdf(Term::N, n));
  out.z_b = probit(r.fit.cdf(Term::B, b));
  out.n_in = r.fit[Term::N].low <= n && n <= r.fit[Term::N].high;
  out.b_in = r.fit[Term::B].low <= b && b <= r.fit[Term::B].high;
  out.p_class = r.verdict.p_class;
  out.class_right = test::true_class(b, n, o.verdict.table) == r.verdict.cls;
  out.p_b2 = r.verdict.B.p_meets[1];
  out.b2_true = b <= 0.008;
  return out;
}

/// Records i = 0 … count − 1 of a set (coefficients spread across the class-1/2/3 limits, so that
/// verdicts of every confidence occur), on two threads.
std::vector<Outcome> run_set(const RecordSet& set, int count) {
  std::vector<Outcome> out(static_cast<std::size_t>(count));
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i = next++; i < count; i = next++) {
      std::mt19937_64 g(set.seed + 8000 + static_cast<std::uint64_t>(i));
      std::uniform_real_distribution<double> un(set.n_low, set.n_high), ub(0.003, 0.011);
      const double n = un(g), b = ub(g);
      out[static_cast<std::size_t>(i)] = run_one(set, set.seed + static_cast<std::uint64_t>(i), n, b);
    }
  };
  std::thread t2(work);
  work();
  t2.join();
  return out;
}

/// Coverage of the 95 % intervals: within 2.5 binomial standard errors of 0.95 at this count.
void check_coverage(const RecordSet& set, const std::vector<Outcome>& out) {
  const double count = static_cast<double>(out.size());
  const double tol = 2.5 * std::sqrt(0.95 * 0.05 / count);
  for (const bool is_n : {true, false}) {
    double in = 0, s = 0, s2 = 0;
    for (const auto& o : out) {
      in += (is_n ? o.n_in : o.b_in) ? 1 : 0;
      const double z = is_n ? o.z_n : o.z_b;
      s += z;
      s2 += z * z;
    }
    const double cover = in / count, mean = s / count, sd = std::sqrt(s2 / count - mean * mean);
    std::printf("%s, %d records: %s interval holds the truth in %.3f (bound 0.95 ± %.3f); probit mean %+.3f, sd %.3f\n",
                set.name, static_cast<int>(count), is_n ? "N" : "B", cover, tol, mean, sd);
    // B averaged over the fits with and without K is wider than it needs to be on short records
    // (0.975 held, probit sd 0.87 on the 30-min set; docs/term-choice.md): conservative, never
    // overconfident, so for B the check is one-sided above by a further binomial error.
    const double wide = is_n ? 0.0 : tol;
    EXPECT_GE(cover, 0.95 - tol) << set.name << (is_n ? " N" : " B");
    EXPECT_LE(cover, 0.95 + tol + wide) << set.name << (is_n ? " N" : " B");
    // The probit's standard deviation is 1 when the intervals have the right width; its sampling
    // standard error is about 1/√(2·count). Too wide (sd below 1) is allowed as far for B.
    const double sd_tol = std::max(0.1, 2.5 / std::sqrt(2.0 * count));
    EXPECT_LE(sd, 1.0 + sd_tol) << set.name << (is_n ? " N" : " B");
    EXPECT_GE(sd, 1.0 - sd_tol - (is_n ? 0.0 : sd_tol)) << set.name << (is_n ? " N" : " B");
  }
}

/// Calibration: bin the stated probabilities; in each bin the share of right verdicts must match
/// the mean stated probability within 0.05, or within 2.5 Monte-Carlo standard errors where the bin
/// is too small to resolve 0.05 (the standard error of the share under calibration being
/// √(Σ p(1 − p))/count).
template <class P, class R>
void check_calibration(const char* what, const std::vector<Outcome>& out, P p_of, R right_of) {
  const std::array<double, 5> edges{0.0, 0.5, 0.7, 0.9, 1.0001};
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    int cnt = 0, hit = 0;
    double ps = 0, pq = 0;
    for (const auto& o : out) {
      const double p = p_of(o);
      if (p < edges[k] || p >= edges[k + 1]) continue;
      ++cnt;
      ps += p;
      pq += p * (1 - p);
      hit += right_of(o) ? 1 : 0;
    }
    if (cnt < 10) continue;
    const double pm = ps / cnt, share = double(hit) / cnt;
    const double se = std::sqrt(pq) / cnt;
    std::printf("%s: stated %.2f..%.2f: %d verdicts, mean P %.3f, share right %.3f (%+.3f, %+.1f MC s.e.)\n", what,
                edges[k], std::min(edges[k + 1], 1.0), cnt, pm, share, share - pm, (share - pm) / se);
    EXPECT_LE(std::abs(share - pm), std::max(0.05, 2.5 * se)) << what << " bin " << k;
  }
}

void check_set(const RecordSet& set, const std::vector<Outcome>& out) {
  check_coverage(set, out);
  check_calibration(
      "overall class", out, [](const Outcome& o) { return o.p_class; }, [](const Outcome& o) { return o.class_right; });
  check_calibration(
      "P(B <= 0.008)", out, [](const Outcome& o) { return std::max(o.p_b2, 1 - o.p_b2); },
      [](const Outcome& o) { return (o.p_b2 >= 0.5) == o.b2_true; });
}

TEST(SlowCoverage, IntervalsAndVerdictProbabilitiesOnShortRecords) {
  check_set(kShort, run_set(kShort, test::population("RWCALC_COVERAGE_RECORDS", 100, 480, 20)));
}

TEST(SlowCoverage, IntervalsAndVerdictProbabilitiesOnFullLengthRecords) {
  check_set(kFull, run_set(kFull, test::population("RWCALC_COVERAGE_FULL_RECORDS", 12, 60, 12)));
}

}  // namespace
}  // namespace rwcalc
