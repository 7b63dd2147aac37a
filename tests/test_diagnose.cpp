// The diagnosis building blocks on synthetic series with known answers: decimation and block
// rates, the periodogram line search, the change point, the warm-up exponential, the mid-τ shapes
// against the simulator's exact Allan variance, the Gumbel calibration, misfit and coverage.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "diagnose/detector.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/simulate.hpp"

#include <nlohmann/json.hpp>

namespace {

using namespace rwcalc;
using namespace rwcalc::diag;

/// A decimated angle at 0.1 s from a rate function plus white rate noise of `sd` per 0.1 s.
Decimated from_rate(double seconds, double sd, std::uint64_t seed, const std::function<double(double)>& rate) {
  Decimated d;
  d.tau_d = 0.1;
  const auto n = static_cast<std::size_t>(seconds / d.tau_d);
  d.theta.assign(n + 1, 0.0);
  std::mt19937_64 g(seed);
  std::normal_distribution<double> z(0.0, sd);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = (static_cast<double>(j) + 0.5) * d.tau_d;
    d.theta[j + 1] = d.theta[j] + (rate(t) + z(g)) * d.tau_d;
  }
  return d;
}

TEST(DiagnoseBlocks, DecimationAndBlockRates) {
  // A power of two (the octave cluster sizes from D on are whole decimated periods).
  EXPECT_EQ(decimation(400), 32u);
  EXPECT_EQ(decimation(100), 8u);
  EXPECT_EQ(decimation(25), 2u);
  EXPECT_EQ(decimation(10), 1u);
  PhaseSeries x;
  x.tau0_s = 0.0025;
  x.arcsec_per_count = 0.5;
  x.counts.resize(4001);
  for (std::size_t i = 0; i < x.counts.size(); ++i) x.counts[i] = static_cast<std::int64_t>(3 * i);  // 600 ″/s
  const auto d = decimate(x);
  EXPECT_DOUBLE_EQ(d.tau_d, 0.08);
  ASSERT_EQ(d.theta.size(), 126u);
  const auto r = block_rates(d, 10);
  ASSERT_EQ(r.size(), 12u);
  for (double v : r) EXPECT_NEAR(v, 600.0, 1e-9);
}

TEST(DiagnoseBlocks, SinusoidLineSearchRecoversFrequencyAndAmplitude) {
  const double f = 0.0371, a = 0.05;
  const auto d = from_rate(7200, 0.3, 5, [&](double t) { return a * std::cos(2 * std::numbers::pi * f * t + 0.4); });
  const auto e = sinusoid_detect(d);
  EXPECT_NEAR(e.f_hz, f, 3 * e.f_sigma + 1e-6);
  EXPECT_NEAR(e.amp, a, 3 * e.amp_sigma);
  EXPECT_GT(e.amp_sigma, 0.0);
  EXPECT_GT(e.statistic, 30.0);
  // Without the line the statistic stays at the level of the largest of ~10⁴ exponential ratios.
  const auto e0 = sinusoid_detect(from_rate(7200, 0.3, 6, [](double) { return 0.0; }));
  EXPECT_LT(e0.statistic, 20.0);
}

// A line of 3.3 cycles per record lies below the periodogram search's 4 cycles: the slow band's
// least-squares search finds it, with level and trend fitted together.
TEST(DiagnoseBlocks, SlowLineOfThreeCyclesRecoversFrequencyAndAmplitude) {
  const double f = 3.3 / 7200.0, a = 0.05;
  const auto d = from_rate(7200, 0.3, 15, [&](double t) { return a * std::cos(2 * std::numbers::pi * f * t + 1.1); });
  const auto e = sinusoid_detect(d);
  EXPECT_LT(e.f_hz * 7200.0, 4.0);
  EXPECT_NEAR(e.f_hz, f, 3 * e.f_sigma + 1e-7);
  EXPECT_NEAR(e.amp, a, 3 * e.amp_sigma);
  EXPECT_GT(e.amp_sigma, 0.0);
  EXPECT_GT(e.statistic, 30.0);
}

TEST(DiagnoseBlocks, StepTimeAndSize) {
  const auto d = from_rate(7200, 0.3, 7, [](double t) { return t > 3100 ? 0.03 : 0.0; });
  const auto e = step_detect(d);
  EXPECT_NEAR(e.t_s, 3100, 120);
  EXPECT_NEAR(e.size, 0.03, 4 * e.size_sigma);
  EXPECT_GT(e.statistic, 6);
}

// The estimate's noise: white only (from_rate's), no flicker or rate random walk.
const DriftNoise kWhite{};

TEST(DiagnoseBlocks, WarmupAmplitudeAndTimeConstant) {
  const auto d = from_rate(7200, 0.3, 8, [](double t) { return -0.08 * std::exp(-t / 500.0); });
  const auto e = warmup_detect(d, 0, &kWhite);
  EXPECT_TRUE(e.separable);
  EXPECT_NEAR(e.amp, -0.08, 4 * e.amp_sigma);
  EXPECT_NEAR(e.tc, 500, 150);
  EXPECT_GT(e.statistic, 20);
}

// A drift A'·(1 − e^{−t/τd}) + r·t is the warm-up model with A = −A'; its trend is the ramp r.
TEST(DiagnoseBlocks, DriftReportsItsLinearPartAsTheRamp) {
  const double ap = 0.1, td = 900, r = 0.02;  // °/h, s, °/h²
  const auto d = from_rate(7200, 0.3, 9, [&](double t) { return ap * -std::expm1(-t / td) + r * t / 3600.0; });
  const auto e = warmup_detect(d, 0, &kWhite);
  EXPECT_TRUE(e.separable);
  EXPECT_NEAR(e.amp, -ap, 4 * e.amp_sigma);
  EXPECT_NEAR(e.tc, td, 0.35 * td);
  EXPECT_GT(e.ramp_sigma, 0.0);
  EXPECT_NEAR(e.ramp, r, 4 * e.ramp_sigma);
  EXPECT_GT(e.statistic, 20);
  // The detection statistic alone leaves the standard errors unset (the estimate sets them).
  EXPECT_EQ(warmup_detect(d).ramp_sigma, 0.0);
}

// A drift whose time constant is half the record: the estimate searches τ beyond the statistic's
// T/3 (where it was clipped, and A and r came out far off), and its joint standard errors (τ
// free) cover the truth.
TEST(DiagnoseBlocks, DriftOfHalfTheRecordIsNotClippedAtAThird) {
  const double ap = 0.6, td = 3600, r = -0.02;  // °/h, s, °/h²
  const auto d = from_rate(7200, 0.3, 11, [&](double t) { return ap * -std::expm1(-t / td) + r * t / 3600.0; });
  const auto e = warmup_detect(d, 0, &kWhite);
  EXPECT_TRUE(e.separable);
  EXPECT_GT(e.tc, 7200.0 / 3.0 * 1.05);
  EXPECT_NEAR(e.tc, td, 3 * e.tc_sigma);
  EXPECT_NEAR(e.amp, -ap, 3 * e.amp_sigma);
  EXPECT_NEAR(e.ramp, r, 3 * e.ramp_sigma);
  EXPECT_LT(e.tc_sigma, kDriftSeparableSigma * e.tc);
}

// A drift of τ ≫ T is a parabola over the record: A, τ and r trade along a ridge, the estimate
// says so, and the mid-record slope and curvature it reports instead are within their errors.
TEST(DiagnoseBlocks, LongDriftReportsSlopeAndCurvatureNotAPair) {
  const double ap = 0.3, td = 20000;  // °/h, s
  const auto d = from_rate(7200, 0.3, 12, [&](double t) { return ap * -std::expm1(-t / td); });
  const auto e = warmup_detect(d, 0, &kWhite);
  EXPECT_FALSE(e.separable);
  const double x = 3600.0 / td, E = std::exp(-x);  // at mid-record, τ in hours = 1/x
  EXPECT_NEAR(e.slope_mid, ap * x * E, 3 * e.slope_mid_sigma);
  EXPECT_NEAR(e.curvature_mid, -ap * x * x * E, 3 * e.curvature_mid_sigma);
  EXPECT_GT(e.slope_mid_sigma, 0.0);
  EXPECT_LT(e.slope_mid_sigma, 0.2 * ap * x * E);  // the slope is determined (5σ and more)
}

TEST(DiagnoseBlocks, DeterministicAngleMatchesTheSimulator) {
  NoiseModel m;
  m.sinusoids.push_back({0.01, 0.2, 0.3});
  m.bias_steps.push_back({100, 0.5});
  m.warmups.push_back({0.7, 50});
  SimulationSettings s;
  s.duration_s = 400;
  s.rate_hz = 10;
  s.scale_arcsec = 1e-6;
  m.readout = ReadoutMode::White;
  const auto x = simulate(m, s);
  for (std::size_t i : {std::size_t{1}, std::size_t{1000}, std::size_t{2500}, std::size_t{4000}})
    EXPECT_NEAR(x.diff(i, 0), deterministic_angle(m, static_cast<double>(i) * 0.1), 1e-5);
}

TEST(DiagnoseBlocks, GaussMarkovShapeMatchesTheoreticalAvar) {
  NoiseModel m;
  m.gauss_markov.push_back({1.0, 30.0});
  for (std::size_t mm : {400u, 4000u, 40000u, 400000u}) {
    const double tau = static_cast<double>(mm) * 0.0025;
    const double exact = theoretical_avar(m, 0.0025, 0.92, mm);
    EXPECT_NEAR(gauss_markov_avar(tau, 30.0), exact, 0.01 * exact) << tau;
  }
}

TEST(DiagnoseBlocks, OutputLowpassAvarMatchesTheSimulatedFilter) {
  // Without a filter: the white angle and white rate lines.
  EXPECT_NEAR(output_lowpass_angle_avar(4, 0.01, 0.0), 3.0 / (0.04 * 0.04), 1e-9);
  EXPECT_NEAR(output_lowpass_rate_avar(4, 0.01, 0.0), 1.0 / 0.04, 1e-12);
  EXPECT_NEAR(output_lowpass_rate_avar(4, 0.01, 1e-9), 1.0 / 0.04, 1e-9);
  // Far above τf the white rate passes (AV → 1/τ); the white angle keeps its variance (1 − φ)/(1 + φ).
  EXPECT_NEAR(output_lowpass_rate_avar(100000, 0.01, 0.05) * 1000.0, 1.0, 1e-3);
  const double phi = std::exp(-0.01 / 0.05);
  EXPECT_NEAR(output_lowpass_angle_avar(100000, 0.01, 0.05) * 1000.0 * 1000.0 / 3.0, (1 - phi) / (1 + phi), 1e-9);
  // The simulator's dithered read-out (white angle noise q²/6) through an output filter.
  NoiseModel m;
  m.earth_rate_deg_per_h = 12.43;
  m.readout = ReadoutMode::White;
  m.output_lowpass_tc_s = 0.05;
  SimulationSettings s;
  s.duration_s = 2000;
  s.rate_hz = 100;
  s.scale_arcsec = 0.92;
  s.seed = 8;
  const PhaseSeries x = simulate(m, s);
  ASSERT_FALSE(x.exact());
  ASSERT_EQ(x.points(), s.samples() + 1);
  const double q2 = 0.92 * 0.92 / 6.0;
  for (std::int64_t mm : {1, 2, 4, 16, 64}) {
    const double expect = q2 * output_lowpass_angle_avar(static_cast<std::size_t>(mm), 0.01, 0.05);
    EXPECT_NEAR(allan_variance(x, mm, Estimator::Overlapping), expect, 0.03 * expect) << mm;
  }
  // The detector recovers τf on it; on the unfiltered record the filter explains nothing.
  std::vector<std::int64_t> ms;
  std::vector<double> v, edf;
  for (std::int64_t mm = 1; mm <= 1024; mm *= 2) {
    ms.push_back(mm);
    v.push_back(allan_variance(x, mm, Estimator::Overlapping));
    edf.push_back(static_cast<double>(x.points()) / static_cast<double>(mm));
  }
  const auto est = output_lowpass_detect(ms, v, edf, 0.01, 2000);
  EXPECT_NEAR(est.tf, 0.05, 0.005);
  EXPECT_NEAR(est.white_angle2, q2, 0.1 * q2);
  EXPECT_LT(est.tf_low, est.tf);
  EXPECT_GT(est.tf_high, est.tf);
  EXPECT_GT(est.statistic, 1000.0);
  m.output_lowpass_tc_s = 0;
  const PhaseSeries y = simulate(m, s);
  for (std::size_t i = 0; i < ms.size(); ++i) v[i] = allan_variance(y, ms[i], Estimator::Overlapping);
  EXPECT_LT(output_lowpass_detect(ms, v, edf, 0.01, 2000).statistic, 20.0);
}

TEST(DiagnoseBlocks, LowpassFindingIsTheOutputChainFilter) {
  NoiseModel m;
  add_finding(nlohmann::json{{"effect", "lowpass"}, {"time_constant_s", 0.02}}, m);
  EXPECT_DOUBLE_EQ(m.output_lowpass_tc_s, 0.02);
  EXPECT_DOUBLE_EQ(m.lowpass_tc_s, 0.0);
  const nlohmann::json j = m;
  EXPECT_DOUBLE_EQ(j.at("output_lowpass_tc_s").get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(j.get<NoiseModel>().output_lowpass_tc_s, 0.02);
  m.output_lowpass_tc_s = -1.0;
  EXPECT_THROW(validate(m, SimulationSettings{}), UsageError);
}

TEST(DiagnoseBlocks, LowpassDetectorSkipsPulseCountsGivenAsNumbers) {
  // A counting read-out written as angles (whole multiples of q): the read-out's sawtooth is not
  // an output-chain filter, and the detector says why it did not run.
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.001;
  m.earth_rate_deg_per_h = 12.43;
  SimulationSettings s;
  s.duration_s = 1300;
  s.rate_hz = 100;
  s.seed = 5;
  Recording rec;
  rec.source = "counts-as-angle";
  rec.phase = simulate(m, s);
  PhaseSeries& x = rec.phase;
  x.values.resize(x.counts.size());
  for (std::size_t i = 0; i < x.counts.size(); ++i) x.values[i] = x.diff(i, 0);
  x.counts.clear();
  rec.rate_hz = 100;
  rec.samples = x.points() - 1;
  DiagnoseOptions o;
  o.runs = 10;
  const auto r = diagnose(rec, o);
  ASSERT_EQ(r.detectors.size(), 5u);
  EXPECT_EQ(r.detectors[4].effect, Effect::Lowpass);
  EXPECT_FALSE(r.detectors[4].fired);
  EXPECT_NE(r.detectors[4].note.find("multiples"), std::string::npos) << r.detectors[4].note;
}

TEST(DiagnoseBlocks, GumbelThresholdSitsInTheTail) {
  std::mt19937_64 g(3);
  std::extreme_value_distribution<double> ev(10.0, 2.0);
  std::vector<double> v(2000);
  for (double& x : v) x = ev(g);
  const double q99 = 10.0 - 2.0 * std::log(-std::log(0.99));
  // With 50 values (fewer than 1/α) the threshold is at least the ensemble maximum; with 2000 it is
  // the fitted quantile.
  const std::vector<double> v50(v.begin(), v.begin() + 50);
  const double thr = gumbel_threshold(v50, 0.01);
  EXPECT_GT(thr, quantile(v, 0.9));
  EXPECT_GE(thr, *std::max_element(v50.begin(), v50.end()));
  EXPECT_NEAR(gumbel_threshold(v, 0.01), q99, 3 * gumbel_quantile(v, 0.01).sigma);
  EXPECT_NEAR(quantile({1, 2, 3, 4, 5}, 0.5), 3.0, 1e-12);
  EXPECT_NEAR(quantile({1, 2, 3, 4, 5}, 0.25), 2.0, 1e-12);
}

// The threshold's Monte-Carlo standard error is the scatter of the threshold over ensembles.
TEST(DiagnoseBlocks, GumbelThresholdSigmaIsItsScatter) {
  std::mt19937_64 g(5);
  std::extreme_value_distribution<double> ev(10.0, 2.0);
  const std::size_t ensembles = 400, K = 200;
  double s = 0, s2 = 0, sig = 0;
  for (std::size_t e = 0; e < ensembles; ++e) {
    std::vector<double> v(K);
    for (double& x : v) x = ev(g);
    const GumbelQuantile q = gumbel_quantile(v, 0.01);
    s += q.value;
    s2 += q.value * q.value;
    sig += q.sigma;
  }
  const double n = static_cast<double>(ensembles), mean = s / n;
  const double sd = std::sqrt((s2 - n * mean * mean) / (n - 1));
  EXPECT_NEAR(mean, 10.0 - 2.0 * std::log(-std::log(0.99)), 0.2);
  EXPECT_NEAR(sig / n, sd, 0.15 * sd);
}

TEST(DiagnoseBlocks, MisfitAndCoverage) {
  std::vector<BandPoint> band(4);
  for (std::size_t i = 0; i < band.size(); ++i) {
    band[i].tau_s = std::pow(2.0, static_cast<double>(i));
    band[i].mean_var = 1.0;
    band[i].low = 0.9;
    band[i].high = 1.1;
    band[i].median = 1.0;
    band[i].edf = 100;
    band[i].dev = 1.0;
  }
  EXPECT_NEAR(band_misfit(band, 50), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(band_coverage(band), 1.0);
  band[2].dev = 1.3;
  EXPECT_DOUBLE_EQ(band_coverage(band), 0.75);
  const double r = 1.69;
  const double nu = 1.0 / (1.0 / 100 + 1.0 / 5000 + 1.0 / 1000);
  EXPECT_NEAR(band_misfit(band, 50), nu * (r - 1 - std::log(r)) / 4, 1e-9);
}

// The band re-fit finds the N², B², K² changes that carry an ensemble mean onto measured values
// made from it with known changes, respects c + Δc ≥ 0, and leaves a fitting band alone.
TEST(DiagnoseBlocks, BandRefitRecoversKnownCoefficientChanges) {
  const std::array<double, 3> c{c_from_coefficient(Term::N, 0.001), c_from_coefficient(Term::B, 0.005),
                                c_from_coefficient(Term::K, 0.002)};
  const std::array<Term, 3> terms{Term::N, Term::B, Term::K};
  auto model = [&](double tau, const std::array<double, 3>& cc) {
    double v = 3e-4 / (tau * tau);  // a read-out term the re-fit does not touch
    for (std::size_t j = 0; j < 3; ++j) v += cc[j] * term_basis(terms[j], tau);
    return v;
  };
  const std::array<double, 3> truth{c[0] * 0.44, c[1] * 1.7, -c[2]};  // N up 20 %, B up 30 %, K to 0
  std::vector<BandPoint> band;
  for (double tau = 0.5; tau < 3000; tau *= 2) {
    BandPoint b;
    b.tau_s = tau;
    b.mean_var = model(tau, c);
    std::array<double, 3> ct{};
    for (std::size_t j = 0; j < 3; ++j) ct[j] = c[j] + truth[j];
    b.dev = std::sqrt(model(tau, ct));
    b.edf = 1e4;
    band.push_back(b);
  }
  const auto dc = band_refit(band, 50, c);
  EXPECT_NEAR(dc[0], truth[0], 0.01 * c[0]);
  EXPECT_NEAR(dc[1], truth[1], 0.01 * c[1]);
  EXPECT_NEAR(dc[2], truth[2], 1e-3 * c[2]);
  EXPECT_GE(c[2] + dc[2], 0.0);

  // K asked to go below zero: held at its bound, N and B still found.
  for (auto& b : band) {
    std::array<double, 3> ct{c[0] + truth[0], c[1] + truth[1], 0.0};
    b.dev = std::sqrt(std::max(1e-30, model(b.tau_s, ct) - 0.5 * c[2] * term_basis(Term::K, b.tau_s)));
  }
  const auto dk = band_refit(band, 50, c);
  EXPECT_NEAR(dk[2], -c[2], 1e-12 * c[2]);
  EXPECT_GT(dk[0], 0.0);

  // K held: only N and B move.
  const auto dh = band_refit(band, 50, c, {true, true, false});
  EXPECT_EQ(dh[2], 0.0);
  EXPECT_GT(dh[0], 0.0);

  for (auto& b : band) b.dev = std::sqrt(b.mean_var);
  const auto d0 = band_refit(band, 50, c);
  EXPECT_EQ(d0[0], 0.0);
  EXPECT_EQ(d0[1], 0.0);
  EXPECT_EQ(d0[2], 0.0);
}

TEST(DiagnoseBlocks, CalibrationCorrectsOnlyTheTermsTheModelCarries) {
  // The pilot calibration's corrections are applied to N, B (and K): Q², which no model carries,
  // is not fitted (left free, its 3/τ² traded with N²'s 1/τ).
  const std::array<double, 4> c{-std::numeric_limits<double>::infinity(), c_from_coefficient(Term::N, 0.001),
                                c_from_coefficient(Term::B, 0.005), 0.0};
  auto avar = [&](double tau, double cn, double cb) {
    return 0.2 / (tau * tau) + cn * term_basis(Term::N, tau) + cb * term_basis(Term::B, tau);
  };
  MidTauReference ref;
  for (double tau = 1.0; tau < 2400.0; tau *= std::pow(10.0, 0.1)) {
    ref.tau.push_back(tau);
    ref.mean.push_back(avar(tau, c[1], c[2]));
    ref.var.push_back(std::pow(0.05 * ref.mean.back(), 2));
    ref.grid.push_back(ref.grid.size() + 1);
  }
  std::vector<double> v;
  for (double tau : ref.tau) v.push_back(avar(tau, 0.5 * c[1], 1.3 * c[2]));
  const auto dc = power_law_corrections(v, ref, c, 1200.0, true);
  EXPECT_EQ(dc[0], 0.0);
  EXPECT_NEAR(dc[1], -0.5 * c[1], 1e-6 * c[1]);
  EXPECT_NEAR(dc[2], 0.3 * c[2], 1e-6 * c[2]);
  EXPECT_EQ(dc[3], 0.0);

  // An excess of the white angle noise's shape 3/τ² is not a correction: no model would carry it.
  for (std::size_t i = 0; i < v.size(); ++i) v[i] += 3.0 * 0.02 / (ref.tau[i] * ref.tau[i]);
  EXPECT_EQ(power_law_corrections(v, ref, c, 1200.0, true)[0], 0.0);

  // Both N² and B² asked below zero with K held: every term at its bound, nothing left to fit.
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.2 / (ref.tau[i] * ref.tau[i]) * 0.999;
  const auto d0 = power_law_corrections(v, ref, c, 1200.0, true);
  EXPECT_EQ(d0[0], 0.0);
  EXPECT_DOUBLE_EQ(d0[1], -c[1]);
  EXPECT_DOUBLE_EQ(d0[2], -c[2]);
}

}  // namespace
