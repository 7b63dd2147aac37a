// The extended model of a stretch: the named effects added to the base model, the rest re-fitted
// on the data without the named terms.
#include <algorithm>
#include <cmath>
#include <complex>

#include "diagnose/models.hpp"

namespace rwcalc::diag {

namespace {

/// A high-frequency line measured behind the output-chain low-pass: the model's line is the
/// sensed one, which the simulated filter then attenuates by |H| and shifts by arg H.
void unfilter_lines(NoiseModel& model, std::vector<Finding>& findings, double tau0, double tf) {
  std::size_t j = 0;
  for (auto& l : model.sinusoids) {
    if (!(l.f_hz > kHighLineMinHz)) continue;
    const std::complex<double> h = lowpass_response(l.f_hz, tau0, tf);
    l.amp_deg_per_h /= std::abs(h);
    if (l.phase_rad != 0) l.phase_rad = std::remainder(l.phase_rad - std::arg(h), 2.0 * kPi);
    for (; j < findings.size(); ++j)
      if (findings[j].effect == Effect::Line) {
        auto& f = findings[j];
        f.evidence["measured_amplitude_deg_per_h"] = f.params["amplitude_deg_per_h"];
        f.params["amplitude_deg_per_h"] = l.amp_deg_per_h;
        f.params["phase_rad"] = l.phase_rad;
        f.uncertainty["amplitude_deg_per_h"] = f.uncertainty["amplitude_deg_per_h"].get<double>() / std::abs(h);
        ++j;
        break;
      }
  }
}

/// The base model with the named terms, keeping the stretch's mean rate: the counting read-out's
/// short-τ structure depends on the rate in each part of the record.
NoiseModel with_named_terms(const Stretch& s, Extension& x) {
  NoiseModel m = s.base;
  m.bias_deg_per_h -= mean_rate_of(x.det, s.rec->phase.duration_s());
  m.sinusoids = x.det.sinusoids;
  m.sinusoids.insert(m.sinusoids.end(), x.broad.begin(), x.broad.end());
  m.bias_steps = x.det.bias_steps;
  m.warmups = x.det.warmups;
  if (x.lowpass && x.lowpass->tf > 0) unfilter_lines(m, x.findings, s.rec->phase.tau0_s, x.lowpass->tf);
  if (!x.broad.empty() && !x.lowpass) {
    // Beyond its first peak a line's AV is that of white angle noise (3A²/(8π²f²τ²)), which the
    // fit took into Q; a broadened line is not subtracted from the data, so Q loses its share.
    double q2 = m.white_angle_arcsec * m.white_angle_arcsec;
    for (const auto& l : x.broad) q2 -= l.amp_deg_per_h * l.amp_deg_per_h / (8.0 * kPi * kPi * l.f_hz * l.f_hz);
    m.white_angle_arcsec = std::sqrt(std::max(0.0, q2));
  }
  if (x.lowpass) {
    m.output_lowpass_tc_s = x.lowpass->tf;
    m.white_angle_arcsec = std::sqrt(std::max(0.0, x.lowpass->white_angle2));
  }
  return m;
}

/// The named deterministic terms, and the stretch's own candidate when no mean shape is named
/// (as the base ensemble's records are taken).
NoiseModel with_candidate(const Stretch& s, const NoiseModel& det) {
  NoiseModel m = det;
  if (det.bias_steps.empty() && det.warmups.empty()) {
    const NoiseModel c = own_candidates(s.dec);
    m.bias_steps = c.bias_steps;
    m.warmups = c.warmups;
  }
  return m;
}

/// The mid-τ AV of the stretch without the named terms (and its candidate).
std::vector<double> mid_var_without(const Stretch& s, const NoiseModel& det) {
  Decimated dm = s.dec;
  subtract_deterministic(dm, with_candidate(s, det));
  return decimated_avar(dm, s.ref.grid);
}

/// The extended model built like the base on the data without the named terms (and without its
/// candidate when no mean shape is named): the five-term fit, then, with `pilot`, N and B
/// calibrated with the base's pilot seeds, so that the models differ by the terms only. The base
/// took a sinusoid into Q: the white angle noise is the fit's without it.
void refit_without_named(const Stretch& s, Extension& x, bool pilot) {
  const NoiseModel rm = with_candidate(s, x.det);
  const Recording clean = with_series(*s.rec, cleaned(s.rec->phase, rm));
  NoiseModel m0 = base_model(analyze_for_base(clean, *s.aopt), s.rec->phase);
  m0.bias_deg_per_h = s.base.bias_deg_per_h;
  Decimated dclean = s.dec;
  subtract_deterministic(dclean, rm);
  x.model.white_angle_arcsec = m0.white_angle_arcsec;
  x.model.readout = m0.readout;
  if (!pilot) return;
  const NoiseModel m =
      calibrated(m0, s.pilot, s.pilot_runs, {s.octave_m, s.ref.grid, true, {}}, dclean, s.opt->progress);
  x.model.arw_deg_per_sqrt_h = m.arw_deg_per_sqrt_h;
  x.model.bias_instability_deg_per_h = m.bias_instability_deg_per_h;
  x.model.rrw_deg_per_h_per_sqrt_h = m.rrw_deg_per_h_per_sqrt_h;
  x.model.ramp_deg_per_h2 = m.ramp_deg_per_h2;
}

}  // namespace

/// Deterministic terms are estimated and removed first; a mid-τ effect is fitted last, with N, B, K.
Extension extend(const Stretch& s, const std::vector<const Detector*>& named) {
  Extension x;
  bool stochastic = false;
  for (const Detector* d : named) {
    if (d->mid_tau())
      stochastic = true;
    else
      d->estimate(s, x);
  }
  x.model = with_named_terms(s, x);
  x.mid_var = mid_var_without(s, x.det);
  const bool deterministic = !x.det.sinusoids.empty() || !x.det.bias_steps.empty() || !x.det.warmups.empty();
  const bool self_pilot = !stochastic && deterministic && s.pilot_runs > 0;
  if (!stochastic && !x.findings.empty() && !self_pilot) {
    // Like the base calibration: data and ensemble records without their candidates.
    correct_nbk(x.model, power_law_corrections(x.mid_var, s.clean_ref, c_of(s.base)));
  }
  if (deterministic && !x.lowpass && (self_pilot || !x.det.sinusoids.empty())) refit_without_named(s, x, self_pilot);
  if (x.ramp) {
    // A named drift's linear part is the rate ramp R, estimated with the exponential (signed, as
    // the simulator's deterministic ramp); the mean rate over the record is kept (the bias, like
    // the base's, is the mean rate without any ramp: the ramp adds r·T/2 to it).
    x.model.bias_deg_per_h -= *x.ramp * s.rec->phase.duration_s() / 3600.0 / 2.0;
    x.model.ramp_deg_per_h2 = *x.ramp;
  }
  for (const Detector* d : named)
    if (d->mid_tau()) d->estimate(s, x);
  return x;
}

}  // namespace rwcalc::diag
