// The base model of a record and the helpers of the extended one.
#include "models.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rwcalc/error.hpp"
#include "signal.hpp"

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
    // The fit's read-out when it modelled a plain counter. Otherwise: a dithered (white) read-out
    // gives σ(τ0) ≈ 0.71·q/τ0, plain counting of a few pulses per sample far less (0.18·q/τ0 at
    // 13.5 pulses/s and 400 Hz): 0.45·q/τ0 separates them. Below one pulse per sample counting gives
    // more (0.58·q/τ0 at 0.34 pulses, 40 Hz), and only the fit tells it.
    const double q = x.arcsec_per_count;
    const bool white = !a.fit.counter_readout && !a.allan.points.empty() && a.allan.points.front().m == 1 &&
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

FitResult refit_noise(const AnalysisResult& a, const std::vector<double>& cleaned_var, NoiseModel& extended) {
  std::vector<FitPoint> pts = fit_points(a.allan);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i].var = cleaned_var[i];
  FitResult f = fit_noise(pts, a.fit.options);
  extended.arw_deg_per_sqrt_h = term_value(f, Term::N);
  extended.bias_instability_deg_per_h = term_value(f, Term::B);
  extended.rrw_deg_per_h_per_sqrt_h = term_value(f, Term::K);
  extended.ramp_deg_per_h2 = term_value(f, Term::R);
  return f;
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
  const double mean = sum / static_cast<double>(n);
  const double sd = std::sqrt(std::max(0.0, sum2 / static_cast<double>(n) - mean * mean));
  return step >= 0.5 * sd;
}

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

}  // namespace rwcalc::diag
