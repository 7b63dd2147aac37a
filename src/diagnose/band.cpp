// The bands of σ per τ from the models' theoretical AV and their misfit (band.hpp).
#include "band.hpp"

#include <algorithm>
#include <cmath>

#include "models.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/confidence.hpp"
#include "rwcalc/deviance.hpp"
#include "rwcalc/output_filter.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc::diag {

namespace {

/// A band point's weight in the misfit: its EDF with a 1000-EDF model floor.
double band_nu(double edf) { return 1.0 / (1.0 / edf + 1.0 / 1000.0); }

/// What a band computes the model's AV from, prepared once per band: the part theoretical_avar
/// gives (`rest`), and what is added to it. A pulse record's read-out (white angle, and a plain
/// counter's sawtooth, which depends on the record's mean rate) is the five-term fit's own,
/// FitResult::readout_var: the simulator's model of a counting read-out has no term for the sawtooth,
/// and a band without it missed the short-τ AV of a clean undithered record by up to 50 times. With
/// an output-chain low-pass, white angle and rate noise pass through the filter.
struct BandModel {
  NoiseModel rest;
  const NoiseModel& model;
  const FitResult& fit;
  bool pulses = false;
};

BandModel band_model(const NoiseModel& model, const FitResult& fit, bool pulses) {
  BandModel b{model, model, fit, pulses};
  if (pulses) {
    b.rest.white_angle_arcsec = 0;
    b.rest.readout = ReadoutMode::Counting;  // no read-out term of its own
  } else if (model.output_lowpass_tc_s > 0) {
    b.rest.arw_deg_per_sqrt_h = b.rest.white_angle_arcsec = 0;
  }
  return b;
}

/// The model's AV at cluster size m.
double model_avar(const BandModel& b, double tau0, double scale, std::size_t m) {
  const double rest = theoretical_avar(b.rest, tau0, scale, m);
  if (b.pulses) return rest + b.fit.readout_var(static_cast<double>(m) * tau0);
  const NoiseModel& model = b.model;
  if (!(model.output_lowpass_tc_s > 0)) return rest;
  const double n = model.arw_deg_per_sqrt_h * units::sqrt_s_per_sqrt_h, tf = model.output_lowpass_tc_s;
  return rest + n * n * output_lowpass_rate_avar(m, tau0, tf) +
         model.white_angle_arcsec * model.white_angle_arcsec * output_lowpass_angle_avar(m, tau0, tf);
}

/// The band of `model` at the measured points (σ per τ in `dev`): the model's σ times the χ²
/// quantiles of a variance with the point's EDF.
std::vector<BandPoint> model_band(const std::vector<AllanPoint>& pts, const std::vector<double>& dev,
                                  const NoiseModel& model, const FitResult& fit, const PhaseSeries& x, double scale,
                                  double level) {
  std::vector<BandPoint> band;
  const BandModel bm = band_model(model, fit, x.exact());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& p = pts[i];
    if (!(dev[i] > 0) || !(p.edf > 0)) continue;
    const double var = model_avar(bm, x.tau0_s, scale, static_cast<std::size_t>(p.m));
    const DevInterval ci = chi2_interval(1.0, p.edf, level);
    BandPoint b;
    b.tau_s = p.tau_s;
    b.dev = dev[i];
    b.edf = p.edf;
    b.mean_var = var;
    b.median = std::sqrt(var);
    b.low = b.median / ci.high;
    b.high = b.median / ci.low;
    band.push_back(b);
  }
  return band;
}

/// The model's noise only: its deterministic terms are taken from the data instead.
NoiseModel noise_only(NoiseModel m) {
  m.sinusoids.clear();
  m.bias_steps.clear();
  m.warmups.clear();
  return m;
}

}  // namespace

void bands(const PhaseSeries& x, DiagnoseResult& r) {
  const auto& pts = r.analysis.allan.points;
  std::vector<double> dev, dev_clean;
  for (const auto& p : pts) dev.push_back(p.dev);
  r.base_band = model_band(pts, dev, r.base, r.analysis.fit, x, r.settings.scale_arcsec, r.band_level);
  if (r.findings.empty()) {
    r.extended_band = r.base_band;
  } else {
    const PhaseSeries c = cleaned(x, r.extended);
    std::vector<double> var_clean(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) var_clean[i] = allan_variance(c, pts[i].m, Estimator::Overlapping);
    // A Gauss–Markov term or an output low-pass is noise the five terms cannot hold: that model
    // keeps the likelihood's levels (diagnose.cpp, extend).
    const bool noise_named = std::any_of(r.findings.begin(), r.findings.end(), [](const Finding& f) {
      return f.effect == Effect::GaussMarkov || f.effect == Effect::Lowpass;
    });
    const FitResult refit = noise_named ? r.analysis.fit : refit_noise(r.analysis, var_clean, r.extended);
    dev_clean.resize(var_clean.size());
    for (std::size_t i = 0; i < var_clean.size(); ++i) dev_clean[i] = std::sqrt(var_clean[i]);
    r.extended_band =
        model_band(pts, dev_clean, noise_only(r.extended), refit, x, r.settings.scale_arcsec, r.band_level);
  }
  r.gain.misfit_base = band_misfit(r.base_band);
  r.gain.misfit_extended = band_misfit(r.extended_band);
  r.gain.coverage_base = band_coverage(r.base_band);
  r.gain.coverage_extended = band_coverage(r.extended_band);
}

}  // namespace rwcalc::diag

namespace rwcalc {

double band_misfit(const std::vector<BandPoint>& band) {
  double sum = 0;
  std::size_t n = 0;
  for (const auto& b : band) {
    if (!(b.mean_var > 0 && b.dev > 0 && b.edf > 0)) continue;
    sum += gamma_deviance(b.dev * b.dev, b.mean_var, diag::band_nu(b.edf));
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

double band_coverage(const std::vector<BandPoint>& band) {
  if (band.empty()) return 0.0;
  std::size_t in = 0;
  for (const auto& b : band) in += (b.dev >= b.low && b.dev <= b.high) ? 1 : 0;
  return static_cast<double>(in) / static_cast<double>(band.size());
}

}  // namespace rwcalc
