// Acceptance of the high-frequency line search of `rwcalc diagnose` (docs/diagnosis.md, "High-
// frequency line") on seeded simulated ADIS16405-like floating records: 1 h at 100 Hz, white rate
// noise N = 2.3 °/√h (about 1400 °/h per sample), B = 40 °/h, white (floating) read-out, plus a
// line of 5–40 Hz and 30–150 °/h (log-uniform, random phase). The line is named as a `sinusoid`
// with its frequency within 0.5/T and its amplitude within 20 % in ≥ 90 % of the cases, and the
// extended model (which simulates the line) fits the Allan variance better in sample. Records
// without a line get no high-frequency finding. The diagnosis uses 20 runs per ensemble.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>

#include <fmt/format.h>

#include "rwcalc/diagnose.hpp"
#include "rwcalc/simulate.hpp"

namespace {

using namespace rwcalc;

constexpr double kSeconds = 3600;

std::size_t cases(std::size_t dflt) {
  if (const char* s = std::getenv("RWCALC_DIAGNOSE_CASES")) return static_cast<std::size_t>(std::atoi(s));
  return dflt;
}

NoiseModel adis_like() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 2.3;
  m.bias_instability_deg_per_h = 40.0;
  m.readout = ReadoutMode::White;
  return m;
}

DiagnoseResult run_case(const NoiseModel& m, std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = kSeconds;
  s.rate_hz = 100;
  s.scale_arcsec = 1e-6;
  s.seed = seed;
  // The record as a floating angle (a finely quantized read-out, as the ADIS16405's rates).
  const PhaseSeries x = simulate(m, s);
  Recording rec;
  rec.source = fmt::format("simulated-{}", seed);
  rec.phase.tau0_s = x.tau0_s;
  rec.phase.kind = x.kind;
  rec.phase.values.resize(x.points());
  for (std::size_t i = 0; i < x.points(); ++i) rec.phase.values[i] = x.diff(i, 0);
  rec.rate_hz = 100;
  rec.samples = rec.phase.points() - 1;
  DiagnoseOptions o;
  o.runs = 20;
  o.seed = seed * 7919 + 3;
  return diagnose(rec, o);
}

/// The high-frequency sinusoid finding (searched from 0.25 Hz on), if any.
const Finding* line_finding(const DiagnoseResult& r) {
  for (const auto& f : r.findings)
    if (f.effect == Effect::Line) return &f;
  return nullptr;
}

std::string summary(const DiagnoseResult& r) {
  std::string s;
  for (const auto& f : r.findings) s += fmt::format(" {}{}", finding_name(f.effect), f.params.dump());
  for (const auto& d : r.detectors)
    s += fmt::format(" {}:{:.3g}/{:.3g}", detector_name(d.effect), d.statistic, d.threshold);
  return s;
}

struct LineTally {
  std::size_t n = 0, named = 0, recovered = 0, gain_in = 0, gain_out = 0;
};

/// The drawn line cases (seeds 6000…), each diagnosed and logged.
LineTally run_line_cases() {
  const std::size_t n = cases(10);
  std::mt19937_64 g(6000);
  std::size_t named = 0, recovered = 0, gain_in = 0, gain_out = 0;
  for (std::size_t i = 0; i < n; ++i) {
    NoiseModel m = adis_like();
    const double f = std::exp(std::uniform_real_distribution<double>(std::log(5.0), std::log(40.0))(g));
    const double a = std::exp(std::uniform_real_distribution<double>(std::log(30.0), std::log(150.0))(g));
    const double p = std::uniform_real_distribution<double>(0, 6.283)(g);
    m.sinusoids.push_back({f, a, p});
    const auto r = run_case(m, 6000 + 101 * i);
    const Finding* e = line_finding(r);
    const bool ok = e && std::abs(e->params["frequency_hz"].get<double>() - f) <= 0.5 / kSeconds &&
                    std::abs(e->params["amplitude_deg_per_h"].get<double>() - a) <= 0.2 * a;
    named += e != nullptr;
    recovered += ok;
    const bool gin = r.gain.misfit_extended < r.gain.misfit_base;
    const bool gout = r.gain.holdout_misfit_extended < r.gain.holdout_misfit_base;
    if (e) {
      gain_in += gin;
      gain_out += gout;
    }
    std::cout << fmt::format(
                     "line case {:2}: truth {:.4f} Hz {:.1f} °/h -> {} | misfit {:.2f}->{:.2f} holdout "
                     "{:.2f}->{:.2f} ({:.1f} s) |{}\n",
                     i, f, a, ok ? "recovered" : (e ? "named, off" : "missed"), r.gain.misfit_base,
                     r.gain.misfit_extended, r.gain.holdout_misfit_base, r.gain.holdout_misfit_extended, r.seconds,
                     summary(r))
              << std::flush;
  }
  std::cout << fmt::format(
      "high-frequency line: named {}/{}, recovered {}/{}, gain in sample {}/{}, out of sample {}/{}\n", named, n,
      recovered, n, gain_in, named, gain_out, named);
  return {n, named, recovered, gain_in, gain_out};
}

}  // namespace

// Measured (seeds 6000…, 10 cases, 20 runs): named 9/10, all 9 within tolerance (f within
// 1e-5 Hz, amplitude within 10 %), gain in sample 9/9 (0.30 -> 0.10 … 4.98 -> 0.55). The miss is
// the weakest line, 30.9 °/h at 9.45 Hz (statistic 14.7 against a threshold of 15.6): the detection
// limit on 1 h of this noise is about 30 °/h (σ of the amplitude ≈ 3.3 °/h). Out of sample 9/9
// (7.78 -> 4.29 … 44.4 -> 2.36, folds of halves and thirds averaged; with halves alone 7.86 -> 1.65
// … 50.1 -> 2.86) with the line's two Fourier coefficients on the predicted block scored
// against its local noise level (docs/diagnosis.md, Gain); through the band alone 5/9, the two models
// within 0.02 of each other (2.45 -> 2.43, 6.82 -> 6.84): the line moves the AV by ≈ 0.1 % and the
// base half model takes its share into its white angle noise.
// One test for both figures: ctest runs every case in its own process, so two tests of the same
// cases would diagnose all of them twice.
TEST(DiagnoseLineAcceptance, HighFrequencyLine) {
  const LineTally t = run_line_cases();
  EXPECT_GE(static_cast<double>(t.recovered), 0.9 * static_cast<double>(t.n));
  EXPECT_EQ(t.gain_in, t.named) << "the extended model must gain in sample on every named case";
  EXPECT_EQ(t.gain_out, t.named) << "the extended model must gain out of sample on every named case";
}

// Records without a line, with and without the ADIS16405's output-chain low-pass (τf 5.5 ms):
// no high-frequency sinusoid named (false-alarm level 1 % per record). Measured (seeds 7000…, 10
// cases): none in 10/10 (statistics 4.7–14.7 against thresholds 11–20.5; the low-pass named on all
// five filtered records).
TEST(DiagnoseLineAcceptance, NoLineNamesNone) {
  const std::size_t n = cases(10);
  std::size_t none = 0;
  for (std::size_t i = 0; i < n; ++i) {
    NoiseModel m = adis_like();
    if (i % 2) m.output_lowpass_tc_s = 0.0055;
    const auto r = run_case(m, 7000 + 13 * i);
    none += line_finding(r) == nullptr;
    std::cout << fmt::format("no line case {:2} (low-pass {}): ({:.1f} s) |{}\n", i, i % 2 ? "yes" : "no", r.seconds,
                             summary(r))
              << std::flush;
  }
  std::cout << fmt::format("no line: no high-frequency sinusoid in {}/{}\n", none, n);
  EXPECT_GE(static_cast<double>(none), 0.95 * static_cast<double>(n));
}
