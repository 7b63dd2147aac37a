// The output-filter test that chooses the fit's lower τ, the per-τ bounds from the fitted model,
// and the warnings of a fit that fails (docs/analysis.md, "Per-τ bounds", "When the fit fails").
#include "fit_range.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>

#include "rwcalc/confidence.hpp"
#include "rwcalc/deviance.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output_filter.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/printable.hpp"

namespace rwcalc {

namespace {

/// The extrapolating fit starts at this many τ0: beyond the reach of any filter that would still
/// leave the record's first octave points usable.
constexpr double kReferenceTaus = 16;
/// A roll-off: the AV at τ0 at most this fraction of the extrapolation, and that many standard
/// errors below it (the EDF of the point and the extrapolation's own variance).
constexpr double kRollOffRatio = 0.9;
constexpr double kRollOffSigmas = 5;
/// The fit starts at this many filter time constants (the filter's AV deficit, ≈ 1.5 τf/τ, is
/// then below 15 % at the first point and falls as 1/τ).
constexpr double kFilterTaus = 10;
/// The extrapolating fit must start beyond this many τf for the filter's estimate to hold.
constexpr double kReferenceFilterTaus = 30;

/// A rejected fit's lower τ moves up at most to this many τ0: a line at a tenth of the sample rate
/// or above (and a filter) bends the AV up to a few times 1/f; beyond, the points carry the white
/// noise that N is read from.
constexpr double kMisfitSearchTaus = 32;
/// A point departs from the fit by this many of its standard errors to be named with its neighbours.
constexpr double kMisfitSigmas = 2;

/// α of S_y(f) ∝ f^α for each term (R, a drift, shown as −2 like K).
constexpr int kTermAlpha[kTermCount] = {2, 0, -1, -2, -2};

double extrapolation_variance(const FitResult& f, double tau_s) {
  Eigen::Matrix<double, kTermCount, 1> b;
  for (int i = 0; i < kTermCount; ++i) b[i] = term_basis(kAllTerms[static_cast<std::size_t>(i)], tau_s);
  return b.dot(f.cov_c * b);
}

/// Time constant of a first-order output filter that brings the model's Q and N parts at τ0 down
/// to the measured AV (the other terms are not filtered at τ0); bisection in ln τf. The fit beyond
/// the filter sees white angle noise already filtered (its AV scaled by (1 − φ)/(1 + φ) at every τ,
/// φ = e^(−τ0/τf)): its Q part at τ0 is that of the long-τ limit times (3 − 4φ + φ²)/3. White rate
/// noise keeps its long-τ AV: its part at τ0 is output_lowpass_rate_avar.
double filter_time_constant(const FitResult& f, double tau0, double measured) {
  const double q = f.c[static_cast<int>(Term::Q)], n = f.c[static_cast<int>(Term::N)];
  const double q_part = q * term_basis(Term::Q, tau0);
  const double rest = f.model_var(tau0) - q_part - n * term_basis(Term::N, tau0);
  auto filtered = [&](double tf) {
    const double phi = std::exp(-tau0 / tf);
    return q_part * (3.0 - 4.0 * phi + phi * phi) / 3.0 + n * output_lowpass_rate_avar(1, tau0, tf) + rest;
  };
  double lo = std::log(tau0 * 1e-3), hi = std::log(tau0 * 1e3);
  if (filtered(std::exp(hi)) > measured) return std::exp(hi);
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (filtered(std::exp(mid)) > measured ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

/// The file name as a shell word (quoted when it holds anything beyond [A-Za-z0-9/._+,-]).
std::string shell_word(const std::string& path) {
  const std::string p = printable(path);
  const bool plain = !p.empty() && p.find_first_not_of(
                                       "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                       "0123456789/._+,-") == std::string::npos;
  if (plain) return p;
  std::string q = "'";
  for (const char ch : p) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

}  // namespace

double filter_free_tau_s(double tc_s) { return kFilterTaus * tc_s; }

double short_tau_reference_s(double tau0_s) { return kReferenceTaus * tau0_s; }

namespace {

/// The fit of the points from `tau_min_s` on, the options otherwise as given; none when it fails (too
/// few points left, or no convergence).
std::optional<FitResult> fit_from(std::span<const FitPoint> points, FitOptions options, double tau_min_s) {
  options.tau_min_s = tau_min_s * (1 - 1e-9);
  try {
    return fit_noise(points, options);
  } catch (const AnalysisError&) {
    return std::nullopt;
  }
}

/// The short-τ points against the model fitted from `reference_tau_s`.
OutputFilterCheck compare_short_tau(std::span<const FitPoint> octave, const FitOptions& fit, double reference_tau_s) {
  OutputFilterCheck c;
  const FitPoint& first = octave.front();
  const std::optional<FitResult> reference = fit_from(octave, fit, reference_tau_s);
  if (!reference) return c;  // too few points beyond the reference τ: no test
  const FitResult& f = *reference;
  c.reference_tau_s = f.used.front().tau_s;
  for (const FitPoint& p : octave) {
    if (p.tau_s >= c.reference_tau_s) break;
    const double pred = f.model_var(p.tau_s);
    if (!(pred > 0) || !(p.edf > 0)) return OutputFilterCheck{};
    const double ratio = p.var / pred;
    const double z = (p.var - pred) / std::sqrt(2.0 * pred * pred / p.edf + extrapolation_variance(f, p.tau_s));
    if (&p == &first) c.ratio = ratio;
    if (std::abs(ratio - 1.0) < 1.0 - kRollOffRatio || std::abs(z) < kRollOffSigmas) continue;
    if (&p == &first && ratio < 1.0) {
      c.found = true;
      c.tc_s = filter_time_constant(f, first.tau_s, first.var);
      c.tau_min_s = std::max(c.tau_min_s, filter_free_tau_s(c.tc_s));
    } else {
      c.departures = true;
      c.departure_tau_s = p.tau_s;
      c.departure_ratio = ratio;
      c.tau_min_s = std::max(c.tau_min_s, 2.0 * p.tau_s * (1 - 1e-9));
    }
  }
  return c;
}

}  // namespace

OutputFilterCheck check_output_filter(std::span<const FitPoint> octave, const FitOptions& fit) {
  if (octave.empty() || octave.front().m != 1 || !(octave.front().edf > 0) || !(octave.front().var > 0)) return {};
  // A filter slow enough to bend the reference range too is underestimated: the reference moves
  // up an octave at a time until it starts beyond 30 τf. A reference so far up that its
  // extrapolation no longer resolves the roll-off keeps the nearer one's finding.
  double reference = kReferenceTaus * octave.front().tau_s;
  OutputFilterCheck c = compare_short_tau(octave, fit, reference);
  for (int k = 0; k < 4 && c.found && c.tc_s * kReferenceFilterTaus > c.reference_tau_s; ++k) {
    reference = 2.0 * c.reference_tau_s;
    const OutputFilterCheck next = compare_short_tau(octave, fit, reference);
    if (next.reference_tau_s == 0 || !next.found) break;  // no fit that far up, or one too loose
    c = next;
  }
  return c;
}

namespace {

/// The fourth-moment ratio reads at most kRatioTerms terms, in kRatioRuns runs spread evenly over
/// the record (long runs: each is read at the speed of memory, not of its latency), a run's terms
/// consecutive at short τ and m/4 apart at long τ (term_spacing). Where the ratio is used white phase noise leads,
/// whose terms share no sample beyond the lags 0, m and 2m: the sample's relative standard error is
/// about 3 % (within 4 % of the whole-record ratio on the records of data/gl2d at every octave up to
/// 2^15), against the clamp's range of a factor 16.
constexpr std::size_t kRatioTerms = std::size_t{1} << 16;
constexpr std::size_t kRatioRuns = 64;
constexpr std::size_t kRatioChunk = 256;  // second differences formed at a time, per lag
constexpr std::size_t kLanes = 4;

/// x_(i+2m) − 2x_(i+m) + x_i, in counts for pulse data (the ratio does not see the pulse weight).
double second_difference(const PhaseSeries& x, std::size_t i, std::size_t m) {
  if (!x.exact()) return x.diff(i + 2 * m, i + m) - x.diff(i + m, i);
  auto at = [&x](std::size_t k) { return static_cast<std::uint64_t>(x.count(k)); };
  return static_cast<double>(static_cast<std::int64_t>(at(i + 2 * m) - 2 * at(i + m) + at(i)));
}

/// The spacing of a run's terms: m/4 at long τ (neighbours there share most of their samples
/// through the other noises), halved while the runs would overlap; a divisor of m, so that the
/// terms and their partners l·m on lie on one lattice. 1 when m has no such divisor.
std::size_t term_spacing(std::size_t m, std::size_t most) {
  std::size_t s = m % 4 == 0 ? m / 4 : 1;
  while (s > most && s % 2 == 0) s /= 2;
  return s <= most ? s : 1;
}

/// The second differences of the terms i = from + j·step (j < len) and of their partners l·m on
/// (l = 1, 2, 3) into d[l·len + j]. For counts, each lattice point's count is read once when the
/// partners are few steps on (the three samples of the 4·len differences lie on the lattice).
void lattice_differences(const PhaseSeries& x, std::size_t from, std::size_t step, std::size_t m, std::size_t len,
                         std::vector<std::uint64_t>& g, double* d) {
  const std::size_t r = m / step;  // m in lattice steps
  if (!x.exact() || m % step != 0 || 5 * r > len) {
    for (std::size_t l = 0; l < 4; ++l)
      for (std::size_t j = 0, i = from + l * m; j < len; ++j, i += step) d[l * len + j] = second_difference(x, i, m);
    return;
  }
  g.resize(len + 5 * r);
  for (std::size_t t = 0; t < g.size(); ++t) g[t] = static_cast<std::uint64_t>(x.count(from + t * step));
  for (std::size_t l = 0; l < 4; ++l)
    for (std::size_t j = 0; j < len; ++j) {
      const std::size_t k = j + l * r;
      d[l * len + j] = static_cast<double>(static_cast<std::int64_t>(g[k + 2 * r] - 2 * g[k + r] + g[k]));
    }
}

}  // namespace

double measured_variance_ratio(const PhaseSeries& x, std::int64_t m) {
  const auto um = static_cast<std::size_t>(m);
  if (x.points() < 8 * um + 2) return 1.0;
  const std::size_t n = x.points() - 5 * um;  // terms with a partner 3m on
  // Σ d_i·d_(i+l) and Σ d_i²·d_(i+l)² at l = 0, m, 2m (the lags at which two terms of white phase
  // noise share phase samples) and 3m (disjoint: the baseline), over the sampled terms.
  double c[4][kLanes] = {}, p[4][kLanes] = {};  // kLanes accumulators each, so the loop vectorises
  const bool sampled = n > kRatioTerms;
  const std::size_t runs = sampled ? kRatioRuns : 1, run = sampled ? kRatioTerms / kRatioRuns : n;
  const std::size_t step = sampled ? term_spacing(um, (n - 1) / kRatioTerms) : 1;
  const std::size_t span = (run - 1) * step + 1;
  std::vector<double> d(4 * std::min(run, kRatioChunk));
  std::vector<std::uint64_t> lattice;
  for (std::size_t r = 0; r < runs; ++r) {
    const std::size_t from = spread_run_start(r, runs, n, span);
    for (std::size_t i0 = 0; i0 < run; i0 += d.size() / 4) {
      const std::size_t len = std::min(d.size() / 4, run - i0);
      lattice_differences(x, from + i0 * step, step, um, len, lattice, d.data());
      for (std::size_t l = 0; l < 4; ++l)
        for (std::size_t j = 0; j < len; ++j) {
          const double a = d[j], b = d[l * len + j];
          c[l][j % kLanes] += a * b;
          p[l][j % kLanes] += a * a * b * b;
        }
    }
  }
  auto total = [](const double(&lanes)[kLanes]) { return std::accumulate(lanes, lanes + kLanes, 0.0); };
  const double c0 = total(c[0]), c1 = total(c[1]), c2 = total(c[2]);
  const double nn = static_cast<double>(runs * run);
  // Per term: Σ_|l|≤2m Cov(d_i², d_(i+l)²) from the data, against its Gaussian value 2·Σ Cov(d_i, d_(i+l))².
  const double measured = (total(p[0]) + 2.0 * total(p[1]) + 2.0 * total(p[2]) - 5.0 * total(p[3])) / nn;
  const double gaussian = 2.0 * (c0 * c0 + 2.0 * c1 * c1 + 2.0 * c2 * c2) / (nn * nn);
  if (!(gaussian > 0) || !(measured > 0)) return 1.0;
  return std::clamp(measured / gaussian, 0.25, 4.0);
}

namespace {

/// The octave m ≤ m (a power of two).
std::int64_t octave_of(std::int64_t m) {
  return std::int64_t{1} << (std::bit_width(static_cast<std::uint64_t>(m)) - 1);
}

/// Whether white phase noise carries at least half of σ²_model at τ.
bool white_phase_leads(const FitResult& fit, double tau_s) {
  return fit.readout_var(tau_s) >= 0.5 * fit.model_var(tau_s);
}

/// measured_variance_ratio of each octave that holds a point where white phase noise leads, the
/// octaves in parallel.
std::map<std::int64_t, double> white_phase_ratios(const AllanResult& allan, const FitResult& fit,
                                                  const PhaseSeries& x) {
  std::vector<std::int64_t> octaves;
  for (const AllanPoint& p : allan.points)
    if (white_phase_leads(fit, p.tau_s) && (octaves.empty() || octaves.back() != octave_of(p.m)))
      octaves.push_back(octave_of(p.m));
  std::vector<double> ratio(octaves.size());
  parallel_for(octaves.size(), [&](std::size_t i) { ratio[i] = measured_variance_ratio(x, octaves[i]); });
  std::map<std::int64_t, double> by_octave;
  for (std::size_t i = 0; i < octaves.size(); ++i) by_octave[octaves[i]] = ratio[i];
  return by_octave;
}

}  // namespace

bool apply_model_bounds(AllanResult& allan, const FitResult& fit, const PhaseSeries* x) {
  if (allan.estimator != Estimator::Overlapping || allan.points.empty()) return false;
  const std::vector<FitPoint> pts = fit_points(allan);
  const std::map<std::int64_t, double> ratio =
      x ? white_phase_ratios(allan, fit, *x) : std::map<std::int64_t, double>{};
  for (std::size_t i = 0; i < allan.points.size(); ++i) {
    AllanPoint& p = allan.points[i];
    const double model = fit.model_var(p.tau_s);
    // One point at a time: a dense grid would not fit a full covariance matrix in memory.
    double var = av_covariance(std::span(&pts[i], 1), fit.covariance_c(), true)(0, 0);
    // Where white phase noise leads, its read-out's non-Gaussian errors set the variance.
    if (x && white_phase_leads(fit, p.tau_s)) var *= ratio.at(octave_of(p.m));
    if (!(model > 0) || !(var > 0)) continue;
    p.edf = 2.0 * model * model / var;
    int leading = 0;
    double largest = -1;
    for (int t = 0; t < kTermCount; ++t) {
      const double part = t == static_cast<int>(Term::Q)
                              ? fit.readout_var(p.tau_s)
                              : fit.c[t] * term_basis(kAllTerms[static_cast<std::size_t>(t)], p.tau_s);
      if (part > largest) largest = part, leading = t;
    }
    p.alpha = kTermAlpha[leading];
    const DevInterval ci = chi2_interval(p.var, p.edf, allan.confidence);
    p.dev_low = ci.low;
    p.dev_high = ci.high;
  }
  return true;
}

void move_past_short_tau_misfit(const std::vector<FitPoint>& points, double tau0_s, FitOptions& fopt,
                                AnalysisResult& r) {
  if (r.fit.used.empty()) return;
  const double rejected_chi2 = r.fit.chi2_per_dof, from = r.fit.used.front().tau_s;
  for (double next = 2.0 * from; next <= kMisfitSearchTaus * tau0_s * (1 + 1e-9); next *= 2.0) {
    std::optional<FitResult> f = fit_from(points, fopt, next);
    if (!f) return;  // too few points left
    if (f->p_value < kFitRejectedP) continue;
    fopt.tau_min_s = f->options.tau_min_s;  // the rest as given: the fit's own options carry its term choice
    r.fit = std::move(*f);
    r.fit_range.source = FitRangeChoice::Source::ShortTau;
    r.fit_range.rejected_chi2 = rejected_chi2;
    r.fit_range.rejected_from_tau_s = from;
    return;
  }
}

namespace {

/// What a run of departing points is, from where it lies and the lines taken off.
std::string misfit_structure(const AnalysisResult& r, const FitMisfit& m) {
  for (const auto& l : r.fit_range.lines) {
    const double peak = kLinePeakTau / l.f_hz;
    if (peak >= 0.5 * m.tau_from_s && peak <= 2.0 * m.tau_to_s)
      return trf(
          "the spectral line at {:.4g} Hz: its Allan variance from the spectrum does not match the points "
          "(a line broader or less steady than one sinusoid)",
          l.f_hz);
  }
  const bool first = m.tau_from_s <= r.fit.used.front().tau_s;
  if (first && m.ratio < 1)
    return tr("a roll-off at the shortest tau fitted: an output filter whose roll-off reaches into the fit's range");
  if (first) return tr("short-tau structure: a line or a resonance near 1/(2 tau) Hz, or a filter");
  if (m.ratio > 1) return tr("a bump the five terms cannot follow: a Gauss-Markov process or a low-frequency line");
  return tr(
      "a dip below the model: the fitted terms rise to follow a bump or a step at other tau (a Gauss-Markov "
      "process, a bias step)");
}

}  // namespace

FitMisfit fit_misfit(const AnalysisResult& r) {
  FitMisfit m;
  const auto& pts = r.fit.used;
  if (!r.fit_rejected() || pts.empty()) return m;
  // Each point's signed share of the fit's Gamma deviance, in standard errors.
  std::vector<double> z(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    z[i] = deviance_residual(pts[i].var, r.fit.model_var(pts[i].tau_s), pts[i].edf);
  // The run of neighbouring points departing on one side with the largest deviance.
  double best = -1;
  for (std::size_t lo = 0; lo < pts.size();) {
    std::size_t hi = lo;
    double sum = z[lo] * z[lo];
    std::size_t worst = lo;
    while (hi + 1 < pts.size() && std::abs(z[hi + 1]) >= kMisfitSigmas && std::abs(z[lo]) >= kMisfitSigmas &&
           (z[hi + 1] > 0) == (z[lo] > 0)) {
      ++hi;
      sum += z[hi] * z[hi];
      if (std::abs(z[hi]) > std::abs(z[worst])) worst = hi;
    }
    if (sum > best) {
      best = sum;
      m.tau_from_s = pts[lo].tau_s, m.tau_to_s = pts[hi].tau_s, m.worst_tau_s = pts[worst].tau_s;
      m.ratio = pts[worst].var / r.fit.model_var(pts[worst].tau_s);
      m.sigmas = z[worst];
    }
    lo = hi + 1;
  }
  m.structure = misfit_structure(r, m);
  return m;
}

nlohmann::json misfit_json(const AnalysisResult& r) {
  if (!r.fit_rejected()) return nullptr;
  const FitMisfit m = fit_misfit(r);
  return {{"tau_from_s", m.tau_from_s}, {"tau_to_s", m.tau_to_s}, {"worst_tau_s", m.worst_tau_s},
          {"ratio", m.ratio},           {"sigmas", m.sigmas},     {"structure", m.structure}};
}

namespace {

/// What the short-τ check saw, one clause per finding.
std::string short_tau_findings(const FitRangeChoice& c) {
  std::string s;
  if (c.filter_tc_s > 0)
    s =
        trf("the AV at tau0 is {:.0f} % of the extrapolation of the model fitted from {:g} s, the roll-off "
            "of an output filter of time constant tau_f = {:.3g} s",
            100.0 * c.shortest_ratio, c.reference_tau_s, c.filter_tc_s);
  if (c.departure_tau_s > 0)
    s +=
        trf("{}the AV at {:g} s is {:.0f} % of the extrapolation of the model fitted from {:g} s (short-tau "
            "structure the five-term model lacks: a spectral line, a bump or a filter)",
            s.empty() ? "" : "; ", c.departure_tau_s, 100.0 * c.departure_ratio, c.reference_tau_s);
  if (c.rejected_chi2 > 0)
    s +=
        trf("{}the fit from {:g} s was rejected (chi2/dof = {:.3g}) and is accepted from {:g} s: short-tau "
            "structure (a line or a filter) that bends the longer tau too",
            s.empty() ? "" : "; ", c.rejected_from_tau_s, c.rejected_chi2, c.tau_min_s);
  return s;
}

}  // namespace

namespace {

/// The clause on the spectral lines taken off the points ("" when none).
std::string lines_clause(const FitRangeChoice& c) {
  if (c.lines.empty()) return {};
  std::string freqs;
  for (const auto& l : c.lines) freqs += fmt::format("{}{:.4g}", freqs.empty() ? "" : ", ", l.f_hz);
  return trf("; the Allan variance of the spectral line(s) at {} Hz taken off the points", freqs);
}

std::string range_clause(const FitRangeChoice& c) {
  switch (c.source) {
    case FitRangeChoice::Source::Option: return tr("the range given by --fit-range");
    case FitRangeChoice::Source::ShortTau:
      return trf("tau >= {:g} s ({}): {}", c.tau_min_s,
                 c.rejected_chi2 > 0 ? tr("from where the fit is accepted")
                 : c.filter_tc_s > 0 && 10.0 * c.filter_tc_s >= 2.0 * c.departure_tau_s
                     ? tr("10 tau_f")
                     : tr("beyond the departing points"),
                 short_tau_findings(c));
    case FitRangeChoice::Source::All: break;
  }
  return tr("every octave point (the short-tau points agree with the model)");
}

}  // namespace

std::string FitRangeChoice::reason() const { return range_clause(*this) + lines_clause(*this); }

void withhold_verdict(const AnalysisResult& r, Verdict& v) {
  const FitRangeChoice& fr = r.fit_range;
  const std::string tried =
      fr.source == FitRangeChoice::Source::Option ? std::string(tr("over the range given by --fit-range"))
      : r.arcsec_per_count > 0
          ? std::string(tr("over every octave point, the pulse read-out taken as white angle noise (Q)"))
          : std::string(tr("after the short-tau check (output filter, short-tau structure) and the spectral-line "
                           "search"));
  v.withhold(trf("the fit is rejected: chi2/dof = {:.3g} on {} degrees of freedom (p = {:.2g} < {:g}), {}",
                 r.fit.chi2_per_dof, r.fit.dof, r.fit.p_value, kFitRejectedP, tried),
             trf("rwcalc diagnose {} [input options]", shell_word(r.source)));
}

namespace {

/// Why an iteration ended before its convergence test held, one phrase.
std::string stop_reason(const Termination& t) {
  return t.status == TerminationStatus::IterationLimit
             ? trf("it took its most iterations ({}) before its test of convergence held", t.iterations)
             : trf("no step lowered its objective after {} iterations", t.iterations);
}

/// The warnings of a fit or an interval search that did not converge (none when all did).
void termination_warnings(const FitResult& f, std::vector<AnalysisWarning>& w) {
  if (!f.termination.converged())
    w.push_back({"fit_not_converged",
                 trf("The noise-model fit did not converge: {}. The coefficients are those of its last iteration.",
                     stop_reason(f.termination)),
                 ""});
  for (const Term t : kAllTerms)
    if (const Coefficient& c = f[t]; c.enabled && !c.termination.converged())
      w.push_back({"interval_not_converged",
                   trf("The search for the {} coefficient's confidence bounds did not converge: {}. Its interval "
                       "is the last one reached.",
                       term_name(t), stop_reason(c.termination)),
                   ""});
}

}  // namespace

std::vector<AnalysisWarning> fit_warnings(const AnalysisResult& r) {
  std::vector<AnalysisWarning> w;
  termination_warnings(r.fit, w);
  const std::string src = shell_word(r.source);
  const FitRangeChoice& fr = r.fit_range;
  if (r.verdict.withheld && r.verdict_applies)
    w.push_back({"no_verdict",
                 trf("No class verdict: {}. A rejected fit gives no class and no probability; find what the "
                     "model misses (diagnose) or choose the fit range (--fit-range).",
                     r.verdict.withheld_reason),
                 r.verdict.next_command});
  if (fr.source == FitRangeChoice::Source::ShortTau)
    w.push_back({fr.filter_tc_s > 0 ? "output_filter" : "short_tau_structure",
                 trf("The fit uses tau >= {:g} s only: {}. Give --fit-range to choose the range yourself.",
                     fr.tau_min_s, short_tau_findings(fr)),
                 trf("rwcalc analyze {} [input options] --fit-range 0:", src)});
  for (const auto& line : fr.lines) {
    const ShownUnit si = si_units(r.sensor).deviation;
    w.push_back({"spectral_line",
                 trf("A spectral line at {:.4g} Hz (rms {:.3g} {}, {:.0f} times the local level of the Welch "
                     "spectrum) is not in the five-term model: its Allan variance, computed from the spectrum's "
                     "excess over the local level, is taken off the octave points before the fit (it was "
                     "{:.0f} % of the AV at {:g} s).",
                     line.f_hz, line.rms * si.factor, localized_label(si), line.peak_ratio, 100.0 * line.max_share,
                     line.tau_at_max_s),
                 ""});
  }
  if (fr.line_points_left_out > 0)
    w.push_back({"spectral_line",
                 trf("{} octave point(s) left out of the fit: spectral lines carry over 90 % of their AV.",
                     fr.line_points_left_out),
                 ""});
  if (r.fit_rejected()) {
    const FitMisfit m = fit_misfit(r);
    w.push_back({"fit_rejected",
                 trf("The five-term model does not describe the Allan variance: chi2/dof = {:.3g} "
                     "(dof {}, p = {:.2g}). The points at tau = {:g}..{:g} s depart most (at {:g} s the AV is "
                     "{:.0f} % of the model's, {:+.1f} sigma): {}. The coefficients' intervals are scaled by "
                     "sqrt(chi2/dof) = {:.3g}.",
                     r.fit.chi2_per_dof, r.fit.dof, r.fit.p_value, m.tau_from_s, m.tau_to_s, m.worst_tau_s,
                     100.0 * m.ratio, m.sigmas, m.structure, fr.interval_scale),
                 trf("rwcalc diagnose {} [input options]", src)});
  }
  return w;
}

}  // namespace rwcalc
