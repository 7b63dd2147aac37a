// The diagnosis pipeline: base fit → ensemble band and detector calibration → findings →
// extended model → its band and the gain, in and out of sample; JSON and the readable report.
#include "rwcalc/diagnose.hpp"

#include <fmt/format.h>

#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "rwcalc/diagnose_detectors.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/units.hpp"
#include "core/timing.hpp"

namespace rwcalc {

using nlohmann::json;
using namespace diag;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kPulseFitTauMin = 20.0;  ///< s, start of the base fit for pulse data
constexpr double kGmMinPeakRatio = 0.6;  ///< bump AV at its peak / base AV there, to name a Gauss–Markov term
constexpr double kGmMinExcess = 2.0;      ///< ensemble SDs a Gauss–Markov bump must raise the mid-τ AV by
constexpr double kStepMinSide = 60.0;     ///< s of a half on each side of a known step to estimate its size there
/// Gauss–Markov statistic: the deviance drop (2 ln of the likelihood ratio) M1 must reach at least.
const double kGmMinLogLr = 2.0 * std::log(100.0);
constexpr double kModelEdf = 1000.0;      ///< model floor of the EDF in the deviance (as band_misfit)

constexpr double kMinDuration = 1200.0;  ///< s, the shortest record the diagnosis takes (its detectors need it)

/// The splits of the out-of-sample check for a record of `T` seconds: halves, and thirds when each
/// third lasts at least kMinDuration (docs/diagnosis.md, Gain).
std::vector<std::size_t> holdout_splits(double T) {
  if (T >= 3.0 * kMinDuration) return {2, 3};
  return {2};
}

double term_value(const FitResult& f, Term t) {
  const auto& c = f[t];
  return (c.enabled && c.in_model) ? c.estimate : 0.0;
}

/// The five-term model of an analysis, read out like the data.
NoiseModel base_model(const AnalysisResult& a, const PhaseSeries& x) {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = term_value(a.fit, Term::N);
  m.bias_instability_deg_per_h = term_value(a.fit, Term::B);
  m.rrw_deg_per_h_per_sqrt_h = term_value(a.fit, Term::K);
  m.ramp_deg_per_h2 = term_value(a.fit, Term::R);
  m.earth_rate_deg_per_h = a.earth_rate_deg_per_h;
  m.bias_deg_per_h = a.mean_rate_deg_per_h - a.earth_rate_deg_per_h;
  const double q_fit = term_value(a.fit, Term::Q);
  if (x.exact()) {
    // Pulse data: which read-out? A dithered (white) read-out gives σ(τ0) ≈ √(1/2)·q/τ0 = 0.71·q/τ0;
    // plain counting of a rate of a few pulses per sample or less gives far less (0.18·q/τ0 at
    // 13.5 pulses/s and 400 Hz). The boundary 0.45·q/τ0 separates them.
    const double q = x.arcsec_per_count;
    const bool white = !a.allan.points.empty() && a.allan.points.front().m == 1 &&
                       a.allan.points.front().dev * x.tau0_s / q > 0.45;
    m.readout = white ? ReadoutMode::White : ReadoutMode::Counting;
    // Extra white angle noise only when the fitted Q clearly exceeds the read-out's own level.
    const double q_read = readout_q_arcsec(m.readout, q);
    if (q_fit > 1.2 * q_read) m.white_angle_arcsec = std::sqrt(q_fit * q_fit - q_read * q_read);
  } else {
    m.readout = ReadoutMode::White;
    m.white_angle_arcsec = q_fit;
  }
  return m;
}

/// Pulse weight of the simulations: the data's for pulse data; a negligible one otherwise.
double sim_scale(const PhaseSeries& x, const AnalysisResult& a) {
  if (x.exact()) return x.arcsec_per_count;
  return std::max(1e-6, 1e-3 * term_value(a.fit, Term::Q));
}

PhaseSeries slice(const PhaseSeries& x, std::size_t a, std::size_t b) {
  PhaseSeries s;
  s.tau0_s = x.tau0_s;
  s.kind = x.kind;
  s.arcsec_per_count = x.arcsec_per_count;
  s.rate_offset = x.rate_offset;
  if (!x.counts.empty())
    s.counts.assign(x.counts.begin() + static_cast<std::ptrdiff_t>(a), x.counts.begin() + static_cast<std::ptrdiff_t>(b) + 1);
  else if (x.exact())
    s.counts.assign(x.counts32.begin() + static_cast<std::ptrdiff_t>(a), x.counts32.begin() + static_cast<std::ptrdiff_t>(b) + 1);
  else
    s.values.assign(x.values.begin() + static_cast<std::ptrdiff_t>(a), x.values.begin() + static_cast<std::ptrdiff_t>(b) + 1);
  return s;
}

Recording with_series(const Recording& rec, PhaseSeries s) {
  Recording r;
  r.source = rec.source;
  r.rate_hz = rec.rate_hz;
  r.rate_source = rec.rate_source;
  r.samples = s.points() - 1;
  r.temperature_c = rec.temperature_c;
  r.column_name = rec.column_name;
  r.mode = s.exact() ? rec.mode : InputMode::Angle;
  r.phase = std::move(s);
  return r;
}

/// The series with the deterministic terms of `det` (time origin t0) removed: floating phase.
PhaseSeries cleaned(const PhaseSeries& x, const NoiseModel& det, double t0) {
  PhaseSeries s;
  s.tau0_s = x.tau0_s;
  s.kind = x.kind;
  s.arcsec_per_count = x.arcsec_per_count;
  s.values.resize(x.points());
  const double a0 = deterministic_angle(det, t0);
  for (std::size_t i = 0; i < x.points(); ++i)
    s.values[i] = x.diff(i, 0) - (deterministic_angle(det, t0 + static_cast<double>(i) * x.tau0_s) - a0);
  return s;
}

/// Effects fitted on the mid-τ AV jointly with the N, B, K corrections.
bool is_mid_tau(const std::string& e) { return e == "gauss_markov"; }

/// The five-term analysis; when the default pulse-data fit range leaves too few Allan points (a
/// short record or half record), it is widened to τ ≥ 1 s, then to all τ.
AnalysisResult analyze_for_base(const Recording& rec, const AnalysisOptions& aopt) {
  try {
    return analyze(rec, aopt);
  } catch (const AnalysisError&) {
    if (!(aopt.fit.tau_min_s > 0)) throw;
    AnalysisOptions wider = aopt;
    wider.fit.tau_min_s = aopt.fit.tau_min_s > 1.0 ? 1.0 : 0.0;
    return analyze_for_base(rec, wider);
  }
}

/// Fit-scale squared coefficients of a model (Q free: the read-out is simulated).
std::array<double, 4> c_of(const NoiseModel& m) {
  return {-std::numeric_limits<double>::infinity(), c_from_coefficient(Term::N, m.arw_deg_per_sqrt_h),
          c_from_coefficient(Term::B, m.bias_instability_deg_per_h),
          c_from_coefficient(Term::K, m.rrw_deg_per_h_per_sqrt_h)};
}

/// The output-chain low-pass fit on the octave AV of an analysis (measured EDF).
OutputLowpassEstimate lowpass_of(const AllanResult& a, double duration) {
  std::vector<std::int64_t> m;
  std::vector<double> v, edf;
  for (const auto& p : a.points) {
    m.push_back(p.m);
    v.push_back(p.var);
    edf.push_back(p.edf);
  }
  return output_lowpass_detect(m, v, edf, a.tau0_s, duration);
}

/// Whether a floating series is pulse counts given as numbers: its first 10⁵ increments are
/// within 10⁻³ of integer multiples of the smallest non-zero one, and that step is coarse against
/// the increments' own scatter (at least half their standard deviation). A finely quantized
/// read-out (an ADC's least significant bit far below the noise) is not counting.
bool on_lattice(const PhaseSeries& x) {
  const std::size_t n = std::min<std::size_t>(x.points() - 1, 100000);
  if (n < 2) return false;
  double step = 0, sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = x.diff(i + 1, i);
    sum += d;
    sum2 += d * d;
    if (std::abs(d) > 1e-9 && (step == 0 || std::abs(d) < step)) step = std::abs(d);
  }
  if (!(step > 0)) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::abs(x.diff(i + 1, i)) / step;
    if (std::abs(r - std::round(r)) > 1e-3) return false;
  }
  const double mean = sum / double(n);
  const double sd = std::sqrt(std::max(0.0, sum2 / double(n) - mean * mean));
  return step >= 0.5 * sd;
}

/// The mid-τ reference of an ensemble's records without their own mean-shape candidate.
MidTauReference clean_reference(const std::vector<std::size_t>& grid, double tau_d, std::vector<RunStats> runs) {
  for (auto& r : runs) r.mid_var = r.mid_var_clean;
  return make_reference(grid, tau_d, runs);
}

/// Gamma deviance of a mid-τ AV against an ensemble reference: Σ ν(r − 1 − ln r), r = v/E v, with
/// the EDF ν = 2(E v)²/Var v of the ensemble and a 1000-EDF model floor (as band_misfit).
double mid_deviance(const std::vector<double>& v, const MidTauReference& ref) {
  double d = 0;
  for (std::size_t i = 0; i < v.size() && i < ref.mean.size(); ++i) {
    if (!(v[i] > 0) || !(ref.mean[i] > 0) || !(ref.var[i] > 0)) continue;
    const double nu = 1.0 / (ref.var[i] / (2.0 * ref.mean[i] * ref.mean[i]) + 1.0 / kModelEdf);
    const double q = v[i] / ref.mean[i];
    d += nu * (q - 1.0 - std::log(q));
  }
  return d;
}

/// Everything needed to estimate named effects on one stretch of data.
struct Stretch {
  const Recording* rec = nullptr;   ///< the stretch as a recording
  const AnalysisResult* analysis = nullptr;
  Decimated dec;                    ///< its decimated angle
  MidTauReference ref;              ///< mid-τ AV reference of its base model's ensemble
  MidTauReference clean_ref;        ///< the same of its records without their own candidate
  std::size_t runs = 0;
  // For the extended model's pilot calibration, like the base's (all set, or none: no pilot).
  const SimulationSettings* settings = nullptr;  ///< settings (and seed) of the base model's pilot ensemble
  const std::vector<std::int64_t>* octave_m = nullptr;
  const DiagnoseOptions* opt = nullptr;
  std::size_t pilot_runs = 0;
  /// A named step's time known from the whole record, in stretch time (< 0: estimate it on the
  /// stretch). Only its size is then estimated on the stretch.
  double step_time_s = -1;
  /// A named high-frequency line's frequency from the whole record (0: search the whole band).
  double line_hint_hz = 0;
  /// A named Gauss–Markov term's correlation time from the whole record (0: fit it on the stretch).
  double gm_tc_s = 0;
};

struct Extension {
  NoiseModel model;                 ///< extended model (time origin: the stretch start)
  std::vector<Finding> findings;    ///< parameters only (no evidence)
};

/// The mean over [0, T] of the rate added by a model's deterministic terms, °/h.
double mean_rate_of(const NoiseModel& det, double T) {
  if (!(T > 0)) return 0.0;
  double a = 0;  // angle added over [0, T], (°/h)·s
  for (const auto& x : det.sinusoids) {
    const double w = 2.0 * kPi * x.f_hz;
    if (w > 0) a += x.amp_deg_per_h / w * (std::sin(w * T + x.phase_rad) - std::sin(x.phase_rad));
  }
  for (const auto& x : det.bias_steps) a += x.size_deg_per_h * std::max(0.0, T - std::max(0.0, x.t_s));
  for (const auto& x : det.warmups) a += x.amp_deg_per_h * x.tc_s * -std::expm1(-T / x.tc_s);
  return a / T;
}

/// A bias step at a known time `ts` (time of θ_0 = 0): its size as the difference of the mean
/// rates over up to 30 min on each side, as step_detect; σ from the 1-s block means' white level.
StepEstimate step_at(const Decimated& d, double ts) {
  StepEstimate e;
  e.t_s = ts;
  const double T = d.duration();
  const double wa = std::min(1800.0, ts), wb = std::min(1800.0, T - ts);
  if (!(wa > d.tau_d) || !(wb > d.tau_d)) return e;
  auto theta_at = [&](double t) {  // linear interpolation of the decimated angle
    const double u = std::clamp(t / d.tau_d, 0.0, static_cast<double>(d.theta.size() - 1));
    const auto i = std::min(static_cast<std::size_t>(u), d.theta.size() - 2);
    const double f = u - static_cast<double>(i);
    return d.theta[i] + f * (d.theta[i + 1] - d.theta[i]);
  };
  const double th = theta_at(ts);
  e.size = (theta_at(ts + wb) - th) / wb - (th - theta_at(ts - wa)) / wa;
  const auto y1 = block_rates(d, std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(1.0 / d.tau_d))));
  double s2 = 0;
  for (std::size_t i = 0; i + 1 < y1.size(); ++i) s2 += (y1[i + 1] - y1[i]) * (y1[i + 1] - y1[i]);
  const double sig1 = y1.size() > 2 ? std::sqrt(s2 / static_cast<double>(y1.size() - 1) / 2.0) : 0.0;
  e.size_sigma = sig1 * std::sqrt(1.0 / wa + 1.0 / wb);
  return e;
}

/// Add a fit-scale correction to a coefficient (°/√h, °/h, …), the corrected square kept ≥ 0.
void correct(double& coef, Term t, double dc) {
  coef = coefficient_from_c(t, std::max(0.0, c_from_coefficient(t, coef) + dc));
}

/// A model plus a fitted Gauss–Markov bump, with the fit's corrections of B² and K² and the white
/// rate noise it leaves beside the bump.
NoiseModel with_bump(const NoiseModel& base, const ShapeEstimate& est) {
  NoiseModel m = base;
  correct(m.bias_instability_deg_per_h, Term::B, est.dc[2]);
  correct(m.rrw_deg_per_h_per_sqrt_h, Term::K, est.dc[3]);
  m.arw_deg_per_sqrt_h = coefficient_from_c(Term::N, est.white_rest);
  m.gauss_markov.push_back({std::sqrt(std::max(est.scale, 0.0)), std::max(est.time, 1e-3)});
  return m;
}

/// Whether a bump fit passes the naming conditions of a Gauss–Markov term before its likelihood
/// test: it raises the mid-τ AV by kGmMinExcess ensemble SDs somewhere or leaves white rate noise
/// beside the bump, and its AV at its peak is at least kGmMinPeakRatio of the base model's there.
bool plausible_bump(const ShapeEstimate& gm) {
  return gm.scale > 0 && (gm.excess >= kGmMinExcess || gm.white_rest >= 2.0 * gm.white_rest_sigma) &&
         gm.peak_ratio >= kGmMinPeakRatio;
}

/// The Gauss–Markov detector on a mid-τ AV `mid_meas` (the data without its mean-shape candidate): the
/// bump fit against the base ensemble (`ref`, its records `base_runs`) proposes M1 = base plus the
/// bump, which is simulated; the statistic is the drop of the mid-τ Gamma deviance from the base
/// ensemble (`clean_ref`, records without their candidate) to M1's, and the threshold the largest
/// drop of a base record (scored alike) and at least 2 ln 100. docs/diagnosis.md, "Naming a
/// Gauss–Markov term".
DetectorResult gauss_markov_test(const std::vector<double>& mid_meas, const MidTauReference& ref,
                                 const MidTauReference& clean_ref, const std::vector<RunStats>& base_runs,
                                 const NoiseModel& base, const SimulationSettings& settings, std::size_t runs,
                                 const std::vector<std::int64_t>& octave_m, const std::vector<std::size_t>& grid,
                                 double tau_d, const DiagnoseOptions& opt) {
  const auto gm = shape_detect(mid_meas, ref, c_of(base));
  DetectorResult d_gm;
  d_gm.effect = "gauss_markov";
  d_gm.threshold = kGmMinLogLr;
  if (!(gm.scale > 0)) {
    d_gm.note = "no bump improves the fit of the mid-τ Allan variance";
  } else if (gm.excess < kGmMinExcess && gm.white_rest < 2.0 * gm.white_rest_sigma) {
    // A Gauss–Markov rate adds variance around its peak, or keeps white rate noise beside it
    // when the base fit has taken the bump into B. A fit that only lowers the mid-τ AV by trading
    // the white noise for a bump (a deficit, e.g. after a sinusoid absorbed into the base N and B
    // was removed) is not one. (A low-pass of the sensed rate before counting is a Gauss–Markov
    // rate, Tc = τf and 2σ²Tc = N², and is named as one.)
    d_gm.note = fmt::format("the fitted shape raises the mid-τ Allan variance by at most {:.2g} ensemble standard "
                            "deviations and leaves no white rate noise ({:.3g} ± {:.2g} (°/h)²·s): a deficit, not a "
                            "Gauss–Markov bump",
                            gm.excess, gm.white_rest, gm.white_rest_sigma);
  } else if (gm.peak_ratio < kGmMinPeakRatio) {
    // A bump far below the local AV is a re-arrangement of the flicker or white noise (a flicker
    // floor is a sum of Gauss–Markov terms): tested only when it carries a sizeable share there.
    d_gm.note = fmt::format("the bump's Allan variance at its peak is {:.2g} of the base model's there (at least {:g} "
                            "needed): not told apart from the flicker and white noise",
                            gm.peak_ratio, kGmMinPeakRatio);
  } else {
    const NoiseModel m1 = with_bump(base, gm);
    const auto m1_runs = run_ensemble(m1, settings, runs, octave_m, grid, false, opt, true);
    const auto m1_ref = clean_reference(grid, tau_d, m1_runs);
    d_gm.statistic = mid_deviance(mid_meas, clean_ref) - mid_deviance(mid_meas, m1_ref);
    std::vector<double> e_gm;
    for (const auto& br : base_runs) {
      const auto loo = leave_one_out(clean_ref, br.mid_var_clean, runs);
      e_gm.push_back(mid_deviance(br.mid_var_clean, loo) - mid_deviance(br.mid_var_clean, m1_ref));
    }
    d_gm.ensemble_max = *std::max_element(e_gm.begin(), e_gm.end());
    d_gm.ensemble_median = quantile(e_gm, 0.5);
    d_gm.threshold = std::max(kGmMinLogLr, d_gm.ensemble_max);
    d_gm.fired = d_gm.named = d_gm.statistic > d_gm.threshold;
  }
  return d_gm;
}

/// The corrections of N², B² (K held, τ ≤ T/6) that bring the mean mid-τ AV of a pilot ensemble
/// of `m` onto the AV of `dec`; `clean`: the pilot records are taken without their own
/// mean-shape candidates, as `dec` is.
std::array<double, 4> pilot_corrections(const NoiseModel& m, const SimulationSettings& settings, std::size_t runs,
                                        const std::vector<std::int64_t>& octave_m, const Decimated& dec,
                                        const std::vector<std::size_t>& grid, const DiagnoseOptions& opt,
                                        bool clean) {
  auto pilot = run_ensemble(m, settings, runs, octave_m, grid, false, opt);
  if (clean)
    for (auto& p : pilot) p.mid_var = p.mid_var_clean;
  const auto ref = make_reference(grid, dec.tau_d, pilot);
  return calibration_corrections(decimated_avar(dec, grid), ref, c_of(m), dec.duration() / 6.0);
}

NoiseModel calibrated(const NoiseModel& m0, const SimulationSettings& settings, std::size_t runs,
                      const std::vector<std::int64_t>& octave_m, const Decimated& dec,
                      const std::vector<std::size_t>& grid, const DiagnoseOptions& opt);

/// Estimate the named effects on a stretch and build the extended model: deterministic terms by
/// least squares on their statistic, removed before the five-term fit and pilot calibration of
/// the rest (as for the base) and before the mid-τ shape fit of a stochastic term, whose Q/N/B/K
/// corrections also enter the model.
Extension extend(const Stretch& s, const NoiseModel& base, const std::vector<std::string>& effects, double f_hint,
                 const AnalysisOptions& aopt) {
  Extension x;
  NoiseModel det;
  std::vector<Sinusoid> broad;  // broadened high-frequency lines: in the model, not subtracted
  std::optional<OutputLowpassEstimate> lowpass;
  for (const auto& e : effects) {
    Finding f;
    f.effect = e;
    if (e == "sinusoid") {
      const auto est = sinusoid_detect(without_mean_shape(s.dec), f_hint);
      det.sinusoids.push_back({est.f_hz, est.amp, est.phase});
      f.params = {{"frequency_hz", est.f_hz}, {"amplitude_deg_per_h", est.amp}, {"phase_rad", est.phase}};
      f.uncertainty = {{"frequency_hz", est.f_sigma}, {"amplitude_deg_per_h", est.amp_sigma}};
    } else if (e == "sinusoid_hf") {
      // The high-frequency line, on the stretch's raw samples (reported as a sinusoid).
      // A coherent line is subtracted from the data like the low-frequency one; a broadened line
      // (power spread over a band by a wandering phase) cannot be, and enters the model only, as
      // a sinusoid of its power at its centroid (the Allan variance sees the power, not the phase).
      const auto est = line_detect(s.rec->phase, kHighLineMinHz, s.line_hint_hz);
      (est.coherent ? det.sinusoids : broad).push_back({est.f_hz, est.amp, est.phase});
      f.params = {{"frequency_hz", est.f_hz}, {"amplitude_deg_per_h", est.amp}, {"phase_rad", est.phase}};
      f.uncertainty = {{"frequency_hz", est.f_sigma}, {"amplitude_deg_per_h", est.amp_sigma}};
      f.evidence = {{"coherent", est.coherent}, {"resolution_hz", est.resolution_hz}};
      if (!est.coherent) f.evidence["width_hz"] = est.width_hz;
    } else if (e == "bias_step") {
      const auto est = s.step_time_s >= 0 ? step_at(s.dec, s.step_time_s) : step_detect(s.dec);
      det.bias_steps.push_back({est.t_s, est.size});
      f.params = {{"time_s", est.t_s}, {"size_deg_per_h", est.size}};
      f.uncertainty = {{"time_s", est.t_sigma}, {"size_deg_per_h", est.size_sigma}};
    } else if (e == "warmup_transient") {
      const auto est = warmup_detect(s.dec);
      det.warmups.push_back({est.amp, est.tc});
      f.params = {{"amplitude_deg_per_h", est.amp}, {"time_constant_s", est.tc}};
      f.uncertainty = {{"amplitude_deg_per_h", est.amp_sigma}, {"time_constant_s", est.tc_sigma}};
    } else if (e == "lowpass") {
      // The output-chain filter: its time constant and the white angle noise before it from the
      // short-τ octave AV; N, B, K stay the mid-τ ones.
      const auto est = lowpass_of(s.analysis->allan, s.rec->phase.duration_s());
      f.params = {{"time_constant_s", est.tf}};
      f.uncertainty = {{"time_constant_s", 0.5 * (est.tf_high - est.tf_low)}};
      lowpass = est;
    } else {
      continue;
    }
    x.findings.push_back(std::move(f));
  }
  x.model = base;
  // The named terms keep the stretch's mean rate: the counting read-out's fine structure at short
  // τ (the beat of the pulse rate against the sampling) depends on the rate in each part of the
  // record, so the level before a step or under a transient must be the data's, not the mean's.
  x.model.bias_deg_per_h -= mean_rate_of(det, s.rec->phase.duration_s());
  x.model.sinusoids = det.sinusoids;
  x.model.sinusoids.insert(x.model.sinusoids.end(), broad.begin(), broad.end());
  x.model.bias_steps = det.bias_steps;
  x.model.warmups = det.warmups;
  if (lowpass && lowpass->tf > 0) {
    // A high-frequency line measured behind the output-chain low-pass: the model's line is the
    // sensed one, which the simulated filter y_k = φy_{k−1} + (1 − φ)r_k then attenuates by
    // |H| and shifts by arg H, H = (1 − φ)/(1 − φe^{−iωτ0}).
    const double t0 = s.rec->phase.tau0_s, phi = std::exp(-t0 / lowpass->tf);
    std::size_t j = 0;
    for (auto& l : x.model.sinusoids) {
      if (!(l.f_hz > kHighLineMinHz)) continue;
      const std::complex<double> h = (1.0 - phi) / (1.0 - phi * std::polar(1.0, -2.0 * kPi * l.f_hz * t0));
      l.amp_deg_per_h /= std::abs(h);
      if (l.phase_rad != 0) l.phase_rad = std::remainder(l.phase_rad - std::arg(h), 2.0 * kPi);
      for (; j < x.findings.size(); ++j)
        if (x.findings[j].effect == "sinusoid_hf") {
          auto& f = x.findings[j];
          f.evidence["measured_amplitude_deg_per_h"] = f.params["amplitude_deg_per_h"];
          f.params["amplitude_deg_per_h"] = l.amp_deg_per_h;
          f.params["phase_rad"] = l.phase_rad;
          f.uncertainty["amplitude_deg_per_h"] = f.uncertainty["amplitude_deg_per_h"].get<double>() / std::abs(h);
          ++j;
          break;
        }
    }
  }
  if (!broad.empty() && !lowpass) {
    // Beyond its first Allan-variance peak (τ ≳ 1/(2f)) a line's AV averages 3A²/(8π²f²τ²): the
    // shape of white angle noise Q² = A²/(8π²f²), which the five-term fit has taken into its Q. A
    // broadened line is not subtracted from the data, so its share is taken out of Q here.
    double q2 = x.model.white_angle_arcsec * x.model.white_angle_arcsec;
    for (const auto& l : broad) q2 -= l.amp_deg_per_h * l.amp_deg_per_h / (8.0 * kPi * kPi * l.f_hz * l.f_hz);
    x.model.white_angle_arcsec = std::sqrt(std::max(0.0, q2));
  }
  if (lowpass) {
    x.model.output_lowpass_tc_s = lowpass->tf;
    x.model.white_angle_arcsec = std::sqrt(std::max(0.0, lowpass->white_angle2));
  }
  // Re-fit: the mid-τ AV of the data without the named deterministic terms (and without its own
  // candidates of the kinds not named, as the base ensemble's records) against the base ensemble
  // gives the corrections of N², B², K² — jointly with the bump of a stochastic term.
  NoiseModel det_mid = det;
  {
    const NoiseModel c = own_candidates(s.dec);
    if (det.bias_steps.empty() && det.warmups.empty()) {
      det_mid.bias_steps = c.bias_steps;
      det_mid.warmups = c.warmups;
    }
    if (det.sinusoids.empty()) det_mid.sinusoids = c.sinusoids;
  }
  Decimated dm = s.dec;
  subtract_deterministic(dm, det_mid);
  const auto v = decimated_avar(dm, s.ref.grid);
  const bool stochastic = std::any_of(effects.begin(), effects.end(), is_mid_tau);
  const bool deterministic = !det.sinusoids.empty() || !det.bias_steps.empty() || !det.warmups.empty();
  const bool self_pilot = !stochastic && deterministic && s.settings && s.octave_m && s.opt && s.pilot_runs > 0;
  if (!stochastic && !x.findings.empty() && !self_pilot) {
    // Like the base calibration: the data without their candidate (or named terms) against the
    // ensemble's records without their own candidate.
    const auto dc = power_law_corrections(v, s.clean_ref.mean.empty() ? s.ref : s.clean_ref, c_of(base));
    correct(x.model.arw_deg_per_sqrt_h, Term::N, dc[1]);
    correct(x.model.bias_instability_deg_per_h, Term::B, dc[2]);
    correct(x.model.rrw_deg_per_h_per_sqrt_h, Term::K, dc[3]);
  }
  if (deterministic && !lowpass && s.rec && (self_pilot || !det.sinusoids.empty())) {
    // The extended model is built like the base, on the data without the named terms: the
    // five-term fit of the record without them (and without its mean-shape candidate when no step
    // or transient is named), then N and B calibrated by a pilot ensemble against the mid-τ AV of
    // those data, the pilot records without their own candidates (like with like), with the
    // base's pilot seeds (common random numbers: where the named terms are the base's candidate,
    // the two models differ by the terms only, not by the pilot's sampling noise). A sinusoid is
    // not part of the base's candidate, so the base took it into N, B and the fit's Q: beyond its
    // AV peak (τ ≈ 1/(2f)) a line's AV falls as 1/τ², the shape of white angle noise, and the fit
    // from 20 s on takes it into Q; simulated as extra white angle noise under a counting read-out
    // that multiplies σ at τ0 (a misfit of 250–500 at the high-EDF short τ for lines of
    // 0.01–0.03 Hz, for both models, when the extended model kept the base's Q).
    NoiseModel rm = det;
    if (det.bias_steps.empty() && det.warmups.empty()) {
      const NoiseModel c = own_candidates(s.dec);
      rm.bias_steps = c.bias_steps;
      rm.warmups = c.warmups;
    }
    const Recording clean = with_series(*s.rec, cleaned(s.rec->phase, rm, 0.0));
    NoiseModel m0 = base_model(analyze_for_base(clean, aopt), s.rec->phase);
    m0.bias_deg_per_h = base.bias_deg_per_h;
    Decimated dclean = s.dec;
    subtract_deterministic(dclean, rm);
    x.model.white_angle_arcsec = m0.white_angle_arcsec;
    x.model.readout = m0.readout;
    if (self_pilot) {
      const NoiseModel m = calibrated(m0, *s.settings, s.pilot_runs, *s.octave_m, dclean, s.ref.grid, *s.opt);
      x.model.arw_deg_per_sqrt_h = m.arw_deg_per_sqrt_h;
      x.model.bias_instability_deg_per_h = m.bias_instability_deg_per_h;
      x.model.rrw_deg_per_h_per_sqrt_h = m.rrw_deg_per_h_per_sqrt_h;
      x.model.ramp_deg_per_h2 = m.ramp_deg_per_h2;
    }
    // (With a stochastic term N, B, K come from its joint fit below; the white angle noise is
    // still the fit's without the line.)
  }
  for (const auto& e : effects) {
    if (!is_mid_tau(e)) continue;
    const ShapeEstimate est = shape_detect(v, s.ref, c_of(base), s.gm_tc_s);
    correct(x.model.bias_instability_deg_per_h, Term::B, est.dc[2]);
    correct(x.model.rrw_deg_per_h_per_sqrt_h, Term::K, est.dc[3]);
    Finding f;
    f.effect = e;
    const double tc = std::max(est.time, 1e-3);
    x.model.arw_deg_per_sqrt_h = coefficient_from_c(Term::N, est.white_rest);
    const double sigma = std::sqrt(std::max(est.scale, 0.0));
    x.model.gauss_markov.push_back({sigma, tc});
    f.params = {{"sigma_deg_per_h", sigma}, {"correlation_time_s", est.time}};
    f.uncertainty = {{"sigma_deg_per_h", sigma > 0 ? est.scale_sigma / (2 * sigma) : 0.0},
                     {"correlation_time_s", 0.5 * (est.time_high - est.time_low)}};
    x.findings.push_back(std::move(f));
  }
  return x;
}

/// The level a model predicts over [0, T], °/h: its constant rate and its named terms' mean (a
/// ramp, whose sign the AV does not give, predicts no change).
double model_level(const NoiseModel& m, double T) {
  return m.earth_rate_deg_per_h + m.bias_deg_per_h + mean_rate_of(m, T);
}

/// The model's mean rate over [0, T] as simulated (the ramp included), °/h.
double model_mean_rate(const NoiseModel& m, double T) {
  return model_level(m, T) + m.ramp_deg_per_h2 * T / units::seconds_per_hour / 2.0;
}

/// Variance of the records' mean rates in an ensemble, (°/h)².
double mean_rate_variance(const std::vector<RunStats>& runs) {
  if (runs.size() < 2) return 0.0;
  double s = 0, s2 = 0;
  for (const auto& r : runs) s += r.mean_rate;
  const double mu = s / static_cast<double>(runs.size());
  for (const auto& r : runs) s2 += (r.mean_rate - mu) * (r.mean_rate - mu);
  return s2 / static_cast<double>(runs.size() - 1);
}

/// The model with its constant rate set so that its mean rate over [0, T] is `mean_rate` (°/h):
/// under a counting read-out the fine structure of the short-τ AV (the beat of the pulse rate
/// against the sampling) depends on the rate, so a simulated record must have the data's.
NoiseModel with_mean_rate(NoiseModel m, double T, double mean_rate) {
  m.bias_deg_per_h += mean_rate - model_mean_rate(m, T);
  return m;
}

/// N, B, K of a model in the fit scale (band_refit's order).
std::array<double, 3> nbk_of(const NoiseModel& m) {
  return {c_from_coefficient(Term::N, m.arw_deg_per_sqrt_h), c_from_coefficient(Term::B, m.bias_instability_deg_per_h),
          c_from_coefficient(Term::K, m.rrw_deg_per_h_per_sqrt_h)};
}

/// The model with N and B re-fitted to a band of its own ensemble (band_refit), K held as in the
/// pilot calibration (over one record the trade between B and K is loose, and the longest τ with
/// a few EDF would otherwise bring in a K no fit found); false when unchanged.
bool refit_to_band(NoiseModel& m, const std::vector<BandPoint>& band, std::size_t runs) {
  const auto c = nbk_of(m);
  const auto dc = band_refit(band, runs, c, {true, true, false});
  if (dc[0] == 0 && dc[1] == 0 && dc[2] == 0) return false;
  m.arw_deg_per_sqrt_h = coefficient_from_c(Term::N, c[0] + dc[0]);
  m.bias_instability_deg_per_h = coefficient_from_c(Term::B, c[1] + dc[1]);
  m.rrw_deg_per_h_per_sqrt_h = coefficient_from_c(Term::K, c[2] + dc[2]);
  return true;
}

/// The extended model's last step: N and B re-fitted to the whole band of the data it was built
/// on (refit_to_band), the re-fitted model simulated again with the same seeds and kept, with its
/// band, when that band fits better.
void refit_whole_band(NoiseModel& m, std::vector<BandPoint>& band, const std::vector<AllanPoint>& measured,
                      const SimulationSettings& settings, std::size_t runs, const std::vector<std::int64_t>& octave_m,
                      const std::vector<std::size_t>& grid, const DiagnoseOptions& opt) {
  NoiseModel refit = m;
  if (!refit_to_band(refit, band, runs)) return;
  const auto rr = run_ensemble(refit, settings, runs, octave_m, grid, false, opt, false);
  auto b2 = make_band(measured, rr, opt.band_level);
  if (band_misfit(b2, runs) < band_misfit(band, runs)) {
    m = refit;
    band = std::move(b2);
  }
}

/// Shift a model's time origin by dt (the model then describes the record from t = dt on).
NoiseModel shifted(NoiseModel m, double dt) {
  for (auto& s : m.sinusoids) s.phase_rad = std::fmod(s.phase_rad + 2 * kPi * s.f_hz * dt, 2 * kPi);
  std::vector<BiasStep> steps;
  for (const auto& st : m.bias_steps) {
    if (st.t_s - dt > 0)
      steps.push_back({st.t_s - dt, st.size_deg_per_h});
    else
      m.bias_deg_per_h += st.size_deg_per_h;  // before the window: part of its constant rate
    // (A step after the window cannot be known: the rate stays the level before it.)
  }
  m.bias_steps = steps;
  std::vector<Warmup> w;
  if (dt >= 0)
    for (const auto& x : m.warmups) w.push_back({x.amp_deg_per_h * std::exp(-dt / x.tc_s), x.tc_s});
  m.warmups = w;  // a transient is not extrapolated backwards in time
  return m;
}

std::vector<std::int64_t> octave_of(const AllanResult& a) {
  std::vector<std::int64_t> m;
  for (const auto& p : a.points) m.push_back(p.m);
  return m;
}

/// Calibrate N and B of a five-term model by a pilot ensemble: the weighted least-squares
/// corrections that bring the pilot's mean mid-τ AV onto the measured one (`dec`), from 1 s to
/// T/6. Data and pilot records alike are taken without their own candidates (own_candidates), so
/// the shrinking of the AV by that removal is the same on both sides. K stays at the base fit's
/// value: over 1 s … T/6 of one record the trade between B and K is too loose, and a B pulled low
/// makes a quiet model beside which the record's own wander looks like a step.
NoiseModel calibrated(const NoiseModel& m0, const SimulationSettings& settings, std::size_t runs,
                      const std::vector<std::int64_t>& octave_m, const Decimated& dec,
                      const std::vector<std::size_t>& grid, const DiagnoseOptions& opt) {
  const auto dc = pilot_corrections(m0, settings, runs, octave_m, dec, grid, opt, true);
  NoiseModel m = m0;
  correct(m.arw_deg_per_sqrt_h, Term::N, dc[1]);
  correct(m.bias_instability_deg_per_h, Term::B, dc[2]);
  correct(m.rrw_deg_per_h_per_sqrt_h, Term::K, dc[3]);
  return m;
}

/// The base model of a stretch: the five-term fit of the data without the mean-shape candidate
/// (a step or a transient left in would be taken up into K, R or B, and the ensemble's wander
/// would then hide it), calibrated on the mid-τ AV by a pilot ensemble. The simulated mean rate
/// stays the measured one, so the counting read-out is reproduced.
struct RobustBase {
  NoiseModel model;
  NoiseModel candidate;
  Coefficient b_fit;  ///< B of the five-term fit without the candidate (its confidence interval)
};

RobustBase robust_base(const Recording& rec, const AnalysisResult& original, const AnalysisOptions& aopt,
                       const Decimated& dec, const SimulationSettings& settings, std::size_t pilot_runs,
                       const std::vector<std::int64_t>& octave_m, const std::vector<std::size_t>& grid,
                       const DiagnoseOptions& opt) {
  RobustBase b;
  b.candidate = own_candidates(dec);
  const Recording clean = with_series(rec, cleaned(rec.phase, b.candidate, 0.0));
  const AnalysisResult a = analyze_for_base(clean, aopt);
  NoiseModel m0 = base_model(a, rec.phase);
  m0.bias_deg_per_h = original.mean_rate_deg_per_h - original.earth_rate_deg_per_h;
  b.b_fit = a.fit[Term::B];
  Decimated dclean = dec;
  subtract_deterministic(dclean, b.candidate);
  b.model = calibrated(m0, settings, pilot_runs, octave_m, dclean, grid, opt);
  return b;
}

json band_json(const std::vector<BandPoint>& band) {
  json a = json::array();
  for (const auto& b : band)
    a.push_back({{"tau_s", b.tau_s}, {"dev", b.dev}, {"band_low", b.low}, {"band_high", b.high}, {"median", b.median},
                 {"edf", b.edf}});
  return a;
}

/// A simulated model with its band and how well the measurement sits in it.
json model_json(const NoiseModel& model, const std::vector<BandPoint>& band, double level, double misfit,
                double coverage) {
  json m;
  to_json(m, model);
  m["band"] = band_json(band);
  m["band_level"] = level;
  m["misfit"] = misfit;
  m["coverage"] = coverage;
  return m;
}

double finite_or(double v, double d = 0.0) { return std::isfinite(v) ? v : d; }

json clean_json(json j) {
  if (j.is_number_float()) return finite_or(j.get<double>());
  if (j.is_object() || j.is_array())
    for (auto& v : j) v = clean_json(v);
  return j;
}

}  // namespace

DiagnoseResult diagnose(const Recording& read, const DiagnoseOptions& opt) {
  const auto t_start = std::chrono::steady_clock::now();
  if (read.phase.kind != PhaseKind::Gyro)
    throw UsageError("diagnose needs gyro data (clock phase/frequency cannot be simulated as a gyro)");
  if (opt.runs < 10) throw UsageError(fmt::format("--runs must be at least 10 (got {})", opt.runs));
  // Outliers are screened once, on the record as read, and the requested action applied before
  // anything else: the detectors, the pilot fits and the hold-out splits all see the same data,
  // and a spike cannot pass for a bias step or inflate N. Every later analysis keeps the data it
  // is given; the report is that of the record as read.
  OutlierReport outliers;
  Recording edited;
  const Recording& rec = screen_outliers(read, opt.analysis.outlier_action, opt.analysis.outlier_threshold,
                                         outliers, edited);
  const double T = rec.phase.duration_s();
  if (T < kMinDuration)
    throw AnalysisError(fmt::format("{}: the record lasts {:.4g} s; the diagnosis needs at least {:g} s", rec.source, T, kMinDuration));
  DiagnoseResult r;
  r.runs = opt.runs;
  r.holdout_runs = opt.holdout_runs ? opt.holdout_runs : opt.runs;
  r.seed = opt.seed;
  r.band_level = opt.band_level;
  r.alpha = opt.alpha;
  detail::LapTimer timer("diagnose");
  // Pulse data: the counting read-out is simulated exactly, and its structured AV at short τ
  // would distort the five-term fit, so the base fit starts at 20 s unless a range was given.
  AnalysisOptions aopt = opt.analysis;
  aopt.outlier_action = OutlierAction::Keep;
  if (rec.phase.exact() && aopt.fit.tau_min_s <= 0) aopt.fit.tau_min_s = kPulseFitTauMin;
  r.analysis = analyze_for_base(rec, aopt);
  r.analysis.outliers = std::move(outliers);
  timer.lap("base fit");
  const PhaseSeries& x = rec.phase;
  const std::size_t n = x.points() - 1;
  r.settings.rate_hz = 1.0 / x.tau0_s;
  r.settings.duration_s = static_cast<double>(n) * x.tau0_s;
  r.settings.scale_arcsec = sim_scale(x, r.analysis);
  r.settings.seed = opt.seed;
  r.settings.temperature_c = r.analysis.temperature_c;
  const auto octave_m = octave_of(r.analysis.allan);
  Stretch full;
  full.rec = &rec;
  full.analysis = &r.analysis;
  full.dec = decimate(x);
  const auto grid = mid_tau_grid(full.dec);
  // The high-frequency line search runs on floating data only: whole pulse counts (or counts
  // given as numbers) carry the counting read-out's beat of the pulse rate against the sampling,
  // which makes lines of its own (as the output-chain low-pass, it is skipped there).
  const bool floating = !x.exact() && !on_lattice(x);
  const std::size_t pilot_runs = std::max<std::size_t>(10, opt.runs / 2);
  NoiseModel candidate;
  Coefficient b_of_fit;  // B of the five-term fit without the candidate
  {
    SimulationSettings sp = r.settings;
    sp.seed = opt.seed + 1000;
    const RobustBase rb = robust_base(rec, r.analysis, aopt, full.dec, sp, pilot_runs, octave_m, grid, opt);
    r.base = rb.model;
    candidate = rb.candidate;
    b_of_fit = rb.b_fit;
  }
  timer.lap("pilot calibration");

  // 1. The base model's ensemble: band and detector calibration.
  const auto base_runs = run_ensemble(r.base, r.settings, opt.runs, octave_m, grid, true, opt, true, floating);
  r.base_band = make_band(r.analysis.allan.points, base_runs, opt.band_level);
  full.ref = make_reference(grid, full.dec.tau_d, base_runs);
  full.clean_ref = clean_reference(grid, full.dec.tau_d, base_runs);
  full.runs = opt.runs;
  timer.lap("base ensemble");

  // 2. Detectors on the measurement.
  const auto sin = sinusoid_detect(without_mean_shape(full.dec));
  const auto step = step_detect(full.dec);
  const auto warm = warmup_detect(full.dec);
  auto calibrate = [&](const std::string& effect, double stat, const std::vector<double>& ens) {
    DetectorResult d;
    d.effect = effect;
    d.statistic = stat;
    d.threshold = gumbel_threshold(ens, opt.alpha);
    d.ensemble_max = ens.empty() ? 0.0 : *std::max_element(ens.begin(), ens.end());
    d.ensemble_median = quantile(ens, 0.5);
    d.fired = stat > d.threshold;
    d.named = d.fired;
    return d;
  };
  std::vector<double> e_sin, e_step, e_warm;
  for (const auto& br : base_runs) {
    e_sin.push_back(br.sin_stat);
    e_step.push_back(br.step_stat);
    e_warm.push_back(br.warm_stat);
  }
  DetectorResult d_sin = calibrate("sinusoid", sin.statistic, e_sin);
  DetectorResult d_step = calibrate("bias_step", step.statistic, e_step);
  DetectorResult d_warm = calibrate("warmup_transient", warm.statistic, e_warm);
  // The null of the mean-shape detectors carries the uncertainty of B: when the five-term fit of the
  // record without its candidate does not resolve B (profile-likelihood lower bound 0), the pilot's
  // calibrated B may be far below the record's, and beside such a quiet model the record's own
  // flicker wander looks like a step or a transient. Their thresholds are then also taken under B
  // at the fit's upper confidence bound (same seeds), and the larger kept: the false-alarm level
  // then holds over the range of B the record allows.
  if (b_of_fit.enabled && !b_of_fit.resolved && b_of_fit.high > r.base.bias_instability_deg_per_h) {
    NoiseModel hi = r.base;
    hi.bias_instability_deg_per_h = b_of_fit.high;
    const auto hi_runs = run_ensemble(hi, r.settings, opt.runs, octave_m, grid, true, opt);
    std::vector<double> h_step, h_warm;
    for (const auto& br : hi_runs) {
      h_step.push_back(br.step_stat);
      h_warm.push_back(br.warm_stat);
    }
    const DetectorResult s_hi = calibrate("bias_step", step.statistic, h_step);
    const DetectorResult w_hi = calibrate("warmup_transient", warm.statistic, h_warm);
    if (s_hi.threshold > d_step.threshold) d_step = s_hi;
    if (w_hi.threshold > d_warm.threshold) d_warm = w_hi;
  }
  if (d_step.fired && d_warm.fired) {
    // One change of the mean: keep the shape that fits the block means better.
    if (warm.rss < step.rss) {
      d_step.named = false;
      d_step.note = "the warm-up transient explains the block means better";
    } else {
      d_warm.named = false;
      d_warm.note = "the bias step explains the block means better";
    }
  }
  // High-frequency line: the same periodogram statistic on the raw rate samples from 0.25 Hz to
  // the Nyquist frequency, calibrated on the base records alike.
  DetectorResult d_line;
  if (floating) {
    std::vector<double> e_line;
    for (const auto& br : base_runs) e_line.push_back(br.line_stat);
    d_line = calibrate("sinusoid_hf", line_detect(x, kHighLineMinHz, 0.0, false).statistic, e_line);
  }
  std::vector<std::string> effects;
  if (d_sin.named) effects.push_back("sinusoid");
  if (d_line.named) effects.push_back("sinusoid_hf");
  if (d_step.named) effects.push_back("bias_step");
  if (d_warm.named) effects.push_back("warmup_transient");

  // Mid-τ shapes on the measurement without its own candidate, as every ensemble record, and
  // without a named sinusoid.
  NoiseModel det = candidate;
  if (d_sin.named) det.sinusoids.push_back({sin.f_hz, sin.amp, sin.phase});
  double line_f = 0;  // a coherent line's frequency (the halves search ±3 bins around it)
  if (d_line.named) {
    const auto line = line_detect(x);
    if (line.coherent) {
      line_f = line.f_hz;
      det.sinusoids.push_back({line.f_hz, line.amp, line.phase});
    }
  }
  Decimated dclean = full.dec;
  subtract_deterministic(dclean, det);
  const auto mid_meas = decimated_avar(dclean, grid);
  // Gauss–Markov. The five-term base fit takes a bump into a large flicker floor (B several times
  // the true one), and such a flicker realises bumps of that size by itself: the χ² drop of the
  // bump fit alone has no power against it. So the bump fit (Q, N, B, K corrections plus σ²·g(τ;
  // Tc), on the mid-τ AV of the data without its candidate) only proposes the alternative M1 =
  // corrected base plus the bump; M1 is simulated (same seeds), and the statistic is the drop of
  // the mid-τ Gamma deviance from the base ensemble to M1's — twice the log likelihood ratio of
  // the data under the two simulated models. It is computed alike on every base record (against
  // the base ensemble without it, and M1's), and M1 must win by more than every one of them and
  // by a likelihood ratio of at least 100.
  const DetectorResult d_gm = gauss_markov_test(mid_meas, full.ref, full.clean_ref, base_runs, r.base, r.settings,
                                                 opt.runs, octave_m, grid, full.dec.tau_d, opt);
  if (d_gm.named) effects.push_back("gauss_markov");

  // Output-chain low-pass: only floating (sub-pulse) data can have passed through one; whole
  // pulse counts come straight from the counter.
  DetectorResult d_lp;
  d_lp.effect = "lowpass";
  if (x.exact()) {
    d_lp.note = "whole pulse counts: no filter in the output chain";
  } else if (on_lattice(x)) {
    d_lp.note = "the samples are whole multiples of a step coarse against their scatter (pulse counts as numbers): no filter in the output chain";
  } else {
    const auto lp = lowpass_of(r.analysis.allan, T);
    std::vector<std::int64_t> om;
    std::vector<double> edf;
    for (const auto& p : r.analysis.allan.points) {
      om.push_back(p.m);
      edf.push_back(p.edf);
    }
    std::vector<double> e_lp;
    for (const auto& br : base_runs)
      e_lp.push_back(output_lowpass_detect(om, br.octave_var, edf, x.tau0_s, T).statistic);
    d_lp = calibrate("lowpass", lp.statistic, e_lp);
    // The simulated base records have no filter, and their statistic is often exactly 0: the
    // threshold is at least the χ²(1) (1 − α) quantile, scaled by the best fit's χ² per degree of
    // freedom when the measured shape is not fitted exactly.
    const double dof = std::max(1.0, lp.points - 4.0);
    const double floor =
        boost::math::quantile(boost::math::chi_squared(1.0), 1.0 - opt.alpha) * std::max(1.0, lp.chi2 / dof);
    if (d_lp.threshold < floor) {
      d_lp.threshold = floor;
      d_lp.fired = d_lp.named = lp.statistic > floor;
    }
    if (d_lp.named) effects.push_back("lowpass");
  }
  r.detectors = {d_sin, d_step, d_warm, d_gm, d_lp};
  if (floating) r.detectors.push_back(d_line);
  timer.lap("detectors");

  // 3–4. Extended model: parameters, re-fit, re-simulation.
  const double f_hint = d_sin.named ? sin.f_hz : 0.0;
  SimulationSettings ext_pilot = r.settings;
  ext_pilot.seed = opt.seed + 1000;  // the base's pilot seed
  full.settings = &ext_pilot;
  full.octave_m = &octave_m;
  full.opt = &opt;
  full.pilot_runs = pilot_runs;
  Extension ext = extend(full, r.base, effects, f_hint, aopt);
  r.extended = ext.model;
  for (auto& f : ext.findings) {
    const auto& d = *std::find_if(r.detectors.begin(), r.detectors.end(),
                                  [&](const DetectorResult& dd) { return dd.effect == f.effect; });
    const json extra = f.evidence;
    f.evidence = {{"statistic", d.statistic},
                  {"threshold", d.threshold},
                  {"ensemble_max", d.ensemble_max},
                  {"ensemble_median", d.ensemble_median},
                  {"false_alarm_level", opt.alpha}};
    if (f.effect == "sinusoid")
      f.evidence["detector"] = "periodogram peak of the 0.5-s block-mean rates over its local median level";
    else if (f.effect == "sinusoid_hf") {
      // Reported as a sinusoid; the evidence names its detector and band.
      f.evidence["detector"] = "periodogram peak of the raw rate samples over its local median level, whole record and Welch means (detector sinusoid_hf)";
      f.evidence["search_band_hz"] = {kHighLineMinHz, 0.5 * r.settings.rate_hz};
      for (const auto& [k, v] : extra.items()) f.evidence[k] = v;
      f.effect = "sinusoid";
    }
    else if (f.effect == "bias_step")
      f.evidence["detector"] = "largest two-window change of the 10-s block-mean rates, in units of its standard error";
    else if (f.effect == "warmup_transient")
      f.evidence["detector"] = "drop of the residual sum of squares of the 10-s block means when an exponential is added";
    else if (f.effect == "gauss_markov")
      f.evidence["detector"] = "χ² drop of the mid-τ Allan variance when a Gauss–Markov bump is added";
    else
      f.evidence["detector"] =
          "χ² drop of the short-τ Allan variance when white angle and rate noise pass through an output-chain low-pass";
    r.findings.push_back(std::move(f));
  }
  if (r.findings.empty()) {
    r.extended_band = r.base_band;
  } else {
    // Common random numbers: the extended ensemble reuses the base ensemble's seeds, so the two
    // bands differ by the model change, not by sampling noise.
    const auto ext_runs = run_ensemble(r.extended, r.settings, opt.runs, octave_m, grid, false, opt, false);
    r.extended_band = make_band(r.analysis.allan.points, ext_runs, opt.band_level);
    // Re-fit of N, B, K to the whole band (the extension was calibrated at mid τ only), kept when
    // its re-simulation (same seeds) fits the band better.
    refit_whole_band(r.extended, r.extended_band, r.analysis.allan.points, r.settings, opt.runs, octave_m, grid, opt);
  }
  timer.lap("extended model");

  // 5. Gain in sample.
  r.gain.misfit_base = band_misfit(r.base_band, opt.runs);
  r.gain.misfit_extended = band_misfit(r.extended_band, opt.runs);
  r.gain.coverage_base = band_coverage(r.base_band);
  r.gain.coverage_extended = band_coverage(r.extended_band);

  // Out of sample: the record is cut into halves and (when each lasts kMinDuration) thirds; a fold
  // fits on one block and predicts a neighbouring one, both ways. The score is the mean over the
  // folds of each split, averaged over the splits: one split alone leaves the verdict to the luck
  // of where its cut falls (a step whose level then wanders, a bump one half shows weakly).
  struct Fold {
    std::size_t len, fit, pred;  // block length (samples), fitting and predicted block
    double weight;               // of the fold's per-point score in the mean
  };
  std::vector<Fold> folds;
  const auto schemes = holdout_splits(static_cast<double>(n) * x.tau0_s);
  for (const std::size_t nb : schemes) {
    const double w = 1.0 / (static_cast<double>(schemes.size()) * 2.0 * static_cast<double>(nb - 1));
    for (std::size_t k = 0; k < nb; ++k) {
      if (k + 1 < nb) folds.push_back({n / nb, k, k + 1, w});
      if (k > 0) folds.push_back({n / nb, k, k - 1, w});
    }
  }
  // A named Gauss–Markov term keeps the whole record's correlation time in every fold (its
  // structure); σ and N, B, K are fitted on the fitting block.
  const double gm_tc = r.extended.gauss_markov.empty() ? 0.0 : r.extended.gauss_markov.front().tc_s;
  double hb = 0, he = 0;
  for (std::size_t fi = 0; fi < folds.size(); ++fi) {
    const std::size_t h = folds[fi].len;
    const double wf = folds[fi].weight;
    const std::size_t fa = folds[fi].fit * h, fb = fa + h;
    const std::size_t pa = folds[fi].pred * h, pb = pa + h;
    const Recording fit_rec = with_series(rec, slice(x, fa, fb));
    const Recording pred_rec = with_series(rec, slice(x, pa, pb));
    const AnalysisResult a_fit = analyze_for_base(fit_rec, aopt);
    AllanOptions ao = opt.analysis.allan;
    const AllanResult a_pred = compute_allan(pred_rec.phase, ao);
    const auto om = octave_of(a_pred);
    SimulationSettings sh = r.settings;
    sh.duration_s = static_cast<double>(h) * x.tau0_s;
    sh.seed = opt.seed + 10 + static_cast<std::uint64_t>(fi);
    Stretch st;
    st.rec = &fit_rec;
    st.analysis = &a_fit;
    st.dec = decimate(fit_rec.phase);
    const auto hgrid = mid_tau_grid(st.dec);
    const NoiseModel b_fit =
        robust_base(fit_rec, a_fit, aopt, st.dec, sh, r.holdout_runs, om, hgrid, opt).model;
    const SimulationSettings sh_pilot = sh;
    sh.seed += 50;
    const double dt = (static_cast<double>(pa) - static_cast<double>(fa)) * x.tau0_s;
    const bool mean_terms = std::any_of(effects.begin(), effects.end(), [](const std::string& e) {
      return e == "sinusoid" || e == "bias_step" || e == "warmup_transient";
    });
    const bool line_named = std::find(effects.begin(), effects.end(), "sinusoid_hf") != effects.end();
    // Both models are simulated over the predicted half at its measured mean rate: under a
    // counting read-out the rate sets the fine structure of the short-τ AV (the beat of the pulse
    // rate against the sampling), which also moves with the rate's wander inside a half and would
    // otherwise score the level twice and erratically. The level each model predicts is scored
    // once, explicitly: one more deviance term beside the band's, the measured mean rate against
    // the model's (its constant rate and its named terms over the window; a ramp, of unknown
    // sign, predicts no change) with the base ensemble's spread of half means, for both models —
    // −2 ln L of a normal. A step or transient in the fitting half predicts the level after it;
    // the base predicts the fitting half's mean. (With each model's own spread, a Gauss–Markov
    // half model whose B the half leaves at 0 was scored by the narrow spread of its half means,
    // not by its predicted level, which is the base's.)
    const double pred_T = pred_rec.phase.duration_s();
    const double pred_mean = pred_rec.phase.diff(pred_rec.phase.points() - 1, 0) / pred_T;
    const auto b_pred =
        run_ensemble(with_mean_rate(b_fit, pred_T, pred_mean), sh, r.holdout_runs, om, hgrid, false, opt, false);
    const double v_base = std::max(mean_rate_variance(b_pred), 1e-30);
    // A prediction's deviance: the band's on the predicted half, the level's and (below) the named
    // lines'. The explicit terms are scored against a yardstick common to both models (the base
    // ensemble's spread of half means; the predicted half's own noise PSD at a line), so that they
    // compare what each model predicts, while the noise models are compared through the band.
    struct Score {
      double sum = 0;
      std::size_t points = 0;
      [[nodiscard]] double per_point() const { return points ? sum / static_cast<double>(points) : 0.0; }
    };
    auto prediction_score = [&](const std::vector<RunStats>& runs, const NoiseModel& m) {
      const auto bb = make_band(a_pred.points, runs, opt.band_level);
      const auto dev = band_deviance(bb, r.holdout_runs);
      const double d = pred_mean - model_level(m, pred_T);
      return Score{dev.sum + d * d / v_base, dev.points + 1};
    };
    Score sb = prediction_score(b_pred, b_fit);
    const double hb_fold = sb.per_point();
    if (effects.empty()) {
      hb += wf * hb_fold;
      he += wf * hb_fold;
      continue;
    }
    // The half's base ensemble at the half's own level: the half's detectors and its mid-τ
    // references (for the Gauss–Markov test on the half and for its extended model).
    const auto b_runs = run_ensemble(b_fit, sh, r.holdout_runs, om, hgrid, mean_terms, opt, true, line_named);
    st.ref = make_reference(hgrid, st.dec.tau_d, b_runs);
    st.clean_ref = clean_reference(hgrid, st.dec.tau_d, b_runs);
    // A deterministic term is carried into the fitting half's extended model only when the half
    // itself shows it: its detector fires against the half's own base ensemble. A step or
    // transient that lies in the predicted half cannot be estimated from the fitting half; a
    // re-estimate there would be the half's largest rate excursion, a spurious term.
    std::vector<std::string> half_effects;
    // A step whose time, known from the whole record, lies inside the fitting half (at least
    // kStepMinSide of data on each side) enters with that time, only its size estimated on the
    // half: a step 350 s before the half's end is estimable from those 350 s even where the half's
    // own detector, which also searches for the time, does not fire. A step in the predicted half
    // stays out.
    double step_time = -1;
    if (!r.extended.bias_steps.empty()) {
      const double t_local = r.extended.bias_steps.front().t_s - static_cast<double>(fa) * x.tau0_s;
      if (t_local >= kStepMinSide && t_local <= static_cast<double>(h) * x.tau0_s - kStepMinSide) step_time = t_local;
    }
    for (const auto& e : effects) {
      double stat = 0;
      std::vector<double> ens;
      if (e == "bias_step") {
        if (step_time >= 0) half_effects.push_back(e);
        continue;
      }
      if (e == "sinusoid") {
        stat = sinusoid_detect(without_mean_shape(st.dec), 0.0, false).statistic;
        for (const auto& br : b_runs) ens.push_back(br.sin_stat);
      } else if (e == "sinusoid_hf") {
        stat = line_detect(fit_rec.phase, kHighLineMinHz, 0.0, false).statistic;
        for (const auto& br : b_runs) ens.push_back(br.line_stat);
      } else if (e == "warmup_transient") {
        stat = warmup_detect(st.dec).statistic;
        for (const auto& br : b_runs) ens.push_back(br.warm_stat);
      } else if (e == "gauss_markov") {
        // A Gauss–Markov term: the structure is the whole record's (its likelihood-ratio test
        // named it, and its correlation time is kept), σ and N, B, K the half's (a bump fitted on
        // one block with its own Tc is loose). The term enters when the bump fit on the half's
        // mid-τ AV (without the half's own candidate, against the half's base ensemble) passes the
        // naming conditions of the whole record before its test (it raises the mid-τ AV or leaves
        // white rate noise beside the bump, and stands at least kGmMinPeakRatio of the local AV at
        // its peak); a bump the half does not show leaves the half's extended model at its base.
        // (The half's own likelihood-ratio test, one hour of data against its base ensemble's
        // largest drop, named the bump in neither half of one record and only in one of another.)
        Decimated dh = st.dec;
        subtract_deterministic(dh, own_candidates(st.dec));
        const auto gm = shape_detect(decimated_avar(dh, hgrid), st.ref, c_of(b_fit), gm_tc);
        if (plausible_bump(gm)) half_effects.push_back(e);
        continue;
      } else {
        half_effects.push_back(e);
        continue;
      }
      if (stat > gumbel_threshold(ens, opt.alpha)) half_effects.push_back(e);
    }
    if (half_effects.empty()) {
      // Nothing named shows in the fitting half: the extended model of the half is its base.
      hb += wf * hb_fold;
      he += wf * hb_fold;
      continue;
    }
    st.runs = r.holdout_runs;
    st.settings = &sh_pilot;
    st.octave_m = &om;
    st.opt = &opt;
    st.pilot_runs = r.holdout_runs;
    st.step_time_s = step_time;
    st.line_hint_hz = line_f;
    st.gm_tc_s = gm_tc;
    const Extension e = extend(st, b_fit, half_effects, f_hint, aopt);
    // (No whole-band re-fit here: on the fitting half's band it lost two warm-up records out of
    // sample and changed no other count; docs/diagnosis.md.)
    const NoiseModel e_pred = shifted(e.model, dt);
    const auto e_runs =
        run_ensemble(with_mean_rate(e_pred, pred_T, pred_mean), sh, r.holdout_runs, om, hgrid, false, opt, false);
    Score se = prediction_score(e_runs, e_pred);
    // A named line keeps its frequency and phase into the predicted half, where the Allan variance
    // hardly sees it (the base model has taken its power into its noise terms, and beyond its AV
    // peak a line looks like white angle noise): what it predicts is the line itself, scored
    // explicitly like the level. The line's two Fourier coefficients on the predicted half (least
    // squares at the model's frequency; the 0.5-s block rates below kHighLineMinHz, the samples'
    // rates above) are normal with the standard error of the half's local noise PSD: −2 ln L is
    // |c − c_model|²/σ² for the extended model and |c|²/σ² for the base, which predicts no line.
    // A broadened line (no phase) predicts no coefficients and is left to the band.
    for (const auto& l : e_pred.sinusoids) {
      const bool broad = std::any_of(e.findings.begin(), e.findings.end(), [&](const Finding& f) {
        return f.evidence.contains("coherent") && !f.evidence["coherent"].get<bool>() &&
               f.params["frequency_hz"].get<double>() == l.f_hz;
      });
      if (broad) continue;
      std::vector<double> y;
      double tb = 0;
      if (l.f_hz < kHighLineMinHz) {
        const Decimated dp = decimate(pred_rec.phase);
        const auto per = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(0.5 / dp.tau_d)));
        y = block_rates(dp, per);
        tb = static_cast<double>(per) * dp.tau_d;
      } else {
        const auto& ph = pred_rec.phase;
        tb = ph.tau0_s;
        y.resize(ph.points() - 1);
        for (std::size_t i = 0; i + 1 < ph.points(); ++i) y[i] = ph.diff(i + 1, i) / tb;
      }
      const LineCoefficients c = line_coefficients(std::move(y), tb, l.f_hz);
      if (!(c.sigma > 0)) continue;
      const double u = kPi * l.f_hz * tb, att = u > 1e-9 ? std::sin(u) / u : 1.0;
      // The model's line is the sensed one: behind a named output-chain low-pass the predicted
      // half shows it through the simulated filter, H = (1 − φ)/(1 − φe^{−iωτ0}).
      std::complex<double> hf = 1.0;
      if (e_pred.output_lowpass_tc_s > 0) {
        const double t0 = pred_rec.phase.tau0_s, phi = std::exp(-t0 / e_pred.output_lowpass_tc_s);
        hf = (1.0 - phi) / (1.0 - phi * std::polar(1.0, -2.0 * kPi * l.f_hz * t0));
      }
      const double am = l.amp_deg_per_h * std::abs(hf) * att, ph = l.phase_rad + std::arg(hf);
      const double ap = am * std::cos(ph), bp = -am * std::sin(ph);
      const double s2 = c.sigma * c.sigma;
      sb.sum += (c.a * c.a + c.b * c.b) / s2;
      se.sum += ((c.a - ap) * (c.a - ap) + (c.b - bp) * (c.b - bp)) / s2;
      sb.points += 2;
      se.points += 2;
    }
    const double he_fold = se.per_point();
    hb += wf * sb.per_point();
    he += wf * he_fold;
  }
  timer.lap("out-of-sample check");
  r.gain.holdout_misfit_base = hb;
  r.gain.holdout_misfit_extended = he;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

json to_json(const DiagnoseResult& r) {
  json j;
  j["source"] = r.analysis.source;
  j["samples"] = r.analysis.samples;
  j["rate_hz"] = r.settings.rate_hz;
  j["duration_s"] = r.settings.duration_s;
  j["scale_arcsec_per_pulse"] = r.settings.scale_arcsec;
  j["temperature_c"] = r.analysis.temperature_c ? json(*r.analysis.temperature_c) : json(nullptr);
  j["runs"] = r.runs;
  j["holdout_runs"] = r.holdout_runs;
  j["seed"] = r.seed;
  j["false_alarm_level_per_detector"] = r.alpha;
  j["simulation_path"] = "ensemble";
  j["outliers"] = to_json(r.analysis.outliers);
  json base = model_json(r.base, r.base_band, r.band_level, r.gain.misfit_base, r.gain.coverage_base);
  // Not under "fit": model_from_analysis_json would read those coefficients instead of this model.
  base["fitted_coefficients"] = {{"Q_arcsec", r.analysis.fit[Term::Q].estimate},
                                 {"N_deg_per_sqrt_h", r.analysis.fit[Term::N].estimate},
                                 {"B_deg_per_h", r.analysis.fit[Term::B].estimate},
                                 {"K_deg_per_h_per_sqrt_h", r.analysis.fit[Term::K].estimate},
                                 {"R_deg_per_h2", r.analysis.fit[Term::R].estimate},
                                 {"chi2_per_dof", r.analysis.fit.chi2_per_dof}};
  j["base_model"] = base;
  json det = json::array();
  for (const auto& d : r.detectors) {
    json o = {{"effect", d.effect},         {"statistic", d.statistic},   {"threshold", d.threshold},
              {"ensemble_max", d.ensemble_max}, {"ensemble_median", d.ensemble_median}, {"fired", d.fired},
              {"named", d.named}};
    if (!d.note.empty()) o["note"] = d.note;
    det.push_back(o);
  }
  j["detectors"] = det;
  json fnd = json::array();
  for (const auto& f : r.findings) {
    json o = {{"effect", f.effect}};
    for (const auto& [k, v] : f.params.items()) o[k] = v;
    o["uncertainty"] = f.uncertainty;
    o["evidence"] = f.evidence;
    fnd.push_back(o);
  }
  j["findings"] = fnd;
  j["extended_model"] =
      model_json(r.extended, r.extended_band, r.band_level, r.gain.misfit_extended, r.gain.coverage_extended);
  j["gain"] = {{"misfit_base", r.gain.misfit_base},
               {"misfit_extended", r.gain.misfit_extended},
               {"coverage_base", r.gain.coverage_base},
               {"coverage_extended", r.gain.coverage_extended},
               {"holdout_misfit_base", r.gain.holdout_misfit_base},
               {"holdout_misfit_extended", r.gain.holdout_misfit_extended}};
  j["seconds"] = r.seconds;
  return clean_json(j);
}

namespace {

std::string unit_of(const std::string& key) {
  if (key.ends_with("_hz")) return "Hz";
  if (key.ends_with("_deg_per_h")) return "°/h";
  if (key.ends_with("_s")) return "s";
  if (key.ends_with("_rad")) return "rad";
  return "";
}

}  // namespace

std::string format_report(const DiagnoseResult& r) {
  std::string s;
  s += fmt::format("Diagnosis of {}\n", printable(r.analysis.source));
  s += fmt::format("  record: {:.0f} s at {:g} Hz, pulse weight {:g}″; ensemble of {} simulated records per model "
                   "(seed {}), band {:g} % per τ\n\n",
                   r.settings.duration_s, r.settings.rate_hz, r.settings.scale_arcsec, r.runs, r.seed,
                   r.band_level * 100);
  s += format_outliers(r.analysis.outliers);
  const auto& m = r.base;
  s += fmt::format("Base model (five-term fit): N = {:.4g} °/√h, B = {:.4g} °/h, K = {:.4g} °/h/√h, R = {:.4g} °/h², "
                   "white angle {:.4g}″, {} read-out, Earth rate {:.4g} °/h, bias {:.4g} °/h\n",
                   m.arw_deg_per_sqrt_h, m.bias_instability_deg_per_h, m.rrw_deg_per_h_per_sqrt_h, m.ramp_deg_per_h2,
                   m.white_angle_arcsec, m.readout == ReadoutMode::Counting ? "counting" : "white",
                   m.earth_rate_deg_per_h, m.bias_deg_per_h);
  std::size_t outside = 0;
  std::string rows;
  for (const auto& b : r.base_band) {
    if (b.dev >= b.low && b.dev <= b.high) continue;
    ++outside;
    if (b.dev > b.high)
      rows += fmt::format("    τ = {:>9.4g} s: σ = {:.4g} °/h, {:.1f} % above the band's upper edge {:.4g} °/h\n",
                          b.tau_s, b.dev, 100 * (b.dev / b.high - 1), b.high);
    else
      rows += fmt::format("    τ = {:>9.4g} s: σ = {:.4g} °/h, {:.1f} % below the band's lower edge {:.4g} °/h\n",
                          b.tau_s, b.dev, 100 * (1 - b.dev / b.low), b.low);
  }
  s += fmt::format("  measured Allan deviation inside the base band at {} of {} τ\n", r.base_band.size() - outside,
                   r.base_band.size());
  s += rows;
  s += "\nDetectors (statistic on the measurement against the ensemble-calibrated threshold, "
       + fmt::format("false-alarm level {:g} % each):\n", r.alpha * 100);
  for (const auto& d : r.detectors)
    s += fmt::format("  {:<17} statistic {:>9.3f} (dimensionless), threshold {:>8.3f}, ensemble max {:>8.3f}: {}{}\n",
                     d.effect, d.statistic, d.threshold, d.ensemble_max,
                     d.named ? "FOUND" : (d.fired ? "fired, not named" : "not found"),
                     d.note.empty() ? "" : " (" + d.note + ")");
  s += "\nFindings:\n";
  if (r.findings.empty()) s += "  none: the base model's simulations explain the measurement\n";
  for (const auto& f : r.findings) {
    s += fmt::format("  {}:", f.effect);
    for (const auto& [k, v] : f.params.items()) {
      if (!v.is_number()) continue;
      const double u = f.uncertainty.contains(k) ? f.uncertainty[k].get<double>() : -1;
      const std::string unit = unit_of(k);
      if (u >= 0)
        s += fmt::format(" {} = {:.4g} ± {:.2g} {}", k, v.get<double>(), u, unit);
      else
        s += fmt::format(" {} = {:.4g} {}", k, v.get<double>(), unit);
      s += ";";
    }
    s.pop_back();
    s += "\n";
  }
  const auto& e = r.extended;
  s += fmt::format("\nExtended model: N = {:.4g} °/√h, B = {:.4g} °/h, K = {:.4g} °/h/√h, R = {:.4g} °/h², "
                   "{} extra term(s)\n",
                   e.arw_deg_per_sqrt_h, e.bias_instability_deg_per_h, e.rrw_deg_per_h_per_sqrt_h, e.ramp_deg_per_h2,
                   r.findings.size());
  s += "\nGain (misfit: mean EDF-weighted Gamma deviance per τ, about 1 (dimensionless) when the model fits):\n";
  s += fmt::format("  {:<44} {:>10} {:>10}\n", "", "base", "extended");
  s += fmt::format("  {:<44} {:>10.3f} {:>10.3f}\n", "Allan-variance misfit (dimensionless)", r.gain.misfit_base,
                   r.gain.misfit_extended);
  s += fmt::format("  {:<44} {:>9.1f}% {:>9.1f}%\n", "measured τ inside the simulated band", 100 * r.gain.coverage_base,
                   100 * r.gain.coverage_extended);
  s += fmt::format("  {:<44} {:>10.3f} {:>10.3f}\n", "out-of-sample misfit (dimensionless)",
                   r.gain.holdout_misfit_base, r.gain.holdout_misfit_extended);
  s += fmt::format("\n  ({:.1f} s)\n", r.seconds);
  return s;
}

}  // namespace rwcalc
