// The out-of-sample check: the record is cut into halves and (when each lasts kMinDuration)
// thirds; a fold fits both models on one block and scores their prediction of a neighbour. The
// score is averaged over the splits: one alone leaves the verdict to where its cut falls.
#include "diagnose/models.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "diagnose/models.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc::diag {

namespace {

constexpr double kStepMinSide = 60.0;  ///< s of a block on each side of a known step to estimate its size

struct Fold {
  std::size_t len, fit, pred;  ///< block length (samples), fitting and predicted block
  double weight;               ///< of the fold's per-point score in the mean
};

std::vector<Fold> holdout_folds(std::size_t n, double tau0) {
  const std::vector<std::size_t> splits = static_cast<double>(n) * tau0 >= 3.0 * kMinDuration
                                              ? std::vector<std::size_t>{2, 3}
                                              : std::vector<std::size_t>{2};
  std::vector<Fold> folds;
  for (const std::size_t nb : splits) {
    const double w = 1.0 / (static_cast<double>(splits.size()) * 2.0 * static_cast<double>(nb - 1));
    for (std::size_t k = 0; k < nb; ++k) {
      if (k + 1 < nb) folds.push_back({n / nb, k, k + 1, w});
      if (k > 0) folds.push_back({n / nb, k, k - 1, w});
    }
  }
  return folds;
}

/// The level a model predicts over [0, T], °/h (a ramp, whose sign the AV does not give, none).
double model_level(const NoiseModel& m, double T) {
  return m.earth_rate_deg_per_h + m.bias_deg_per_h + mean_rate_of(m, T);
}

/// The model with its mean rate over [0, T] (the ramp included) set to `mean_rate`.
NoiseModel with_mean_rate(NoiseModel m, double T, double mean_rate) {
  m.bias_deg_per_h += mean_rate - (model_level(m, T) + m.ramp_deg_per_h2 * T / units::seconds_per_hour / 2.0);
  return m;
}

/// The model from t = dt on: steps before it join the constant rate, transients decay.
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

double mean_rate_variance(const std::vector<RunStats>& runs) {
  if (runs.size() < 2) return 0.0;
  double s = 0, s2 = 0;
  for (const auto& r : runs) s += r.mean_rate;
  const double mu = s / static_cast<double>(runs.size());
  for (const auto& r : runs) s2 += (r.mean_rate - mu) * (r.mean_rate - mu);
  return s2 / static_cast<double>(runs.size() - 1);
}

/// A named line predicts its frequency and phase, which the Allan variance hardly sees: its two
/// Fourier coefficients on the predicted block are scored, −2 ln L = |c − c_model|²/σ² (the base
/// predicts c = 0). A broadened line (no phase) is left to the band.
void score_lines(const PhaseSeries& pred, const NoiseModel& e_pred, const std::vector<Sinusoid>& broad,
                 BandDeviance& sb, BandDeviance& se) {
  for (const auto& l : e_pred.sinusoids) {
    if (std::any_of(broad.begin(), broad.end(), [&](const Sinusoid& b) { return b.f_hz == l.f_hz; })) continue;
    std::vector<double> y;
    double tb = 0;
    if (l.f_hz < kHighLineMinHz) {
      const Decimated dp = decimate(pred);
      const auto per = per_block_for(dp, 0.5);
      y = block_rates(dp, per);
      tb = static_cast<double>(per) * dp.tau_d;
    } else {
      tb = pred.tau0_s;
      y.resize(pred.points() - 1);
      for (std::size_t i = 0; i + 1 < pred.points(); ++i) y[i] = pred.diff(i + 1, i) / tb;
    }
    const std::size_t ny = y.size();
    const LineCoefficients c = line_coefficients(std::move(y), tb, l.f_hz);
    if (!(c.sigma > 0)) continue;
    const double att = block_attenuation(l.f_hz, tb);
    // Behind a named output-chain low-pass the block shows the sensed line through the filter.
    const std::complex<double> hf =
        e_pred.output_lowpass_tc_s > 0 ? lowpass_response(l.f_hz, pred.tau0_s, e_pred.output_lowpass_tc_s) : 1.0;
    const double am = l.amp_deg_per_h * std::abs(hf) * att, ph = l.phase_rad + std::arg(hf);
    double ap = am * std::cos(ph), bp = -am * std::sin(ph);
    if (l.f_hz < kHighLineMinHz) {
      // The block's coefficients are fitted after its level and trend are taken out, which takes
      // a share of a line of a few cycles: the model's line is put through the same fit.
      std::vector<double> ym(ny);
      for (std::size_t i = 0; i < ym.size(); ++i)
        ym[i] = am * std::cos(2.0 * kPi * l.f_hz * (static_cast<double>(i) + 0.5) * tb + ph);
      const LineCoefficients cm = line_coefficients(std::move(ym), tb, l.f_hz);
      ap = cm.a;
      bp = cm.b;
    }
    const double s2 = c.sigma * c.sigma;
    sb.sum += (c.a * c.a + c.b * c.b) / s2;
    se.sum += ((c.a - ap) * (c.a - ap) + (c.b - bp) * (c.b - bp)) / s2;
    sb.points += 2;
    se.points += 2;
  }
}

/// A block's pilot ensembles (of its base and of its extended model alike, same seeds), as the
/// whole record's, have half the runs.
std::size_t block_pilot_runs(const DiagnoseResult& r) { return r.holdout_runs; }

/// The block's base is calibrated without the block's own step or transient already: a named
/// mean shape changes the level the model predicts, and its re-calibrated N and B would only add
/// the pilot's scatter to the comparison. Its extended model keeps the base's power laws.
void keep_power_laws(const NoiseModel& base, NoiseModel& m) {
  m.arw_deg_per_sqrt_h = base.arw_deg_per_sqrt_h;
  m.bias_instability_deg_per_h = base.bias_instability_deg_per_h;
  m.rrw_deg_per_h_per_sqrt_h = base.rrw_deg_per_h_per_sqrt_h;
  m.ramp_deg_per_h2 = base.ramp_deg_per_h2;
}

/// The fitting block as a stretch with its base model, pilot settings and hints.
Stretch fitting_stretch(const Stretch& full, const DiagnoseResult& r, const Named& named, const Recording& fit_rec,
                        const AnalysisResult& a_fit, const SimulationSettings& pilot, double t_fit) {
  Stretch st;
  st.rec = &fit_rec;
  st.analysis = &a_fit;
  st.aopt = full.aopt;
  st.opt = full.opt;
  st.dec = decimate(fit_rec.phase);
  st.pilot = pilot;
  st.pilot_runs = block_pilot_runs(r);
  st.sin_hint_hz = named.sin_hint_hz;
  st.line_hint_hz = named.line_hint_hz;
  // A named Gauss–Markov term keeps the whole record's correlation time (its structure).
  st.gm_tc_s = r.extended.gauss_markov.empty() ? 0.0 : r.extended.gauss_markov.front().tc_s;
  // So does a transient or drift: half the record cannot place a time constant of up to T/3.
  st.warmup_tc_s = r.extended.warmups.empty() ? 0.0 : r.extended.warmups.front().tc_s;
  // A step whose time lies inside the fitting block, with data on each side, keeps that time.
  if (!r.extended.bias_steps.empty()) {
    const double t_local = r.extended.bias_steps.front().t_s - t_fit;
    if (t_local >= kStepMinSide && t_local <= fit_rec.phase.duration_s() - kStepMinSide) st.step_time_s = t_local;
  }
  return st;
}

/// One fold's per-point scores of the base and the extended model. Both are simulated at the
/// predicted block's measured mean rate (under a counting read-out the rate sets the short-τ AV);
/// the level each predicts is scored once, against the base ensemble's spread of block means.
std::pair<double, double> score_fold(const Stretch& full, const DiagnoseResult& r, const Named& named, const Fold& f,
                                     std::size_t index) {
  const PhaseSeries& x = full.rec->phase;
  const DiagnoseOptions& opt = *full.opt;
  const std::size_t h = f.len, fa = f.fit * h, pa = f.pred * h;
  const Recording fit_rec = with_series(*full.rec, slice(x, fa, fa + h));
  const Recording pred_rec = with_series(*full.rec, slice(x, pa, pa + h));
  const AnalysisResult a_fit = analyze_for_base(fit_rec, *full.aopt);
  const AllanResult a_pred = compute_allan(pred_rec.phase, opt.analysis.allan);
  SimulationSettings sh = r.settings;
  sh.duration_s = static_cast<double>(h) * x.tau0_s;
  sh.seed = opt.seed + 10 + static_cast<std::uint64_t>(index);
  Stretch st = fitting_stretch(full, r, named, fit_rec, a_fit, sh, static_cast<double>(fa) * x.tau0_s);
  st.octave_m = octave_of(a_pred);
  EnsemblePlan plan{st.octave_m, mid_tau_grid(st.dec), true, {}};
  st.base = robust_base(fit_rec, a_fit, *full.aopt, st.dec, sh, block_pilot_runs(r), plan, opt.progress).model;
  sh.seed += 50;
  const double pred_T = pred_rec.phase.duration_s();
  const double pred_mean = pred_rec.phase.diff(pred_rec.phase.points() - 1, 0) / pred_T;
  const EnsemblePlan pred_plan{plan.octave_m, {}, false, {}, false};
  const auto b_pred =
      run_ensemble(with_mean_rate(st.base, pred_T, pred_mean), sh, r.holdout_runs, pred_plan, opt.progress);
  const double v_base = std::max(mean_rate_variance(b_pred), 1e-30);
  auto prediction_score = [&](const std::vector<RunStats>& runs, const NoiseModel& m, double ramp_level = 0) {
    const auto dev = band_deviance(make_band(a_pred.points, runs, opt.band_level), r.holdout_runs);
    const double d = pred_mean - model_level(m, pred_T) - ramp_level;
    return BandDeviance{dev.sum + d * d / v_base, dev.points + 1};
  };
  BandDeviance sb = prediction_score(b_pred, st.base);
  if (named.detectors.empty()) return {sb.per_point(), sb.per_point()};
  // An effect enters the block's extended model only when the block shows it.
  for (const Detector* d : named.detectors)
    if (const auto* rd = dynamic_cast<const RecordDetector*>(d); rd && rd->block_statistic()) plan.scored.push_back(rd);
  const auto b_runs = run_ensemble(st.base, sh, r.holdout_runs, plan, opt.progress);
  st.ref = make_reference(plan.grid, st.dec.tau_d, b_runs);
  st.clean_ref = make_reference(plan.grid, st.dec.tau_d, b_runs, true);
  st.clean = without_own_candidates(st.dec);
  const std::vector<double> no_octave;
  const Trial trial{{fit_rec.phase, st.dec, st.clean, no_octave}, b_runs, st, sh, nullptr};
  std::vector<const Detector*> shown;
  for (const Detector* d : named.detectors)
    if (d->shows_in(trial)) shown.push_back(d);
  if (shown.empty()) return {sb.per_point(), sb.per_point()};
  Extension e = extend(st, shown);
  if (std::all_of(shown.begin(), shown.end(), [](const Detector* d) { return d->mean_shape(); }))
    keep_power_laws(st.base, e.model);
  const double dt = (static_cast<double>(pa) - static_cast<double>(fa)) * x.tau0_s;
  NoiseModel e_pred = shifted(e.model, dt);
  double ramp_level = 0;
  if (e.ramp) {
    // A named drift's signed ramp carries the level to the predicted block, shrunk by how well
    // the block determines it, r²/(r² + σ_r²): beside an exponential whose time constant is near
    // the block's length the trend is loose, and its extrapolation over a block missed the level
    // by far more than the rate's wander (out of sample 63.6 → 2237 on one drift).
    const double ramp = *e.ramp, s2 = e.ramp_sigma * e.ramp_sigma;
    const double r_eff = ramp * ramp * ramp / std::max(ramp * ramp + s2, 1e-300);
    e_pred.bias_deg_per_h += ramp * fit_rec.phase.duration_s() / 3600.0 / 2.0;  // the ramp's own share
    e_pred.ramp_deg_per_h2 = r_eff;
    e_pred.bias_deg_per_h += r_eff * (dt - fit_rec.phase.duration_s() / 2.0) / 3600.0;
    ramp_level = r_eff * pred_T / 3600.0 / 2.0;
  }
  const auto e_runs =
      run_ensemble(with_mean_rate(e_pred, pred_T, pred_mean), sh, r.holdout_runs, pred_plan, opt.progress);
  BandDeviance se = prediction_score(e_runs, e_pred, ramp_level);
  score_lines(pred_rec.phase, e_pred, e.broad, sb, se);
  return {sb.per_point(), se.per_point()};
}

}  // namespace

HoldoutScores out_of_sample(const Stretch& full, const DiagnoseResult& r, const Named& named) {
  const PhaseSeries& x = full.rec->phase;
  const auto folds = holdout_folds(x.points() - 1, x.tau0_s);
  // The folds run side by side (each fold's ensembles then run on its thread): their fits and
  // Allan variances of the measured blocks are otherwise serial. Summed in fold order.
  std::vector<std::pair<double, double>> scores(folds.size());
  parallel_for(folds.size(), [&](std::size_t i) { scores[i] = score_fold(full, r, named, folds[i], i); });
  HoldoutScores s;
  for (std::size_t i = 0; i < folds.size(); ++i) {
    s.base += folds[i].weight * scores[i].first;
    s.extended += folds[i].weight * scores[i].second;
  }
  return s;
}

}  // namespace rwcalc::diag

