// The diagnosis's acceptance on simulated records (label slow): slow lines named at 3.5× the
// flicker floor, clean records naming nothing, the same findings for every seed, and the 95 %
// intervals' coverage. The records are GL-2D-like (N 0.001 °/√h, B 0.005 °/h, counting read-out
// of 0.92″ pulses) at 40 Hz: the likelihood reads 10-s block means, which a higher rate would not
// change, and the suite stays short. Each population has its acceptance size under RWCALC_ACCEPTANCE=1
// and a smaller default whose bounds widen by the binomial error (tests/support/population.hpp).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <string>

#include "population.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/simulate.hpp"

namespace {

using namespace rwcalc;

constexpr double kT = 7200;
constexpr double kFloor = 0.6643 * 0.005;  ///< the flicker floor 0.6643·B, °/h

NoiseModel gl2d() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.001;
  m.bias_instability_deg_per_h = 0.005;
  m.earth_rate_deg_per_h = 12.43;
  return m;
}

DiagnoseResult run_case(const NoiseModel& m, std::uint64_t seed, std::uint64_t diagnosis_seed = 1) {
  SimulationSettings s;
  s.duration_s = kT;
  s.rate_hz = 40;
  s.scale_arcsec = 0.92;
  s.seed = seed;
  Recording rec;
  rec.source = fmt::format("simulated-{}", seed);
  rec.phase = simulate(m, s);
  rec.rate_hz = s.rate_hz;
  rec.samples = rec.phase.points() - 1;
  DiagnoseOptions o;
  o.seed = diagnosis_seed;
  return diagnose(rec, o);
}

const Finding* finding(const DiagnoseResult& r, Effect e) {
  for (const auto& f : r.findings)
    if (f.effect == e) return &f;
  return nullptr;
}

bool covers(const Finding& f, const char* name, double truth) {
  const FindingParameter& p = f.parameter(name);
  return p.low95 <= truth && truth <= p.high95;
}

/// At least `share` of `n` cases, set for the acceptance's `acceptance` cases and widened for fewer.
double at_least(double share, int n, int acceptance) {
  return n * (share - test::share_allowance(share, n, acceptance));
}

/// Named cases from which an interval's coverage is checked against the acceptance's 90–98 %.
constexpr int kCoverageCases = 18;

/// A fraction in [0, 1) drawn by the golden ratio: the cases spread evenly, no random stream.
double spread(int i) { return i * 0.6180339887498949 - std::floor(i * 0.6180339887498949); }

/// A case out of tolerance, for the log: what was named, and each detector's statistic against its
/// threshold.
void print_case(const std::string& what, const DiagnoseResult& r) {
  std::cout << "  " << what << " not in tolerance:";
  for (const Finding& e : r.findings) {
    std::cout << ' ' << finding_name(e.effect);
    for (const FindingParameter& p : e.parameters) std::cout << fmt::format(" {} {:.3g}", p.name, p.value);
  }
  std::cout << ", statistic/threshold";
  for (const auto& d : r.detectors)
    std::cout << fmt::format(" {} {:.1f}/{:.1f}", detector_name(d.effect), d.statistic, d.threshold);
  std::cout << '\n';
}

}  // namespace

// Slow lines of 3–5 cycles at 3.5× the flicker floor: named with frequency within 0.5/T and
// amplitude within 30 % in at least 90 % of records, with a positive out-of-sample gain. The line
// is never named as a Gauss–Markov term, nor is one named beside it: the counting read-out's
// sawtooth, correlated over a block or two, is in the Gauss–Markov test's null (docs/diagnosis.md).
TEST(DiagnoseAcceptance, SlowLinesAtThreeAndAHalfFloors) {
  const int n = test::population("RWCALC_DIAGNOSE_LINES", 8, 20);
  int named = 0, gauss_markov = 0, gain = 0, cover_f = 0, cover_a = 0;
  for (int i = 0; i < n; ++i) {
    NoiseModel m = gl2d();
    const double f = (3.0 + 2.0 * spread(i)) / kT, amp = 3.5 * kFloor;
    m.sinusoids.push_back({f, amp, 6.283 * spread(i + 7)});
    const DiagnoseResult r = run_case(m, 100 + static_cast<std::uint64_t>(i));
    if (const Finding* g = finding(r, Effect::GaussMarkov)) {
      ++gauss_markov;
      std::cout << fmt::format("  record {}: a Gauss-Markov term named (σ {:.3g} °/h, Tc {:.3g} s), statistic", i,
                               g->parameter("sigma").value, g->parameter("correlation_time").value);
      for (const auto& d : r.detectors) std::cout << fmt::format(" {} {:.1f}", detector_name(d.effect), d.statistic);
      std::cout << '\n';
    }
    const Finding* s = finding(r, Effect::Sinusoid);
    const bool ok = s && std::abs(s->parameter("frequency").value - f) < 0.5 / kT &&
                    std::abs(s->parameter("amplitude").value / amp - 1) < 0.3;
    if (!ok) print_case(fmt::format("record {} (f {:.3g} Hz)", i, f), r);
    if (!s) continue;
    named += ok;
    gain += r.gain.likelihood_holdout > 0;
    cover_f += covers(*s, "frequency", f);
    cover_a += covers(*s, "amplitude", amp);
  }
  std::cout << fmt::format(
      "slow lines at 3.5x: {}/{} named in tolerance, {} Gauss-Markov, {} with out-of-sample "
      "gain, frequency interval covers {}, amplitude interval {}\n",
      named, n, gauss_markov, gain, cover_f, cover_a);
  EXPECT_GE(named, at_least(0.9, n, 20));
  EXPECT_EQ(gauss_markov, 0);
  EXPECT_GE(gain, named - 1);
}

// Clean records: no family names anything in more than 2 % of them (its bound is α = 1 %). 100
// records with the counting read-out and 100 with the white one under RWCALC_ACCEPTANCE=1 (20 and
// 20 by default), each at most 2 per family: at least 98 % of the 200 clean records without a finding
// per family.
void expect_clean(ReadoutMode readout, std::uint64_t first_seed) {
  const int n = test::population("RWCALC_DIAGNOSE_CLEAN", 20, 100);
  std::array<int, kEffectCount> fired{};
  for (int i = 0; i < n; ++i) {
    NoiseModel m = gl2d();
    m.readout = readout;
    const DiagnoseResult r = run_case(m, first_seed + static_cast<std::uint64_t>(i));
    for (const auto& f : r.findings) ++fired[static_cast<std::size_t>(f.effect)];
  }
  for (std::size_t e = 0; e < kEffectCount; ++e) {
    std::cout << fmt::format("{}: named in {}/{} clean records\n", detector_name(static_cast<Effect>(e)), fired[e], n);
    EXPECT_LE(fired[e], 2) << detector_name(static_cast<Effect>(e));
  }
}

TEST(DiagnoseAcceptance, CleanRecordsNameNothingCountingReadout) { expect_clean(ReadoutMode::Counting, 5000); }
TEST(DiagnoseAcceptance, CleanRecordsNameNothingWhiteReadout) { expect_clean(ReadoutMode::White, 6000); }

// The same record gives the same findings, parameters and intervals for every --seed.
TEST(DiagnoseAcceptance, SameFindingsForEverySeed) {
  NoiseModel m = gl2d();
  m.sinusoids.push_back({4.2 / kT, 5 * kFloor, 0.4});
  m.bias_steps.push_back({4000, 0.05});
  const std::string first = to_json(run_case(m, 77, 1))["findings"].dump();
  EXPECT_NE(first.find("bias_step"), std::string::npos) << first;
  const auto last = static_cast<std::uint64_t>(test::population("RWCALC_DIAGNOSE_SEEDS", 3, 10, 2));
  for (std::uint64_t seed = 2; seed <= last; ++seed)
    EXPECT_EQ(to_json(run_case(m, 77, seed))["findings"].dump(), first);
}

// Bias steps of 0.04–0.08 °/h: named, and the 95 % intervals of their time and size cover the
// truth in at least 85 % of the named cases (acceptance: 90–98 %; 20 cases resolve it to ±5 %).
TEST(DiagnoseAcceptance, StepIntervalsCover) {
  const int n = test::population("RWCALC_DIAGNOSE_STEPS", 8, 20);
  int named = 0, cover_t = 0, cover_s = 0;
  for (int i = 0; i < n; ++i) {
    NoiseModel m = gl2d();
    const double t = 1000 + 5000 * spread(i), size = (0.04 + 0.04 * spread(i + 3)) * (i % 2 ? 1 : -1);
    m.bias_steps.push_back({t, size});
    const DiagnoseResult r = run_case(m, 3000 + static_cast<std::uint64_t>(i));
    const Finding* s = finding(r, Effect::BiasStep);
    if (!s) continue;
    ++named;
    cover_t += covers(*s, "time", t);
    cover_s += covers(*s, "size", size);
  }
  std::cout << fmt::format("steps: {}/{} named, time interval covers {}, size interval covers {}\n", named, n, cover_t,
                           cover_s);
  EXPECT_GE(named, at_least(0.9, n, 20));
  EXPECT_GE(cover_t, at_least(0.85, named, 20));
  EXPECT_GE(cover_s, at_least(0.85, named, 20));
}

namespace {

/// One family's acceptance count: cases, named with its parameters within tolerance, and of those
/// the extended model's likelihood gain over the base in sample (less Akaike's charge) and on the
/// held-out runs (docs/diagnosis.md, "Band and gain"): positive for every named case.
struct Tally {
  int cases = 0, named = 0, gain_in = 0, gain_out = 0;
  std::string gains;  ///< each named case's gains, in sample / out of sample, −2Δ ln L
  void add(const DiagnoseResult& r, bool in_tolerance) {
    ++cases;
    if (!in_tolerance) return;
    ++named;
    gain_in += r.gain.likelihood_in_sample > 0;
    gain_out += r.gain.likelihood_holdout > 0;
    gains += fmt::format(" {:.1f}/{:.1f}", r.gain.likelihood_in_sample, r.gain.likelihood_holdout);
  }
  void check(const char* what) const {
    std::cout << fmt::format("{}: {}/{} named in tolerance, gain in sample {}, out of sample {} (−2Δ ln L:{})\n", what,
                             named, cases, gain_in, gain_out, gains);
    EXPECT_GE(named, at_least(0.9, cases, 20)) << what;
    EXPECT_EQ(gain_in, named) << what;
    EXPECT_EQ(gain_out, named) << what;
  }
};

bool near(double estimate, double truth, double relative) { return std::abs(estimate / truth - 1) < relative; }

/// A warm-up named with its amplitude within 30 % (its time constant: docs/diagnosis.md).
bool warmup_in_tolerance(const DiagnoseResult& r, double amp) {
  const Finding* w = finding(r, Effect::Warmup);
  return w && near(w->parameter("amplitude").value, amp, 0.3);
}

}  // namespace

// A Gauss–Markov rate of σ 0.3 °/h (90 times the flicker floor) and Tc 25–60 s: named alone (no other
// effect beside it) with σ within 30 % in at least 90 % of records, each with a positive gain. Tc,
// like a warm-up's time constant, scatters widely (σ² and Tc trade against each other): its interval's
// coverage is printed. A longer Tc or a weaker term looks like flicker and random walk to 10-s block
// means (docs/diagnosis.md).
TEST(DiagnoseAcceptance, GaussMarkovNamedWithinTolerance) {
  const int n = test::population("RWCALC_DIAGNOSE_EFFECTS", 4, 20);
  Tally gm;
  int sigma_covered = 0, tc_covered = 0;
  for (int i = 0; i < n; ++i) {
    const double tc = 25 + 35 * spread(i + 3), sigma = 0.3;
    NoiseModel m = gl2d();
    m.gauss_markov.push_back({sigma, tc});
    const DiagnoseResult r = run_case(m, 7400 + static_cast<std::uint64_t>(i));
    const Finding* g = finding(r, Effect::GaussMarkov);
    const bool ok = g && r.findings.size() == 1 && near(g->parameter("sigma").value, sigma, 0.3);
    gm.add(r, ok);
    if (!ok) print_case(fmt::format("record {} (Tc {:.1f} s)", i, tc), r);
    if (!g) continue;
    sigma_covered += covers(*g, "sigma", sigma);
    tc_covered += covers(*g, "correlation_time", tc);
  }
  std::cout << fmt::format("Gauss-Markov: 95 % intervals cover σ in {}, Tc in {} of the named\n", sigma_covered,
                           tc_covered);
  // The acceptance's 90–98 % of the named cases, resolved from 60 on (RWCALC_DIAGNOSE_EFFECTS=80);
  // checked from 18 named on (RWCALC_ACCEPTANCE=1): a handful cannot tell 90 % from 60 %.
  if (gm.named >= kCoverageCases)
    for (const int covered : {sigma_covered, tc_covered}) {
      EXPECT_GE(covered, at_least(0.9, gm.named, 60));
      EXPECT_LE(covered, gm.named * (0.98 + test::share_allowance(0.98, gm.named, 60)));
    }
  gm.check("Gauss-Markov term");
}

// An output-chain low-pass of τf 0.02–0.1 s on GL-2D-like noise with a dithered read-out, 30 min
// at 200 Hz as a floating angle (the filter is tested on floating data only): named alone with τf
// within 30 % in at least 90 % of records, each with a positive gain in sample and held out; its 95 %
// interval holds τf in 90–98 % of the named cases (checked from 18 named on, as below).
TEST(DiagnoseAcceptance, OutputLowpassNamedWithinTolerance) {
  const int n = test::population("RWCALC_DIAGNOSE_EFFECTS", 4, 20);
  Tally lowpass;
  int covered = 0, found = 0;
  for (int i = 0; i < n; ++i) {
    const double tf = 0.02 + 0.08 * spread(i + 11);
    NoiseModel m = gl2d();
    m.readout = ReadoutMode::White;
    m.output_lowpass_tc_s = tf;
    SimulationSettings s;
    s.duration_s = 1800;
    s.rate_hz = 200;
    s.scale_arcsec = 0.92;
    s.seed = 8100 + static_cast<std::uint64_t>(i);
    Recording rec;
    rec.source = fmt::format("simulated-{}", s.seed);
    rec.phase = simulate(m, s);
    rec.rate_hz = s.rate_hz;
    rec.samples = rec.phase.points() - 1;
    const DiagnoseResult r = diagnose(rec, DiagnoseOptions{});
    const Finding* f = finding(r, Effect::Lowpass);
    const bool ok = f && r.findings.size() == 1 && near(f->parameter("time_constant").value, tf, 0.3);
    lowpass.add(r, ok);
    if (!ok) print_case(fmt::format("record {} (τf {:.3f} s)", i, tf), r);
    if (!f) continue;
    ++found;
    covered += covers(*f, "time_constant", tf);
  }
  std::cout << fmt::format("output low-pass: 95 % interval covers τf in {} of {}\n", covered, found);
  if (found >= kCoverageCases) {
    EXPECT_GE(covered, at_least(0.9, found, 60));
    EXPECT_LE(covered, found * (0.98 + test::share_allowance(0.98, found, 60)));
  }
  lowpass.check("output low-pass");
}

// The effects beside slow lines and steps, each at a level its detector resolves on a 2-h record:
// a warm-up (0.1 °/h, 30 times the flicker floor, τ 300–900 s), the same on a ramp of 0.01 °/h² (an
// exponential + linear drift), a line above the slow band (0.02–0.2 Hz, 0.1 °/h), and a slow line
// with a step at once: named within tolerance in at least 90 % of records. (Gauss–Markov terms and
// the output low-pass: docs/diagnosis.md.)
TEST(DiagnoseAcceptance, EveryEffectNamedWithinTolerance) {
  const int n = test::population("RWCALC_DIAGNOSE_EFFECTS", 4, 20);
  Tally warmup, drift, fast_line, two;
  // Each reported parameter's 95 % interval against the truth, over the records that name its term.
  std::map<std::string, std::pair<int, int>> coverage;  // covered, named
  const auto cover = [&](const char* what, const Finding* f, const char* name, double truth) {
    if (!f) return;
    auto& [covered, named] = coverage[fmt::format("{} {}", what, name)];
    ++named;
    covered += covers(*f, name, truth);
  };
  for (int i = 0; i < n; ++i) {
    const auto seed = 7000 + static_cast<std::uint64_t>(i);
    const double tc = 300 + 600 * spread(i), amp = 0.1 * (i % 2 ? 1 : -1);
    NoiseModel w = gl2d();
    w.warmups.push_back({amp, tc});
    const DiagnoseResult rw = run_case(w, seed);
    warmup.add(rw, warmup_in_tolerance(rw, amp));
    cover("warm-up", finding(rw, Effect::Warmup), "time_constant", tc);
    cover("warm-up", finding(rw, Effect::Warmup), "amplitude", amp);
    w.ramp_deg_per_h2 = 0.01;
    const DiagnoseResult rd = run_case(w, seed + 100);
    drift.add(rd, warmup_in_tolerance(rd, amp));
    cover("warm-up on a ramp", finding(rd, Effect::Warmup), "time_constant", tc);
    cover("warm-up on a ramp", finding(rd, Effect::Warmup), "amplitude", amp);

    NoiseModel l = gl2d();
    const double f = 0.02 * std::pow(10.0, spread(i + 5));
    l.sinusoids.push_back({f, 0.1, 6.283 * spread(i + 9)});
    const DiagnoseResult rl = run_case(l, seed + 200);
    const Finding* s = finding(rl, Effect::Line);
    if (!s) s = finding(rl, Effect::Sinusoid);
    fast_line.add(rl, s && std::abs(s->parameter("frequency").value - f) < 0.5 / kT &&
                          near(s->parameter("amplitude").value, 0.1, 0.3));
    cover("fast line", s, "frequency", f);
    cover("fast line", s, "amplitude", 0.1);

    NoiseModel t = gl2d();
    const double fs = (3.0 + 2.0 * spread(i + 2)) / kT, step_t = 1500 + 4000 * spread(i + 4);
    t.sinusoids.push_back({fs, 5 * kFloor, 6.283 * spread(i + 1)});
    t.bias_steps.push_back({step_t, 0.06});
    const DiagnoseResult rt = run_case(t, seed + 300);
    const Finding *ts = finding(rt, Effect::Sinusoid), *tb = finding(rt, Effect::BiasStep);
    two.add(rt, ts && tb && std::abs(ts->parameter("frequency").value - fs) < 0.5 / kT &&
                    near(ts->parameter("amplitude").value, 5 * kFloor, 0.3) &&
                    std::abs(tb->parameter("time").value - step_t) < 30 &&
                    near(tb->parameter("size").value, 0.06, 0.3));
    cover("line beside a step", ts, "frequency", fs);
    cover("line beside a step", ts, "amplitude", 5 * kFloor);
    cover("step beside a line", tb, "time", step_t);
    cover("step beside a line", tb, "size", 0.06);
  }
  // The acceptance's 90–98 % of the named cases, resolved from 60 on (RWCALC_DIAGNOSE_EFFECTS=80);
  // checked from 18 named on (RWCALC_ACCEPTANCE=1): a handful cannot tell 90 % from 60 %.
  for (const auto& [what, c] : coverage) {
    std::cout << fmt::format("{}: 95 % interval covers the truth in {} of {}\n", what, c.first, c.second);
    if (c.second < kCoverageCases) continue;
    EXPECT_GE(c.first, at_least(0.9, c.second, 60)) << what;
    EXPECT_LE(c.first, c.second * (0.98 + test::share_allowance(0.98, c.second, 60))) << what;
  }
  warmup.check("warm-up");
  drift.check("exponential + linear drift");
  fast_line.check("line above the slow band");
  two.check("slow line and step at once");
}
