// The simulator's Ensemble path and ensembles: the analytic size of its departure from the exact
// flicker, that it changes nothing but the flicker, thread-count independence, error propagation.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "rwcalc/ensemble.hpp"
#include "rwcalc/error.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;

using test::gl2d_model;

SimulationSettings short_record(std::size_t samples = 20000) {
  SimulationSettings s;
  s.duration_s = static_cast<double>(samples) / 400.0;
  s.seed = 7;
  return s;
}

TEST(FastFlickerAvar, EqualsTheExactKasdinAvWithoutDecimation) {
  for (std::size_t m : {1, 2, 3, 7, 16, 100, 1000})
    EXPECT_NEAR(fast_flicker_avar(0.01, m, 1) / flicker_avar(0.01, m), 1.0, 1e-7) << m;
}

TEST(FastFlickerAvar, DepartsOnlyBelowAFewTauD) {
  const std::size_t d = flicker_decimation(400.0);
  EXPECT_EQ(d, 40u);
  EXPECT_EQ(flicker_decimation(100.0), 10u);
  EXPECT_EQ(flicker_decimation(1000.0), 100u);
  EXPECT_EQ(flicker_decimation(10.0), 1u);
  // The held flicker is smoother below τd; the deficit shrinks as (τd/τ): 20 % at τd, < 0.5 %
  // from 10·τd on, and the value tends to the exact one.
  const auto ratio = [&](std::size_t m) { return fast_flicker_avar(1.0, m, d) / flicker_avar(1.0, m); };
  EXPECT_NEAR(ratio(d), 0.80, 0.01);
  EXPECT_NEAR(ratio(1), 1.0 / static_cast<double>(d), 1e-3);  // one block edge in d phases
  for (std::size_t m = 10 * d; m <= 256 * d; m *= 2) {
    EXPECT_GT(ratio(m), 0.995) << m;
    EXPECT_LE(ratio(m), 1.0) << m;
  }
  double prev = 0.0;
  for (std::size_t m = 1; m <= 64 * d; m *= 2) {
    EXPECT_GT(ratio(m), prev) << m;
    prev = ratio(m);
  }
}

TEST(FastFlickerAvar, DepartureIsNegligibleInTheTotalAvOfAGl2dRecord) {
  // Relative to the whole model AV of a GL-2D record (quantization dominates below ~60 s), the
  // missing flicker AV is below 1e-4 at every τ: the ensemble path sees the same AV curve.
  const auto m = gl2d_model();
  const std::size_t d = flicker_decimation(400.0);
  double worst = 0.0;
  // (Above 256·D = 10240 samples fast_flicker_avar is the exact value by construction.)
  for (std::size_t k = 1; k <= 12'000; k = k < 64 ? k + 1 : k * 3 / 2) {
    const double total = theoretical_avar(m, 0.0025, 0.92, k);
    const double missing =
        flicker_avar(m.bias_instability_deg_per_h, k) - fast_flicker_avar(m.bias_instability_deg_per_h, k, d);
    EXPECT_GE(missing, -1e-12 * total) << k;
    worst = std::max(worst, missing / total);
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(worst, 1e-8);  // it is a real (if tiny) departure, not zero
}

TEST(EnsemblePath, ChangesOnlyTheFlickerTerm) {
  auto m = gl2d_model();
  m.bias_instability_deg_per_h = 0;  // without flicker both paths draw the same numbers
  Simulator exact(m, short_record()), fast(m, short_record(), SimulationPath::Ensemble);
  PhaseSeries a, b;
  exact.run(11, a);
  fast.run(11, b);
  EXPECT_EQ(a.counts, b.counts);
  // With flicker the records differ, but the flicker changes the angle by far less than the
  // record's spread over 50 s.
  Simulator exact_f(gl2d_model(), short_record()), fast_f(gl2d_model(), short_record(), SimulationPath::Ensemble);
  exact_f.run(11, a);
  fast_f.run(11, b);
  EXPECT_NE(a.counts, b.counts);
  EXPECT_EQ(a.counts.size(), b.counts.size());
}

TEST(EnsemblePath, RecordLengthNotAMultipleOfTheDecimation) {
  for (std::size_t n : {2u, 39u, 41u, 1001u}) {
    Simulator fast(gl2d_model(), short_record(n), SimulationPath::Ensemble);
    PhaseSeries p;
    fast.run(3, p);
    EXPECT_EQ(p.counts.size(), n + 1);
  }
}

TEST(EnsemblePath, GoldenChecksumPinsTheHeldFlicker) {
  // 1001 samples: the simulator's blocks end inside flicker holds of D = 40 samples and the record
  // ends inside a block, so this pins the held flicker across block edges with the rest of the
  // generator (Simulate.GoldenChecksumPinsTheGenerator pins the Exact path).
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.001;
  m.bias_instability_deg_per_h = 0.008;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.readout = ReadoutMode::White;
  Simulator fast(m, short_record(1001), SimulationPath::Ensemble);
  PhaseSeries p;
  fast.run(5, p);
  const auto c = pulse_increments(p);
  ASSERT_EQ(c.size(), 1001u);
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a over the increments' bytes
  for (const auto x : c)
    for (int i = 0; i < 8; ++i) {
      h ^= (static_cast<std::uint64_t>(x) >> (8 * i)) & 0xff;
      h *= 1099511628211ULL;
    }
  EXPECT_EQ(h, 13027080680862084314ULL) << h;
}

TEST(SimulateEnsemble, SameRecordsWhateverTheThreadCount) {
  const auto m = gl2d_model();
  const auto s = short_record();
  auto collect = [&](const char* threads) {
    const test::ScopedEnv env("RWCALC_THREADS", threads);
    std::vector<std::vector<std::int64_t>> out(7);
    simulate_ensemble(m, s, out.size(), [&](std::size_t r, const PhaseSeries& p) { out[r] = p.counts; });
    return out;
  };
  const auto one = collect("1"), two = collect("2"), four = collect("4");
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, four);
  for (std::size_t r = 1; r < one.size(); ++r) EXPECT_NE(one[r], one[0]) << r;
  // Realisation r is the Simulator's run with ensemble_seed(seed, r).
  Simulator sim(m, s, SimulationPath::Ensemble);
  PhaseSeries p;
  sim.run(ensemble_seed(s.seed, 3), p);
  EXPECT_EQ(p.counts, one[3]);
}

TEST(SimulateEnsemble, ErrorsPropagateAndInvalidModelsAreRejectedUpFront) {
  const auto s = short_record();
  {
    // One thread: the runs are consumed in order, so the failure at run 2 stops the ensemble there.
    const test::ScopedEnv env("RWCALC_THREADS", "1");
    int calls = 0;
    EXPECT_THROW(simulate_ensemble(gl2d_model(), s, 20,
                                   [&](std::size_t r, const PhaseSeries&) {
                                     ++calls;
                                     if (r == 2) throw std::runtime_error("consumer failed");
                                   }),
                 std::runtime_error);
    EXPECT_EQ(calls, 3);
  }
  {
    // Two threads: the consumer's exception reaches the caller, whichever thread raised it.
    const test::ScopedEnv env("RWCALC_THREADS", "2");
    EXPECT_THROW(simulate_ensemble(gl2d_model(), s, 20,
                                   [&](std::size_t r, const PhaseSeries&) {
                                     if (r == 2) throw std::runtime_error("consumer failed");
                                   }),
                 std::runtime_error);
  }
  auto bad = gl2d_model();
  bad.arw_deg_per_sqrt_h = -1;
  EXPECT_THROW(simulate_ensemble(bad, s, 3, [](std::size_t, const PhaseSeries&) {}), UsageError);
  int none = 0;
  simulate_ensemble(gl2d_model(), s, 0, [&](std::size_t, const PhaseSeries&) { ++none; });
  EXPECT_EQ(none, 0);
}

}  // namespace
