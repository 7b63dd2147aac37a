// The counter read-out in the fit (docs/analysis.md, "The counter read-out"), on two generators:
// rwcalc's simulator with its default read-out (a plain counter) and a second one written here in the
// frequency domain (FFT-shaped flicker, white rate, its own counter with or without dither), which
// shares no code with the simulator or the fit (tests/independent_gyro.hpp). Each record: fit accepted (p ≥ 0.001), the
// read-out the fit chose, N and B inside their 95 % intervals, and a verdict that is right or stated below P = 0.9.
// RWCALC_COUNTER_RECORDS scales every set (the docs' table comes from larger counts).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "independent_gyro.hpp"
#include "population.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/noise_model.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/simulate.hpp"
#include "test_fit_sim.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

struct Outcome {
  bool accepted = false, counter = false, n_in = false, b_in = false, verdict_ok = false, k_resolved = false;
  double p_class = 0;  // stated probability of the overall class
  bool class_right = false;
};

Recording independent_record(double n, double b, double seconds, double rate_hz, bool dither, std::uint64_t seed) {
  test::IndependentSettings s;
  s.seconds = seconds;
  s.rate_hz = rate_hz;
  s.dither = dither;
  return test::independent_record({n, b, 0.0}, s, seed);
}

Outcome judge(const Recording& rec, double n, double b) {
  const AnalysisOptions o;
  const AnalysisResult r = analyze(rec, o);
  Outcome out;
  out.accepted = r.fit.p_value >= 0.001;
  out.counter = r.fit.counter_readout;
  out.n_in = r.fit[Term::N].low <= n && n <= r.fit[Term::N].high;
  out.b_in = r.fit[Term::B].low <= b && b <= r.fit[Term::B].high;
  out.k_resolved = r.fit[Term::K].resolved;  // the records have no rate random walk
  out.class_right = test::true_class(b, n, o.verdict.table) == r.verdict.cls;
  out.p_class = r.verdict.p_class;
  out.verdict_ok = out.class_right || r.verdict.p_class < 0.9;
  if (std::getenv("RWCALC_COUNTER_VERBOSE"))
    std::printf(
        "record N %.6f [%.6f, %.6f] truth %.6f; B %.5f [%.5f, %.5f] truth %.5f; chi2/dof %.2f; class %d P %.2f\n",
        r.fit[Term::N].estimate, r.fit[Term::N].low, r.fit[Term::N].high, n, r.fit[Term::B].estimate,
        r.fit[Term::B].low, r.fit[Term::B].high, b, r.fit.chi2_per_dof, r.verdict.cls.value_or(0), r.verdict.p_class);
  return out;
}

/// `ci` records by default, `acceptance` under RWCALC_ACCEPTANCE=1 (tests/support/population.hpp);
/// RWCALC_COUNTER_RECORDS sets the count.
int records(int ci, int acceptance) { return test::population("RWCALC_COUNTER_RECORDS", ci, acceptance, 4); }

/// Runs `count` records (N in 0.0005–0.001 °/√h, B in 0.005–0.01 °/h, drawn per record) in parallel
/// and checks the set; `wrong_share` of the records may state a wrong class at P ≥ 0.9.
template <class Make>
void check_set(const char* name, int count, bool counter_expected, double wrong_share, Make make) {
  std::vector<Outcome> out(static_cast<std::size_t>(count));
  parallel_for(out.size(), [&](std::size_t i) {
    std::mt19937_64 g(7000 + i);
    std::uniform_real_distribution<double> un(0.0005, 0.001), ub(0.005, 0.01);
    const double n = un(g), b = ub(g);
    out[i] = judge(make(n, b, 7100 + i), n, b);
  });
  int accepted = 0, readout = 0, n_in = 0, b_in = 0, verdict_ok = 0, k_resolved = 0;
  for (const Outcome& o : out) {
    accepted += o.accepted;
    readout += o.counter == counter_expected;
    n_in += o.n_in;
    b_in += o.b_in;
    verdict_ok += o.verdict_ok;
    k_resolved += o.k_resolved;
  }
  const double c = count;
  std::printf(
      "%s, %d records: fit accepted %d, read-out %s %d, N covered %.3f, B covered %.3f, verdict right or "
      "P < 0.9 %d, K resolved (none in the truth) %d\n",
      name, count, accepted, counter_expected ? "counter" : "white", readout, n_in / c, b_in / c, verdict_ok,
      k_resolved);
  const double tol = 2.5 * std::sqrt(0.95 * 0.05 / c);
  EXPECT_GE(accepted, std::floor(0.95 * c)) << name;
  EXPECT_EQ(readout, count) << name;
  EXPECT_NEAR(n_in / c, 0.95, tol) << name;
  EXPECT_NEAR(b_in / c, 0.95, tol) << name;
  EXPECT_GE(verdict_ok, count - std::floor(wrong_share * c)) << name;
  EXPECT_LE(k_resolved, std::max(1.0, 0.05 * c)) << name;
}

TEST(CounterReadout, SimulatorDefaultReadoutTwoHourRecords) {
  check_set("simulate's default read-out, 2 h at 400 Hz", records(8, 24), true, 0.0,
            [](double n, double b, std::uint64_t seed) {
              SimulationSettings s;
              s.seed = seed;
              return test::simulated_gyro(n, b, s, ReadoutMode::Counting);
            });
}

TEST(CounterReadout, IndependentGeneratorPlainCounter) {
  // One record in 48 (N 0.00055, B 0.0073 °/h) settles with N at 0 and B 1.4× the truth, stated class 3
  // at P = 0.97 (docs/calibration.md, "The counter read-out"): 5 % are allowed.
  check_set("frequency-domain generator, plain counter, 30 min at 400 Hz", records(12, 48), true, 0.05,
            [](double n, double b, std::uint64_t seed) {
              return independent_record(n, b, 1800.0, 400.0, false, seed);
            });
}

TEST(CounterReadout, IndependentGeneratorDitheredCounter) {
  check_set("frequency-domain generator, dithered counter, 30 min at 400 Hz", records(8, 24), false, 0.0,
            [](double n, double b, std::uint64_t seed) { return independent_record(n, b, 1800.0, 400.0, true, seed); });
}

}  // namespace
}  // namespace rwcalc
