// The diagnosis pipeline: base fit → ensemble band and detector calibration → findings →
// extended model → its band and the gain in and out of sample (render.cpp writes the results).
#include "rwcalc/diagnose.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>

#include "diagnose/models.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc {

using namespace diag;

namespace {

constexpr double kPulseFitTauMin = 20.0;       ///< s, start of the base fit for pulse data
constexpr std::size_t kCalibrationFactor = 4;  ///< default calibration ensemble: 4K records

/// Records of the pilot ensemble the base model is calibrated with: K/2, at least 10.
std::size_t pilot_records(const DiagnoseOptions& opt) { return std::max<std::size_t>(10, opt.runs / 2); }
/// Records of the base model's calibration ensemble (DiagnoseOptions::calibration_runs).
std::size_t calibration_records(const DiagnoseOptions& opt) {
  return std::max(opt.runs, opt.calibration_runs ? opt.calibration_runs : kCalibrationFactor * opt.runs);
}

/// The measurement and what every stage reads of it.
struct Context {
  const Recording& rec;
  const DiagnoseOptions& opt;
  AnalysisOptions aopt;            ///< the five-term fit's
  EnsemblePlan plan;               ///< octave sizes and mid-τ grid of the record
  Stretch full;                    ///< the whole record as a stretch
  std::vector<double> octave_var;  ///< measured octave AV
  RobustBase rb;                   ///< base model, own candidate, B of the fit without it
  std::vector<std::unique_ptr<Detector>> detectors;
  [[nodiscard]] RecordView view() const { return {rec.phase, full.dec, full.clean, octave_var}; }
};

/// Outliers are screened once, first: every stage sees the same data, and a spike cannot pass for
/// a bias step or inflate N.
const Recording& screened(const Recording& read, const DiagnoseOptions& opt, OutlierReport& outliers,
                          Recording& edited) {
  // An accelerometer's velocity (1/3600 m/s, units.hpp) takes the angle's place: the fit, the
  // simulator and the detectors read it as they read a gyro's angle; only the output's units differ.
  if (!sensor_kind(read.phase.kind))
    throw UsageError(
        tr("diagnose needs gyro or accelerometer data (clock phase/frequency cannot be simulated as a sensor)"));
  if (read.segments.size() > 1)
    throw UsageError(tr("diagnose needs one contiguous record: --gaps segments is for analyze, allan and imu"));
  if (opt.runs < 10) throw UsageError(trf("--runs must be at least 10 (got {})", opt.runs));
  const Recording& rec =
      screen_outliers(read, opt.analysis.outlier_action, opt.analysis.outlier_threshold, outliers, edited);
  const double T = rec.phase.duration_s();
  if (T < kMinDuration)
    throw AnalysisError(
        trf("{}: the record lasts {:.4g} s; the diagnosis needs at least {:g} s", rec.source, T, kMinDuration));
  return rec;
}

/// The five-term fit of the record and its base model. Pulse data: the counting read-out's
/// structured short-τ AV (simulated exactly) would distort the fit, which starts at 20 s.
void fit_base(Context& c, DiagnoseResult& r, OutlierReport outliers) {
  c.aopt = c.opt.analysis;
  c.aopt.outlier_action = OutlierAction::Keep;
  // The Earth-rate choice is the recording's (pulse input: on), kept for the cleaned and sliced
  // floating series the stages analyse.
  if (!c.aopt.earth_rate) c.aopt.earth_rate = c.rec.mode == InputMode::Pulses || c.rec.mode == InputMode::Counter;
  const PhaseSeries& x = c.rec.phase;
  if (x.exact() && c.aopt.fit.tau_min_s <= 0) c.aopt.fit.tau_min_s = kPulseFitTauMin;
  r.analysis = analyze_for_base(c.rec, c.aopt);
  r.analysis.outliers = std::move(outliers);
  r.settings.rate_hz = 1.0 / x.tau0_s;
  r.settings.duration_s = static_cast<double>(x.points() - 1) * x.tau0_s;
  r.settings.scale_arcsec = sim_scale(x, r.analysis);
  r.settings.seed = c.opt.seed;
  r.settings.temperature_c = r.analysis.temperature_c;
  for (const auto& p : r.analysis.allan.points) c.octave_var.push_back(p.var);
  Stretch& s = c.full;
  s.rec = &c.rec;
  s.analysis = &r.analysis;
  s.aopt = &c.aopt;
  s.opt = &c.opt;
  s.dec = decimate(x);
  s.octave_m = octave_of(r.analysis.allan);
  s.pilot = r.settings;
  s.pilot.seed = c.opt.seed + 1000;
  s.pilot_runs = pilot_records(c.opt);
  c.plan = {s.octave_m, mid_tau_grid(s.dec), true, {}};
  c.rb = robust_base(c.rec, r.analysis, c.aopt, s.dec, s.pilot, s.pilot_runs, c.plan, c.opt.progress);
  r.base = s.base = c.rb.model;
  s.clean = s.dec;
  subtract_deterministic(s.clean, c.rb.candidate);
  c.detectors = make_detectors(r.analysis, x, !x.exact() && on_lattice(x));
}

/// The record detectors, or those of them that change the mean.
std::vector<const RecordDetector*> record_detectors(const Context& c, bool mean_shape_only) {
  std::vector<const RecordDetector*> out;
  for (const auto& d : c.detectors)
    if (const auto* rd = dynamic_cast<const RecordDetector*>(d.get()); rd && (!mean_shape_only || rd->mean_shape()))
      out.push_back(rd);
  return out;
}

/// The base model's ensemble: every record's detector statistics (calibration_runs records, the
/// nulls being cheap: a threshold from a larger ensemble scatters less from seed to seed); its
/// first K records give the band and the mid-τ references.
std::vector<RunStats> base_ensemble(Context& c, DiagnoseResult& r) {
  EnsemblePlan plan = c.plan;
  plan.scored = record_detectors(c, false);
  plan.stats_from = c.opt.runs;
  auto runs = run_ensemble(r.base, r.settings, r.calibration_runs, plan, c.opt.progress);
  const std::vector<RunStats> band_runs(runs.begin(), runs.begin() + static_cast<std::ptrdiff_t>(c.opt.runs));
  r.base_band = make_band(r.analysis.allan.points, band_runs, c.opt.band_level);
  c.full.ref = make_reference(c.plan.grid, c.full.dec.tau_d, band_runs);
  c.full.clean_ref = make_reference(c.plan.grid, c.full.dec.tau_d, band_runs, true);
  return runs;
}

/// When the fit does not resolve B, the calibrated B may be far below the record's, and beside
/// such a quiet model the record's flicker wander looks like a step or a transient: the
/// mean-shape thresholds are also taken under B at its upper bound (same seeds), the larger kept.
void recalibrate_under_high_b(const Context& c, const DiagnoseResult& r, std::vector<DetectorResult>& results) {
  const Coefficient& b = c.rb.b_fit;
  if (!(b.enabled && !b.resolved && b.high > r.base.bias_instability_deg_per_h)) return;
  NoiseModel hi = r.base;
  hi.bias_instability_deg_per_h = b.high;
  EnsemblePlan plan{c.plan.octave_m, {}, false, record_detectors(c, true), false};
  const auto hi_runs = run_ensemble(hi, r.settings, r.calibration_runs, plan, c.opt.progress);
  for (const RecordDetector* d : plan.scored)
    for (auto& res : results)
      if (res.effect == d->effect()) {
        const DetectorResult h = d->calibrate(res.statistic, hi_runs, c.opt.alpha);
        if (h.threshold > res.threshold) res = h;
      }
}

/// A step and a transient are two forms of one change of the mean: the detectors decide that
/// there is one (either is named), the residual sum of squares of the block means decides its
/// form (the record's own candidate). Left to the two thresholds, whose scatter from seed to seed
/// is large when the base has rate random walk, the form changed with the seed.
void one_mean_shape(const NoiseModel& candidate, std::vector<DetectorResult>& results) {
  auto of = [&](Effect e) {
    return std::find_if(results.begin(), results.end(), [e](auto& d) { return d.effect == e; });
  };
  const auto step = of(Effect::BiasStep), warm = of(Effect::Warmup);
  if (step == results.end() || warm == results.end() || !(step->named || warm->named)) return;
  const bool warmup_form = !candidate.warmups.empty();
  auto& keep = warmup_form ? *warm : *step;
  auto& drop = warmup_form ? *step : *warm;
  if (!keep.named) {
    keep.named = true;
    keep.note =
        trf("named as the form of the change of the mean the {} detector found: it explains the "
            "block means better",
            detector_name(drop.effect));
  }
  if (drop.named) {
    drop.named = false;
    drop.note = trf("the {} explains the block means better", warmup_form ? tr("warm-up transient") : tr("bias step"));
  }
}

bool is_named(const std::vector<DetectorResult>& results, Effect e) {
  return std::any_of(results.begin(), results.end(), [e](const auto& d) { return d.effect == e && d.named; });
}

/// The base the mid-τ detectors test against. A base calibrated with a named line in the data
/// takes the line's Allan variance into N or B, and beside it the data without the line shows a
/// deficit that a bump fit mistakes for a Gauss–Markov term: with a named line, the base is
/// re-calibrated (pilot seeds as before) on the data without it, and its ensemble taken.
struct MidTauBase {
  Stretch stretch;
  std::optional<std::vector<RunStats>> runs;  ///< empty: the base ensemble's
};
MidTauBase mid_tau_base(const Context& c, const DiagnoseResult& r, const NoiseModel& det, const Decimated& dclean,
                        const std::vector<RunStats>& runs) {
  MidTauBase m{c.full, std::nullopt};
  if (det.sinusoids.empty()) return m;
  m.stretch.base = calibrated(c.rb.model, c.full.pilot, c.full.pilot_runs, c.plan, dclean, c.opt.progress);
  EnsemblePlan plan = c.plan;
  plan.scored.clear();
  m.runs = run_ensemble(m.stretch.base, r.settings, runs.size(), plan, c.opt.progress);
  m.stretch.ref = make_reference(c.plan.grid, c.full.dec.tau_d, *m.runs);
  m.stretch.clean_ref = make_reference(c.plan.grid, c.full.dec.tau_d, *m.runs, true);
  return m;
}

/// Every detector's verdict (r.detectors) and the named effects. The mid-τ detectors read the
/// measurement without its candidate and without the named lines, so they run last.
Named test_detectors(Context& c, const std::vector<RunStats>& cal_runs, DiagnoseResult& r) {
  std::vector<DetectorResult> res(c.detectors.size());
  const Trial trial{c.view(), cal_runs, c.full, r.settings, nullptr};
  // The mid-τ detectors compare with the band's records (their references' own).
  const std::vector<RunStats> runs(cal_runs.begin(), cal_runs.begin() + static_cast<std::ptrdiff_t>(c.opt.runs));
  for (std::size_t i = 0; i < c.detectors.size(); ++i) {
    res[i].effect = c.detectors[i]->effect();
    if (!c.detectors[i]->mid_tau()) res[i] = c.detectors[i]->test(trial);
  }
  recalibrate_under_high_b(c, r, res);
  one_mean_shape(c.rb.candidate, res);
  Named named;
  NoiseModel det = c.rb.candidate;
  if (is_named(res, Effect::Sinusoid)) {
    const auto sin = sinusoid_detect(c.full.clean, 0, true, &c.full.dec, &c.rb.candidate);
    det.sinusoids.push_back({sin.f_hz, sin.amp, sin.phase});
    named.sin_hint_hz = sin.f_hz;
  }
  if (is_named(res, Effect::Line)) {
    const auto line = line_detect(c.rec.phase);
    if (line.coherent) {
      named.line_hint_hz = line.f_hz;
      det.sinusoids.push_back({line.f_hz, line.amp, line.phase});
    }
  }
  Decimated dclean = c.full.dec;
  subtract_deterministic(dclean, det);
  const auto mid_var = decimated_avar(dclean, c.plan.grid);
  const MidTauBase mid = mid_tau_base(c, r, det, dclean, runs);
  const Trial mid_trial{c.view(), mid.runs ? *mid.runs : runs, mid.stretch, r.settings, &mid_var};
  for (std::size_t i = 0; i < c.detectors.size(); ++i)
    if (c.detectors[i]->mid_tau()) res[i] = c.detectors[i]->test(mid_trial);
  for (std::size_t e = 0; e < kEffectCount; ++e)
    for (std::size_t i = 0; i < c.detectors.size(); ++i)
      if (static_cast<std::size_t>(res[i].effect) == e && res[i].named) named.detectors.push_back(c.detectors[i].get());
  r.detectors = std::move(res);
  return named;
}

/// A finding's evidence: its detector's verdict, and what the estimate added.
void add_evidence(Finding& f, const DiagnoseResult& r) {
  const auto& d = *std::find_if(r.detectors.begin(), r.detectors.end(),
                                [&](const DetectorResult& dd) { return dd.effect == f.effect; });
  const nlohmann::json extra = f.evidence;
  f.evidence = {{"statistic", d.statistic},
                {"threshold", d.threshold},
                {"ensemble_max", d.ensemble_max},
                {"ensemble_median", d.ensemble_median},
                {"false_alarm_level", r.alpha}};
  f.evidence["detector"] = std::string(detector_description(f.effect));
  if (f.effect == Effect::Line) {
    f.evidence["search_band_hz"] = {kHighLineMinHz, 0.5 * r.settings.rate_hz};
    for (const auto& [k, v] : extra.items()) f.evidence[k] = v;
  }
}

/// The extended model of the whole record, its findings and its band. Its ensemble reuses the
/// base's seeds, so the bands differ by the model, not by sampling noise; N and B are then
/// re-fitted to the whole band (the extension was calibrated at mid τ only).
void extended_model(Context& c, const Named& named, DiagnoseResult& r) {
  c.full.sin_hint_hz = named.sin_hint_hz;
  Extension ext = extend(c.full, named.detectors);
  r.extended = ext.model;
  for (auto& f : ext.findings) {
    add_evidence(f, r);
    r.findings.push_back(std::move(f));
  }
  if (r.findings.empty()) {
    r.extended_band = r.base_band;
    return;
  }
  const auto ext_runs =
      run_ensemble(r.extended, r.settings, c.opt.runs, {c.plan.octave_m, {}, false, {}, false}, c.opt.progress);
  r.extended_band = make_band(r.analysis.allan.points, ext_runs, c.opt.band_level);
  refit_whole_band(r.extended, r.extended_band, r.analysis.allan.points, r.settings, c.opt.runs, c.plan, c.opt);
}

/// A finding must predict: when the extended model does not predict the held-out blocks better
/// than the base, its terms are reported as failed candidates with their figures, the detectors'
/// statistics as an excess, and the base stays the model.
void reject_findings(DiagnoseResult& r) {
  const std::string why = fmt::format(
      "excess, not named: the model with it predicts the held-out blocks no better than the base (out-of-sample "
      "misfit {:.4g} against {:.4g})",
      r.gain.holdout_misfit_extended, r.gain.holdout_misfit_base);
  for (auto& f : r.findings) {
    f.evidence["holdout_misfit_base"] = r.gain.holdout_misfit_base;
    f.evidence["holdout_misfit_extended"] = r.gain.holdout_misfit_extended;
    for (auto& d : r.detectors)
      if (d.effect == f.effect && d.named) {
        d.named = false;
        d.excess = true;
        d.note = why;
      }
  }
  r.rejected = std::move(r.findings);
  r.findings.clear();
  r.extended = r.base;
  r.extended_band = r.base_band;
  r.gain.misfit_extended = r.gain.misfit_base;
  r.gain.coverage_extended = r.gain.coverage_base;
}

}  // namespace

std::uint64_t simulated_records(const DiagnoseOptions& opt) { return pilot_records(opt) + calibration_records(opt); }

DiagnoseResult diagnose(const Recording& read, const DiagnoseOptions& opt) {
  const auto t_start = std::chrono::steady_clock::now();
  OutlierReport outliers;
  Recording edited;
  Context c{screened(read, opt, outliers, edited), opt, {}, {}, {}, {}, {}, {}};
  DiagnoseResult r;
  r.runs = opt.runs;
  r.holdout_runs = opt.holdout_runs ? opt.holdout_runs : 2 * opt.runs;
  r.calibration_runs = calibration_records(opt);
  r.seed = opt.seed;
  r.band_level = opt.band_level;
  r.alpha = opt.alpha;
  fit_base(c, r, std::move(outliers));
  const auto base_runs = base_ensemble(c, r);
  const Named named = test_detectors(c, base_runs, r);
  extended_model(c, named, r);
  r.gain.misfit_base = band_misfit(r.base_band, opt.runs);
  r.gain.misfit_extended = band_misfit(r.extended_band, opt.runs);
  r.gain.coverage_base = band_coverage(r.base_band);
  r.gain.coverage_extended = band_coverage(r.extended_band);
  if (r.findings.empty()) {  // nothing to predict: the base is the extended model
    r.gain.holdout_misfit_base = r.gain.holdout_misfit_extended = std::numeric_limits<double>::quiet_NaN();
  } else {
    const HoldoutScores h = out_of_sample(c.full, r, named);
    r.gain.holdout_misfit_base = h.base;
    r.gain.holdout_misfit_extended = h.extended;
    if (!(h.extended < h.base)) reject_findings(r);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

}  // namespace rwcalc
