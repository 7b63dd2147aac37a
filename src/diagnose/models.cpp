// The base model of a record and the helpers of the extended one.
#include "diagnose/models.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rwcalc/error.hpp"

namespace rwcalc::diag {

namespace {

double term_value(const FitResult& f, Term t) {
  const auto& c = f[t];
  return (c.enabled && c.in_model) ? c.estimate : 0.0;
}

}  // namespace

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
    // A dithered (white) read-out gives σ(τ0) ≈ 0.71·q/τ0, plain counting of a few pulses per
    // sample far less (0.18·q/τ0 at 13.5 pulses/s and 400 Hz): 0.45·q/τ0 separates them.
    const double q = x.arcsec_per_count;
    const bool white =
        !a.allan.points.empty() && a.allan.points.front().m == 1 && a.allan.points.front().dev * x.tau0_s / q > 0.45;
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

double sim_scale(const PhaseSeries& x, const AnalysisResult& a) {
  if (x.exact()) return x.arcsec_per_count;
  // Coarse enough that a record of the data's extent stays within 2^50 pulses (data of huge rates;
  // the simulator counts up to 2^61).
  double extent = 0;
  for (const double v : x.values) extent = std::max(extent, std::abs(v - x.values.front()));
  extent += std::abs(x.rate_offset) * x.duration_s();
  return std::max({1e-6, 1e-3 * term_value(a.fit, Term::Q), std::ldexp(extent, -50)});
}

AnalysisResult analyze_for_base(const Recording& rec, const AnalysisOptions& options) {
  AnalysisOptions aopt = options;
  aopt.fit_checks = false;  // the base model is the plain five-term fit: the detectors explain its misfit
  aopt.cross_checks = false;
  try {
    return analyze(rec, aopt);
  } catch (const AnalysisError&) {
    if (!(aopt.fit.tau_min_s > 0)) throw;
    AnalysisOptions wider = aopt;
    wider.fit.tau_min_s = aopt.fit.tau_min_s > 1.0 ? 1.0 : 0.0;
    return analyze_for_base(rec, wider);
  }
}

PhaseSeries slice(const PhaseSeries& x, std::size_t a, std::size_t b) {
  PhaseSeries s;
  s.tau0_s = x.tau0_s;
  s.kind = x.kind;
  s.arcsec_per_count = x.arcsec_per_count;
  s.rate_offset = x.rate_offset;
  if (x.exact()) {  // the exact counts, as 64-bit integers
    s.counts.resize(b - a + 1);
    for (std::size_t i = a; i <= b; ++i) s.counts[i - a] = x.count(i);
  } else {
    s.values.assign(x.values.begin() + static_cast<std::ptrdiff_t>(a),
                    x.values.begin() + static_cast<std::ptrdiff_t>(b) + 1);
  }
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

std::vector<std::int64_t> octave_of(const AllanResult& a) {
  std::vector<std::int64_t> m;
  for (const auto& p : a.points) m.push_back(p.m);
  return m;
}

std::array<double, 4> c_of(const NoiseModel& m) {
  return {-std::numeric_limits<double>::infinity(), c_from_coefficient(Term::N, m.arw_deg_per_sqrt_h),
          c_from_coefficient(Term::B, m.bias_instability_deg_per_h),
          c_from_coefficient(Term::K, m.rrw_deg_per_h_per_sqrt_h)};
}

void correct(double& coef, Term t, double dc) {
  coef = coefficient_from_c(t, std::max(0.0, c_from_coefficient(t, coef) + dc));
}

void correct_nbk(NoiseModel& m, const std::array<double, 4>& dc) {
  correct(m.arw_deg_per_sqrt_h, Term::N, dc[1]);
  correct(m.bias_instability_deg_per_h, Term::B, dc[2]);
  correct(m.rrw_deg_per_h_per_sqrt_h, Term::K, dc[3]);
}

double mean_rate_of(const NoiseModel& det, double T) { return T > 0 ? deterministic_angle(det, T) / T : 0.0; }

PhaseSeries cleaned(const PhaseSeries& x, const NoiseModel& det) {
  PhaseSeries s;
  s.tau0_s = x.tau0_s;
  s.kind = x.kind;
  s.arcsec_per_count = x.arcsec_per_count;
  s.values.resize(x.points());
  const double a0 = deterministic_angle(det, 0.0);
  for (std::size_t i = 0; i < x.points(); ++i)
    s.values[i] = x.diff(i, 0) - (deterministic_angle(det, static_cast<double>(i) * x.tau0_s) - a0);
  return s;
}

/// K stays at the fit's value: over 1 s … T/6 the trade between B and K is too loose, and a B
/// pulled low makes a quiet model beside which the record's own wander looks like a step.
NoiseModel calibrated(const NoiseModel& m0, const SimulationSettings& settings, std::size_t runs,
                      const EnsemblePlan& plan, const Decimated& dec, Progress* progress) {
  const EnsemblePlan pilot_plan{plan.octave_m, plan.grid, true, {}, false};
  const auto pilot = run_ensemble(m0, settings, runs, pilot_plan, progress);
  const auto ref = make_reference(plan.grid, dec.tau_d, pilot, true);
  const auto dc = power_law_corrections(decimated_avar(dec, plan.grid), ref, c_of(m0), dec.duration() / 6.0, true);
  NoiseModel m = m0;
  correct_nbk(m, dc);
  return m;
}

/// A step or transient left in would go into K, R or B, and the ensemble's wander would hide it.
RobustBase robust_base(const Recording& rec, const AnalysisResult& original, const AnalysisOptions& aopt,
                       const Decimated& dec, const SimulationSettings& pilot, std::size_t pilot_runs,
                       const EnsemblePlan& plan, Progress* progress) {
  RobustBase b;
  b.candidate = own_candidates(dec);
  const Recording clean = with_series(rec, cleaned(rec.phase, b.candidate));
  const AnalysisResult a = analyze_for_base(clean, aopt);
  NoiseModel m0 = base_model(a, rec.phase);
  m0.bias_deg_per_h = original.mean_rate_deg_per_h - original.earth_rate_deg_per_h;
  b.b_fit = a.fit[Term::B];
  Decimated dclean = dec;
  subtract_deterministic(dclean, b.candidate);
  b.model = calibrated(m0, pilot, pilot_runs, plan, dclean, progress);
  return b;
}

/// K is held as in the pilot calibration: the longest τ, with a few EDF, would otherwise bring in
/// a K no fit found.
void refit_whole_band(NoiseModel& m, std::vector<BandPoint>& band, const std::vector<AllanPoint>& measured,
                      const SimulationSettings& settings, std::size_t runs, const EnsemblePlan& plan,
                      const DiagnoseOptions& opt) {
  const auto c4 = c_of(m);
  const std::array<double, 3> c{c4[1], c4[2], c4[3]};
  const auto dc = band_refit(band, runs, c, {true, true, false});
  if (dc[0] == 0 && dc[1] == 0 && dc[2] == 0) return;
  NoiseModel refit = m;
  refit.arw_deg_per_sqrt_h = coefficient_from_c(Term::N, c[0] + dc[0]);
  refit.bias_instability_deg_per_h = coefficient_from_c(Term::B, c[1] + dc[1]);
  refit.rrw_deg_per_h_per_sqrt_h = coefficient_from_c(Term::K, c[2] + dc[2]);
  const auto rr = run_ensemble(refit, settings, runs, {plan.octave_m, {}, false, {}, false}, opt.progress);
  auto b2 = make_band(measured, rr, opt.band_level);
  if (band_misfit(b2, runs) < band_misfit(band, runs)) {
    m = refit;
    band = std::move(b2);
  }
}

}  // namespace rwcalc::diag
