// The diagnosis pipeline: base fit → block means → forward selection of effects by likelihood
// ratios (effects.cpp) → estimates with profile intervals → extended model, its band and gain
// (band.cpp); render.cpp writes the results. No decision reads a random number.
#include "rwcalc/diagnose.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "band.hpp"
#include "effects.hpp"
#include "fast_line.hpp"
#include "gain.hpp"
#include "lowpass.hpp"
#include "models.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/segments.hpp"
#include "rwcalc/units.hpp"
#include "signal.hpp"

namespace rwcalc {

using namespace diag;

namespace {

constexpr double kBlockSeconds = 10.0;    ///< block length of the likelihood, s (longer for long records)
constexpr std::size_t kMaxBlocks = 1000;  ///< the likelihood's cost grows as blocks²
constexpr double kSlowCycles = 12.0;      ///< the slow-line band ends at 12 cycles per record

/// Outliers are screened once, first: every stage sees the same data, and a spike cannot pass for
/// a bias step or inflate N.
const Recording& screened(const Recording& read, const DiagnoseOptions& opt, OutlierReport& outliers,
                          Recording& edited) {
  // An accelerometer's velocity (1/3600 m/s, units.hpp) takes the angle's place: the fit and the
  // likelihood read it as they read a gyro's angle; only the output's units differ.
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

/// The five-term fit of the record and its base model, over the τ `analyze` fits: a pulse record's
/// read-out (a plain counter's sawtooth or white angle noise) is part of that fit's model.
void fit_base(const Recording& rec, const DiagnoseOptions& opt, DiagnoseResult& r, OutlierReport outliers) {
  AnalysisOptions aopt = opt.analysis;
  aopt.outlier_action = OutlierAction::Keep;
  if (!aopt.earth_rate) aopt.earth_rate = rec.mode == InputMode::Pulses || rec.mode == InputMode::Counter;
  const PhaseSeries& x = rec.phase;
  r.analysis = analyze_for_base(rec, aopt);
  r.analysis.outliers = std::move(outliers);
  r.settings.rate_hz = 1.0 / x.tau0_s;
  r.settings.duration_s = static_cast<double>(x.points() - 1) * x.tau0_s;
  r.settings.scale_arcsec = sim_scale(x, r.analysis);
  r.settings.seed = opt.seed;
  r.settings.temperature_c = r.analysis.temperature_c;
  r.base = base_model(r.analysis, x);
}

/// The block means the likelihood reads: 10-s blocks, longer when the record has more than 1000.
Blocks make_blocks(const PhaseSeries& x) {
  const Decimated d = decimate(x);
  const double seconds = std::max(kBlockSeconds, d.duration() / static_cast<double>(kMaxBlocks));
  const std::size_t per = per_block_for(d, seconds);
  Blocks b;
  b.tb = static_cast<double>(per) * d.tau_d;
  b.y = block_rates(d, per);
  b.z = second_differences(b.y);
  return b;
}

/// Blocks either side of a block whose mean rate gives the counter's local advance: the line or
/// bias wander that moves it (a slow line of 3.5 flicker floors by ±0.13 pulse a block on GL-2D-like
/// records) stays, the block means' own noise (≈ 0.45 pulse) averages to ≈ 0.06.
constexpr std::size_t kAdvanceHalfWindow = 30;

/// The angle error at the block edges: a plain counter's sawtooth, of variance q²/12 (known, not
/// profiled), correlated across blocks by its phase's advance (the local mean rate) and spread by
/// the base model's white rate and white angle over a block (the AV fit resolves N; the blocks
/// alone trade it against Q). Taken as white (Q), its correlation was named a Gauss–Markov term of
/// Tc 20–33 s beside 2 of 20 slow lines; with its level free, it took a line.
std::optional<CovTerm> counter_term(const NoiseModel& base, double q_arcsec, const Blocks& b) {
  const std::size_t nb = b.y.size();
  if (!(q_arcsec > 0) || base.readout != ReadoutMode::Counting || nb == 0) return std::nullopt;
  std::vector<double> prefix(nb + 1, 0.0);  // °/h, that is ″/s
  for (std::size_t k = 0; k < nb; ++k) prefix[k + 1] = prefix[k] + b.y[k];
  std::vector<double> advance(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    const std::size_t lo = k > kAdvanceHalfWindow ? k - kAdvanceHalfWindow : 0;
    const std::size_t hi = std::min(nb, k + kAdvanceHalfWindow + 1);
    const double pulses = std::abs(prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo) * b.tb / q_arcsec;
    advance[k] = pulses - std::floor(pulses);
  }
  const double n = base.arw_deg_per_sqrt_h * units::sqrt_s_per_sqrt_h;  // ″/√s
  const double spread =
      (n * n * b.tb + 2.0 * base.white_angle_arcsec * base.white_angle_arcsec) / (q_arcsec * q_arcsec);
  CovTerm t{CovKind::Counter};
  t.correlation = std::make_shared<const std::vector<double>>(counter_correlation(advance, spread, b.n() + 3));
  t.known_level = q_arcsec * q_arcsec / 12.0;
  return t;
}

/// The base model's levels in the likelihood's units (gls.hpp), each at least a small share of the
/// largest so that its logarithm can start.
std::vector<double> start_levels(const NoiseModel& m, double q_arcsec, const Blocks& b,
                                 const std::vector<CovTerm>& terms) {
  const double n = m.arw_deg_per_sqrt_h * units::sqrt_s_per_sqrt_h;
  const double k = m.rrw_deg_per_h_per_sqrt_h / units::sqrt_s_per_sqrt_h;
  std::vector<double> lv = {m.white_angle_arcsec * m.white_angle_arcsec + q_arcsec * q_arcsec / 12.0, n * n,
                            kFlickerFloorPerB2 * m.bias_instability_deg_per_h * m.bias_instability_deg_per_h,
                            k * k / 3.0};
  double top = 0;
  std::vector<double> share(lv.size());
  for (std::size_t t = 0; t < lv.size(); ++t) {
    share[t] = term_autocov(terms[t], 1, b.tb)[0];
    top = std::max(top, lv[t] * share[t]);
  }
  for (std::size_t t = 0; t < lv.size(); ++t) lv[t] = std::max(lv[t], 1e-3 * top / share[t]);
  return lv;
}

/// The tests outside the block means: lines above their band on the periodogram, the output
/// low-pass on the short-τ AV. Pulse counts (whole, or as numbers on a lattice) get the periodogram
/// of the decimated angle up to 0.25 Hz only (the counting read-out's beat of the pulse rate against
/// the sampling makes lines above) and no low-pass test.
struct Outside {
  std::optional<FastLine> fast;
  std::string lowpass_skip;  ///< why the low-pass is not tested (empty: it is)
};

/// The rate samples of a record, τ0 apart.
std::vector<double> rates(const PhaseSeries& x) {
  std::vector<double> y(x.points() - 1);
  for (std::size_t k = 0; k < y.size(); ++k) y[k] = x.rate(k);
  return y;
}

/// The rate samples the periodogram reads, `dt` s apart: a pulse record's decimated angle
/// differenced, otherwise the rate per sample.
std::vector<double> periodogram_rates(const PhaseSeries& x, bool pulses, double& dt) {
  std::vector<double> y;
  if (pulses) {
    const Decimated d = decimate(x);
    dt = d.tau_d;
    for (std::size_t j = 0; j + 1 < d.theta.size(); ++j) y.push_back((d.theta[j + 1] - d.theta[j]) / dt);
  } else {
    dt = x.tau0_s;
    y = rates(x);
  }
  return y;
}

bool counts_pulses(const PhaseSeries& x) { return x.exact() || on_lattice(x); }

Outside outside_tests(const PhaseSeries& x, const Blocks& b, double alpha) {
  Outside o;
  const bool pulses = counts_pulses(x);
  const double f_min = 0.4 / b.tb;
  double dt = 0;
  std::vector<double> y = periodogram_rates(x, pulses, dt);
  const double f_max = pulses ? std::min(0.25, 0.49 / dt) : 0.49 / dt;
  if (f_max > 2 * f_min) o.fast = fast_line_search(std::move(y), dt, f_min, f_max, 0.5 * alpha);
  if (pulses) o.lowpass_skip = tr("not tested: pulse counts cannot have passed through an output-chain filter");
  return o;
}

/// The families and their searches against the current model.
Candidate search(Effect e, const Blocks& b, const GlsModel& cur, double alpha) {
  const double T = b.duration();
  switch (e) {
    case Effect::Sinusoid: return search_slow_line(b, cur, alpha, 2.5 / T, kSlowCycles / T, e);
    case Effect::Line: return search_slow_line(b, cur, 0.5 * alpha, kSlowCycles / T, 0.4 / b.tb, e);
    case Effect::BiasStep: return search_step(b, cur, alpha);
    case Effect::Warmup: return search_transient(b, cur, alpha);
    default: return search_gauss_markov(b, cur, alpha);
  }
}

DetectorResult verdict(const Candidate& c, bool named, double alpha) {
  DetectorResult d;
  d.effect = c.effect;
  d.statistic = c.lr;
  d.threshold = d.threshold_upper = c.threshold;
  d.p_value = c.p;
  d.test = c.test;
  d.fired = c.p <= alpha;
  d.named = named;
  return d;
}

/// The output low-pass, tested on the short-τ AV of the record less the named lines (a line's AV
/// bump would otherwise pass for a filter); named, its white noises before the filter replace the
/// extended model's N and white angle noise.
void test_lowpass(const PhaseSeries& x, const Outside& out, DiagnoseResult& r) {
  DetectorResult d;
  d.effect = Effect::Lowpass;
  if (!out.lowpass_skip.empty()) {
    d.note = out.lowpass_skip;
    r.detectors.push_back(d);
    return;
  }
  const PhaseSeries c = cleaned(x, r.extended);
  const bool clean = r.extended.sinusoids.empty() && r.extended.bias_steps.empty() && r.extended.warmups.empty();
  std::vector<std::int64_t> m;
  std::vector<double> v, edf;
  for (const auto& p : r.analysis.allan.points) {
    m.push_back(p.m);
    v.push_back(clean ? p.var : allan_variance(c, p.m, Estimator::Overlapping));
    edf.push_back(p.edf);
  }
  OutputLowpassEstimate lp = output_lowpass_detect(m, v, edf, x.tau0_s, x.duration_s(), r.alpha);
  if (lp.points < 5) {
    d.note = tr("not tested: fewer than 5 Allan points below 20 s");
    r.detectors.push_back(d);
    return;
  }
  d.statistic = lp.statistic;
  d.threshold = d.threshold_upper = lp.threshold;
  d.p_value = lp.p;
  d.test =
      "χ² drop of the short-τ Allan variance (τ ≤ min(20 s, T/100)) of the record less its named lines when white "
      "angle and rate noise pass through a first-order low-pass, scaled by the fit's χ²/dof; null law: χ²₁, "
      "Bonferroni over the octave points";
  d.fired = d.named = lp.p <= r.alpha;
  if (d.named && !output_lowpass_estimate(rates(c), m, v, edf, x.tau0_s, x.duration_s(), lp)) {
    d.named = false;
    d.note = tr("not named: the record is too short for the rate spectrum its time constant is read from");
  }
  r.detectors.push_back(d);
  if (!d.named) return;
  Finding f{Effect::Lowpass, {from_interval("time_constant", Quantity::Time, lp.tf, lp.tf_low, lp.tf_high)}, {}};
  f.evidence = {{"statistic", d.statistic},     {"threshold", d.threshold}, {"p_value", d.p_value},
                {"false_alarm_level", r.alpha}, {"detector", d.test},       {"spectrum_dispersion", lp.dispersion}};
  if (r.findings.empty()) r.extended = r.base;
  r.extended.output_lowpass_tc_s = lp.tf;
  r.extended.arw_deg_per_sqrt_h = std::sqrt(lp.white_rate) / units::sqrt_s_per_sqrt_h;
  r.extended.white_angle_arcsec = std::sqrt(lp.white_angle2);
  r.findings.push_back(std::move(f));
}

/// The line family above the slow band has two parts (block means, periodogram), each at α/2:
/// its p-value is twice the smaller one's.
void merge_fast(DetectorResult& d, const Candidate& c, const std::optional<FastLine>& fast, bool& fast_wins) {
  fast_wins = fast && fast->p < c.p;
  d.p_value = std::min(1.0, 2.0 * (fast_wins ? fast->p : c.p));
  if (fast_wins) {
    d.statistic = fast->statistic;
    d.threshold = d.threshold_upper = fast->threshold;
    d.test = fast->test;
  }
}

/// Two effects at once can each hide the other: a slow line and a step together raise the profiled
/// noise levels against which either alone is tested (a 0.06 °/h step beside a line at 5× the
/// flicker floor: p 0.023 and 0.072 alone). When no family fires, the two with the smallest p-values
/// (each within kPairScreen·α, fitted to the block means rather than found in the periodogram) are
/// searched each against the model holding the other's candidate; both are named when each is then
/// within α. Under the null the pair needs two conditional p-values within α, far rarer than one.
constexpr double kPairScreen = 10.0;

struct NamedPair {
  std::size_t first = 0, second = 0;
  Candidate first_given_second, second_given_first;
};

std::optional<NamedPair> pair_of(const std::vector<Effect>& families, const std::vector<Candidate>& cands,
                                 const std::vector<DetectorResult>& verdicts, const std::vector<bool>& usable,
                                 const Blocks& b, double alpha) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < families.size(); ++i)
    if (usable[i] && verdicts[i].p_value <= kPairScreen * alpha) order.push_back(i);
  if (order.size() < 2) return std::nullopt;
  std::partial_sort(order.begin(), order.begin() + 2, order.end(),
                    [&](std::size_t x, std::size_t y) { return verdicts[x].p_value < verdicts[y].p_value; });
  NamedPair pair{order[0], order[1], {}, {}};
  pair.second_given_first = search(families[pair.second], b, cands[pair.first].model, alpha);
  if (!(pair.second_given_first.p <= alpha)) return std::nullopt;
  pair.first_given_second = search(families[pair.first], b, cands[pair.second].model, alpha);
  if (!(pair.first_given_second.p <= alpha)) return std::nullopt;
  return pair;
}

/// Forward selection: every family searched against the current model, the one with the smallest
/// p-value bound named when that bound is within its false-alarm level, and the search repeated
/// against the model that includes it (or, when none fires, two named at once: pair_of); the
/// families' verdicts are their last ones. Returns the final model; `fast_named` tells whether the
/// line family was named from the periodogram.
GlsModel select_effects(const Blocks& b, GlsModel cur, const Outside& out, double alpha, DiagnoseResult& r,
                        bool& fast_named, Progress* progress) {
  const std::vector<Effect> families = {Effect::Sinusoid, Effect::Line, Effect::BiasStep, Effect::Warmup,
                                        Effect::GaussMarkov};
  std::vector<DetectorResult> verdicts(families.size());
  std::vector<bool> named(families.size(), false), fast(families.size(), false);
  std::vector<Candidate> cands(families.size());
  for (;;) {
    std::size_t best = families.size();
    for (std::size_t i = 0; i < families.size(); ++i) {
      if (named[i]) continue;
      cands[i] = search(families[i], b, cur, alpha);
      verdicts[i] = verdict(cands[i], false, alpha);
      if (families[i] == Effect::Line) {
        bool wins = false;
        merge_fast(verdicts[i], cands[i], out.fast, wins);
        fast[i] = wins;
      }
      verdicts[i].fired = verdicts[i].p_value <= alpha;
      if (verdicts[i].fired && (best == families.size() || verdicts[i].p_value < verdicts[best].p_value)) best = i;
    }
    if (progress) progress->advance();
    if (best == families.size()) {
      std::vector<bool> usable(families.size());
      for (std::size_t i = 0; i < families.size(); ++i) usable[i] = !named[i] && !fast[i];
      const std::optional<NamedPair> pair = pair_of(families, cands, verdicts, usable, b, alpha);
      if (!pair) break;
      for (const auto& [i, c, other] : {std::tuple{pair->first, pair->first_given_second, pair->second},
                                        std::tuple{pair->second, pair->second_given_first, pair->first}}) {
        named[i] = true;
        verdicts[i] = verdict(c, false, alpha);
        verdicts[i].fired = verdicts[i].named = true;
        verdicts[i].note =
            trf("named with the {}: each is significant given the other", detector_name(families[other]));
      }
      cur = pair->second_given_first.model;
      continue;
    }
    named[best] = true;
    verdicts[best].named = true;
    if (fast[best])
      fast_named = true;
    else
      cur = cands[best].model;
    for (std::size_t i = 0; i < families.size(); ++i)
      if (!named[i] && verdicts[i].fired)
        verdicts[i].note = trf("explained by the {} named before it", detector_name(families[best]));
  }
  r.detectors = verdicts;
  return cur;
}

/// The named terms as findings and as the extended model (N, B and K of the final profile).
void extend(const Blocks& b, const GlsModel& m, const Outside& out, bool fast_named, DiagnoseResult& r) {
  r.extended = r.base;
  if (fast_named) {
    const FastLine& l = *out.fast;
    Finding f{Effect::Line,
              {from_sigma("frequency", Quantity::Frequency, l.f_hz, l.f_sigma),
               from_sigma("amplitude", Quantity::Rate, l.amp, l.amp_sigma),
               {"phase", Quantity::Phase, l.phase}},
              {}};
    r.extended.sinusoids.push_back({l.f_hz, l.amp, l.phase});
    r.findings.push_back(std::move(f));
  }
  std::vector<TermEstimate> estimates = estimate_det(b, m);
  for (std::size_t j = 0; j < m.det.size(); ++j) {
    Finding f{m.det[j].effect, std::move(estimates[j].parameters), {}};
    const auto v = [&f](std::string_view name) { return f.parameter(name).value; };
    if (f.effect == Effect::BiasStep)
      r.extended.bias_steps.push_back({v("time"), v("size")});
    else if (f.effect == Effect::Warmup)
      r.extended.warmups.push_back({v("amplitude"), v("time_constant")});
    else
      r.extended.sinusoids.push_back({v("frequency"), v("amplitude"), v("phase")});
    r.findings.push_back(std::move(f));
  }
  for (std::size_t c = 0; c < m.cov.size(); ++c) {
    const double lv = m.fit.level[c];
    switch (m.cov[c].kind) {
      case CovKind::B: r.extended.bias_instability_deg_per_h = std::sqrt(lv / kFlickerFloorPerB2); break;
      case CovKind::K: r.extended.rrw_deg_per_h_per_sqrt_h = std::sqrt(3.0 * lv) * units::sqrt_s_per_sqrt_h; break;
      case CovKind::GM: {
        Finding f{Effect::GaussMarkov, estimate_gm(b, m, c).parameters, {}};
        r.extended.gauss_markov.push_back({f.parameter("sigma").value, f.parameter("correlation_time").value});
        r.findings.push_back(std::move(f));
        break;
      }
      default: break;
    }
  }
  if (r.findings.empty()) {  // nothing named: the base is the extended model
    r.extended = r.base;
    return;
  }
  std::stable_sort(r.findings.begin(), r.findings.end(),
                   [](const Finding& a, const Finding& c) { return a.effect < c.effect; });
  for (auto& f : r.findings)
    for (const auto& d : r.detectors)
      if (d.effect == f.effect) {
        f.evidence["statistic"] = d.statistic;
        f.evidence["threshold"] = d.threshold;
        f.evidence["p_value"] = d.p_value;
        f.evidence["false_alarm_level"] = r.alpha;
        f.evidence["detector"] = d.test;
      }
}

/// The low-pass out of sample (lowpass.hpp): the short-τ octave AV of each half of the record less
/// its named lines.
double lowpass_holdout(const PhaseSeries& c, const std::vector<AllanPoint>& pts) {
  const std::size_t n = c.points() / 2;
  const std::array<PhaseSeries, 2> half{phase_slice(c, 0, n - 1), phase_slice(c, n, c.points() - 1)};
  const double duration = half[0].duration_s(), tau_cut = std::min(20.0, duration / 100.0);
  std::vector<std::int64_t> m;
  std::array<std::vector<double>, 2> v;
  std::vector<double> edf;
  for (const auto& p : pts) {
    if (static_cast<double>(p.m) * c.tau0_s > tau_cut) continue;
    m.push_back(p.m);
    edf.push_back(0.5 * p.edf);
    for (std::size_t h = 0; h < 2; ++h) v[h].push_back(allan_variance(half[h], p.m, Estimator::Overlapping));
  }
  return output_lowpass_holdout(m, v, edf, c.tau0_s, duration);
}

/// The extended model's likelihood gain over every test that named a term: the block means' (gain.hpp),
/// the periodogram's for a line above their band, the short-τ Allan variance's for the low-pass.
void likelihood_gain(const PhaseSeries& x, const Blocks& b, const GlsModel& base, const GlsModel& extended,
                     const Outside& out, bool fast_named, DiagnoseResult& r) {
  if (r.findings.empty()) {
    r.gain.likelihood_in_sample = r.gain.likelihood_holdout = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  LikelihoodGain g;
  if (!extended.det.empty() || extended.cov.size() != base.cov.size()) g = block_gain(b, base, extended);
  if (fast_named) {
    double dt = 0;
    const std::vector<double> y = periodogram_rates(x, counts_pulses(x), dt);
    g.in_sample += out.fast->lr - 6.0;  // frequency, amplitude, phase
    g.holdout += fast_line_holdout(y, dt, *out.fast);
  }
  for (const auto& d : r.detectors)
    if (d.effect == Effect::Lowpass && d.named) {
      g.in_sample += d.statistic - 2.0;  // the time constant
      g.holdout += lowpass_holdout(cleaned(x, r.extended), r.analysis.allan.points);
    }
  r.gain.likelihood_in_sample = g.in_sample;
  r.gain.likelihood_holdout = g.holdout;
}

}  // namespace

DiagnoseResult diagnose(const Recording& read, const DiagnoseOptions& opt) {
  require_valid(opt);
  const auto t_start = std::chrono::steady_clock::now();
  OutlierReport outliers;
  Recording edited;
  const Recording& rec = screened(read, opt, outliers, edited);
  DiagnoseResult r;
  r.runs = opt.runs;
  r.seed = opt.seed;
  r.band_level = opt.band_level;
  r.alpha = opt.alpha;
  fit_base(rec, opt, r, std::move(outliers));
  Blocks b = make_blocks(rec.phase);
  GlsModel h0;
  h0.cov = {{CovKind::Q}, {CovKind::N}, {CovKind::B}, {CovKind::K}};
  const double q = rec.phase.exact() ? rec.phase.arcsec_per_count : 0.0;
  h0.fit = profile(b, hypothesis_of(b, {}, h0.cov), start_levels(r.base, q, b, h0.cov));
  b.counter = counter_term(r.base, q, b);
  const Outside out = outside_tests(rec.phase, b, opt.alpha);
  bool fast_named = false;
  const GlsModel final_model = select_effects(b, h0, out, opt.alpha, r, fast_named, opt.progress);
  r.termination = combine(h0.fit.termination, final_model.fit.termination);
  extend(b, final_model, out, fast_named, r);
  test_lowpass(rec.phase, out, r);
  bands(rec.phase, r);
  likelihood_gain(rec.phase, b, h0, final_model, out, fast_named, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

}  // namespace rwcalc
