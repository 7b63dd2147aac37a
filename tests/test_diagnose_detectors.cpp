// Each detector of the diagnosis through the Detector interface: a simulated record with its
// effect clears the threshold calibrated on an ensemble of the model without it; the same record
// (same noise) without the effect does not.
#include <gtest/gtest.h>

#include <memory>

#include "diagnose/detector.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;
using namespace rwcalc::diag;

constexpr double kSeconds = 2400;
constexpr std::size_t kRuns = 20;

/// White rate noise (N = 0.01 °/√h) with a white angle read-out of 2″, at 10 Hz.
NoiseModel quiet() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.01;
  m.white_angle_arcsec = 2.0;
  m.readout = ReadoutMode::White;
  return m;
}

SimulationSettings settings(std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = kSeconds;
  s.rate_hz = 10;
  s.scale_arcsec = 1e-6;
  s.seed = seed;
  return s;
}

/// A simulated record as a floating angle (the domain of the line and low-pass detectors).
PhaseSeries record(const NoiseModel& m) { return test::floating_angle(simulate(m, settings(7))); }

AnalysisResult octave_analysis(const PhaseSeries& x) {
  AnalysisResult a;
  a.allan = compute_allan(x);
  return a;
}

/// The detector's verdict on `x` against an ensemble of `base` (the quiet model).
DetectorResult verdict(const Detector& d, const PhaseSeries& x) {
  static const DiagnoseOptions opt;
  const AnalysisResult a = octave_analysis(x);
  Stretch s;
  s.opt = &opt;
  s.base = quiet();
  s.dec = decimate(x);
  s.clean = without_own_candidates(s.dec);
  std::vector<double> octave_var;
  for (const auto& p : a.allan.points) {
    s.octave_m.push_back(p.m);
    octave_var.push_back(p.var);
  }
  EnsemblePlan plan{s.octave_m, mid_tau_grid(s.dec), true, {}};
  if (const auto* rd = dynamic_cast<const RecordDetector*>(&d)) plan.scored.push_back(rd);
  const SimulationSettings sim = settings(100);
  const auto runs = run_ensemble(s.base, sim, kRuns, plan, nullptr);
  s.ref = make_reference(plan.grid, s.dec.tau_d, runs);
  s.clean_ref = make_reference(plan.grid, s.dec.tau_d, runs, true);
  const std::vector<double> mid = decimated_avar(s.clean, plan.grid);
  return d.test(Trial{{x, s.dec, s.clean, octave_var}, runs, s, sim, &mid});
}

/// The detector fires on the record with the effect and not on the record without it.
void expect_detects(const Detector& d, const NoiseModel& with_effect) {
  const DetectorResult yes = verdict(d, record(with_effect));
  EXPECT_EQ(yes.effect, d.effect());
  EXPECT_TRUE(yes.fired) << yes.statistic << " vs " << yes.threshold << " " << yes.note;
  EXPECT_GT(yes.statistic, yes.threshold);
  const DetectorResult no = verdict(d, record(quiet()));
  EXPECT_FALSE(no.fired) << no.statistic << " vs " << no.threshold;
  EXPECT_LE(no.statistic, no.threshold);
}

TEST(DiagnoseDetectors, Sinusoid) {
  NoiseModel m = quiet();
  m.sinusoids.push_back({0.05, 0.3, 0.4});
  expect_detects(*sinusoid_detector(), m);
}

TEST(DiagnoseDetectors, HighFrequencyLine) {
  NoiseModel m = quiet();
  m.sinusoids.push_back({2.0, 20.0, 0.7});  // the 2″ read-out: about 28 °/h per sample
  expect_detects(*line_detector(), m);
}

TEST(DiagnoseDetectors, BiasStep) {
  NoiseModel m = quiet();
  m.bias_steps.push_back({1200, 0.5});
  expect_detects(*step_detector(), m);
}

TEST(DiagnoseDetectors, Warmup) {
  NoiseModel m = quiet();
  m.warmups.push_back({1.0, 200});
  expect_detects(*warmup_detector(), m);
}

TEST(DiagnoseDetectors, GaussMarkov) {
  NoiseModel m = quiet();
  m.gauss_markov.push_back({0.3, 50});
  expect_detects(*gauss_markov_detector(), m);
}

TEST(DiagnoseDetectors, Lowpass) {
  NoiseModel m = quiet();
  m.output_lowpass_tc_s = 0.5;
  const PhaseSeries x = record(m);
  expect_detects(*lowpass_detector(octave_analysis(x), kSeconds, ""), m);
}

TEST(DiagnoseDetectors, LowpassSaysWhyPulseCountsAreNotTested) {
  const PhaseSeries x = record(quiet());
  const auto d = lowpass_detector(octave_analysis(x), kSeconds, "pulse counts");
  const DetectorResult r = verdict(*d, x);
  EXPECT_FALSE(r.fired);
  EXPECT_EQ(r.note, "pulse counts");
}

}  // namespace
