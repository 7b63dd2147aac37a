// The analyze pipeline and its JSON (the readable report: analysis_text.cpp).
#include "rwcalc/analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <optional>

#include "fit_range.hpp"
#include "rwcalc/confidence.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/segments.hpp"
#include "rwcalc/units.hpp"
#include "spectral_lines.hpp"

namespace rwcalc {

namespace {

nlohmann::json coef_json(const Coefficient& c) {
  return {{"value", c.value},       {"sigma", c.sigma},       {"low95", c.low},
          {"high95", c.high},       {"resolved", c.resolved}, {"estimate", c.estimate},
          {"in_model", c.in_model}, {"fitted", c.enabled},    {"termination", to_json(c.termination)}};
}

nlohmann::json method_json(const MethodEstimate& m) {
  if (!m.valid) return nullptr;
  return {{"value", m.value}, {"sigma", m.sigma},       {"low95", m.low},
          {"high95", m.high}, {"resolved", m.resolved}, {"estimate", m.estimate}};
}

nlohmann::json opt_num(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

std::string_view range_source_name(FitRangeChoice::Source s) {
  switch (s) {
    case FitRangeChoice::Source::Option: return "option";
    case FitRangeChoice::Source::ShortTau: return "short_tau_check";
    case FitRangeChoice::Source::All: break;
  }
  return "all";
}

}  // namespace

double vertical_earth_rate(double latitude_deg) {
  return units::earth_rate_deg_per_h * std::sin(latitude_deg * std::numbers::pi / 180.0);
}

std::optional<double> temperature_from_name(std::string_view path) {
  const auto slash = path.find_last_of("/\\");
  const std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  auto alnum = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) continue;
    if (i > 0 && std::isdigit(static_cast<unsigned char>(name[i - 1]))) continue;
    std::size_t j = i;
    while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
    if (j + 1 < name.size() && name[j] == '.' && std::isdigit(static_cast<unsigned char>(name[j + 1]))) {
      ++j;
      while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
    }
    if (j >= name.size() || name[j] != 'C') continue;
    if (j + 1 < name.size() && alnum(name[j + 1])) continue;
    double sign = 1.0;
    if (i > 0) {
      const char s = name[i - 1];
      if (s == 'm' || s == 'p') {
        sign = s == 'm' ? -1.0 : 1.0;
        if (i > 1 && alnum(name[i - 2])) continue;  // "…xm50C" is not a temperature
      } else if (s == '-' || s == '+') {
        sign = s == '-' ? -1.0 : 1.0;
      } else if (alnum(s)) {
        continue;
      }
    }
    return sign * std::stod(std::string(name.substr(i, j - i)));
  }
  return std::nullopt;
}

nlohmann::json allan_json(const AllanResult& a) {
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : a.points)
    pts.push_back({{"m", p.m},
                   {"tau_s", p.tau_s},
                   {"n", p.n},
                   {"alpha", p.alpha},
                   {"edf", p.edf},
                   {"var", p.var},
                   {"dev", p.dev},
                   {"dev_low", p.dev_low},
                   {"dev_high", p.dev_high}});
  return {{"estimator", std::string(to_string(a.estimator))},
          {"unit", a.unit},
          {"tau0_s", a.tau0_s},
          {"points_in", a.points_in},
          {"confidence", a.confidence},
          {"points", pts}};
}

nlohmann::json input_json(const Recording& rec) {
  nlohmann::json j = {{"column", rec.column_name},
                      {"kind", std::string(to_string(rec.mode))},
                      {"unit", std::string(input_unit(rec))},
                      {"rate_hz", rec.rate_hz},
                      {"rate_source", std::string(to_string(rec.rate_source))},
                      {"notes", rec.notes},
                      {"warnings", rec.warnings},
                      {"file_bytes", rec.file_bytes},
                      {"sha256", rec.sha256}};
  nlohmann::json id = nlohmann::json::object();
  for (std::string_view key : kIdentificationKeys) {
    const auto it = rec.metadata.find(std::string(key));
    id[std::string(key)] = it == rec.metadata.end() ? nlohmann::json(nullptr) : nlohmann::json(it->second);
  }
  j["identification"] = std::move(id);
  if (rec.mode == InputMode::Pulses || rec.mode == InputMode::Counter)
    j["arcsec_per_count"] = rec.phase.arcsec_per_count;
  j["time_column"] = rec.time_column ? nlohmann::json(*rec.time_column) : nlohmann::json(nullptr);
  if (rec.time_column) {
    j["time_unit"] = rec.time_unit;
    j["time_unit_source"] = rec.time_unit_source;
    j["jitter"] = {{"steps", rec.jitter.steps},
                   {"max_fraction", rec.jitter.max_fraction},
                   {"rms_fraction", rec.jitter.rms_fraction}};
  }
  return j;
}

namespace {

/// A line that carries less than this share of every octave point's AV is ignored.
constexpr double kLineShareIgnored = 0.01;
/// Points whose AV the lines carry more than this share of are left out of the fit.
constexpr double kLineShareLeftOut = 0.9;

/// What the result says of its record: source, size, column, pulse weight and temperature (from the
/// option, the metadata or a column, or the file name, in that order).
void describe_record(const Recording& rec, const AnalysisOptions& options, AnalysisResult& r) {
  r.source = rec.source;
  r.samples = rec.samples;
  r.rate_hz = rec.rate_hz;
  r.duration_s = rec.phase.duration_s();
  r.segments = rec.segments;
  r.column = rec.column_name;
  r.arcsec_per_count = rec.phase.exact() ? rec.phase.arcsec_per_count : 0.0;
  if (options.temperature_c) {
    r.temperature_c = options.temperature_c;
    r.temperature_source = N_("option");  // the JSON's keyword, translated where shown
  } else if (rec.temperature_c) {
    r.temperature_c = rec.temperature_c;
    r.temperature_source = rec.metadata.count("temperature_c") ? N_("metadata") : N_("column");
  } else if (auto t = temperature_from_name(rec.source)) {
    r.temperature_c = t;
    r.temperature_source = N_("file name");
  }
}

/// The octave points of a finer grid's result, on which the fit and the slope readout work. As on
/// the octave grid itself, the longest τ carries the previous τ's α (Stable32), and its EDF and
/// bounds follow from that α.
AllanResult octave_points_of(const AllanResult& all, const AllanOptions& aopt) {
  AllanResult octave_points = all;
  std::erase_if(octave_points.points, [](const AllanPoint& p) { return (p.m & (p.m - 1)) != 0; });
  auto& op = octave_points.points;
  if (aopt.noise_id && op.size() > 1 && op.back().alpha != op[op.size() - 2].alpha) {
    AllanPoint& last = op.back();
    last.alpha = op[op.size() - 2].alpha;
    last.edf = edf_for(aopt.estimator, last.alpha, last.m, octave_points.points_in);
    const DevInterval ci = chi2_interval(last.var, last.edf, aopt.confidence);
    last.dev_low = ci.low;
    last.dev_high = ci.high;
  }
  return octave_points;
}

/// A B estimate from one AV point as the verdict's input: its χ² confidence distribution.
EstimateInput av_estimate_input(const AvBEstimate& b) {
  EstimateInput e;
  e.value = b.B.value;
  e.low = b.B.low;
  e.high = b.B.high;
  e.resolved = b.B.resolved;
  e.cdf = [b](double x) { return b.cdf(x); };
  return e;
}

/// The class verdict from the fit's N and the B estimate the options choose.
Verdict verdict_of(const AnalysisResult& r, const AnalysisOptions& options) {
  const FitResult& fit = r.fit;
  auto from_fit = [&fit](Term t) {
    EstimateInput e;
    const auto& c = fit[t];
    e.value = c.value;
    e.low = c.low;
    e.high = c.high;
    e.resolved = c.resolved;
    e.cdf = [&fit, t](double x) { return fit.cdf(t, x); };
    return e;
  };
  EstimateInput b_in;
  double rho = 0;
  switch (options.verdict.b_estimate) {
    case BEstimate::Fit:
      b_in = from_fit(Term::B);
      rho = fit.log_correlation(Term::B, Term::N);
      break;
    case BEstimate::SigmaMin:
      if (!r.b_min.B.valid)
        throw AnalysisError(trf("{}: no Allan deviation minimum at tau <= T/10 to read B from", r.source));
      b_in = av_estimate_input(r.b_min);
      break;
    case BEstimate::Avg100:
      if (!r.b100.B.valid)
        throw AnalysisError(trf("{}: the record is shorter than three {:g}-s blocks; use --b-estimate fit", r.source,
                                options.methods.block_s));
      b_in = av_estimate_input(r.b100);
      break;
  }
  return decide(b_in, from_fit(Term::N), rho, options.verdict);
}

/// The Earth rate and the class table are a ring-laser gyro's on its test stand: on for pulse or
/// counter input, or when asked for; off (and said) for other gyros; never for accelerometers.
void decide_applicability(const Recording& rec, const AnalysisOptions& options, AnalysisResult& r) {
  const bool gyro = r.sensor == SensorKind::Gyro;
  const bool pulses = rec.mode == InputMode::Pulses || rec.mode == InputMode::Counter;
  r.earth_rate_applied = gyro && options.earth_rate.value_or(pulses);
  r.verdict_applies = gyro && options.verdict_wanted.value_or(pulses);
  if (!gyro)
    r.not_applied_reason = tr("an accelerometer: no Earth rate and no gyro class table");
  else if (!r.earth_rate_applied || !r.verdict_applies)
    r.not_applied_reason = trf("{} input, not a ring-laser gyro's pulses: {}{}{} (--vertical asks for both{})",
                               to_string(rec.mode), r.earth_rate_applied ? "" : tr("the Earth rate is not subtracted"),
                               !r.earth_rate_applied && !r.verdict_applies ? tr(" and ") : "",
                               r.verdict_applies ? "" : tr("the GOST RV 52339 class verdict is not given"),
                               !r.verdict_applies ? tr("; --limits FILE for the verdict")
                                                  : tr("; --earth-rate or --latitude for the Earth rate"));
}

/// Mean rate, expected Earth rate and the bias between them.
void earth_rate_and_bias(const Recording& rec, const AnalysisOptions& options, AnalysisResult& r) {
  if (rec.segments.size() < 2) {
    r.mean_rate_deg_per_h = rec.phase.diff(rec.phase.points() - 1, 0) / r.duration_s;
  } else {  // over the segments only: the phase may run on through a gap (angle input)
    double change = 0, duration = 0;
    for (const PhaseSeries& x : segment_phases(rec))
      if (x.points() > 1) change += x.diff(x.points() - 1, 0), duration += x.duration_s();
    r.mean_rate_deg_per_h = change / duration;
  }
  if (!r.earth_rate_applied) {  // the mean is the bias (for an accelerometer, with gravity's projection)
    r.bias_deg_per_h = r.mean_rate_deg_per_h;
    return;
  }
  r.earth_rate_given = options.earth_rate_deg_per_h.has_value();
  r.latitude_deg = r.earth_rate_given ? 0.0 : options.latitude_deg;
  r.earth_rate_deg_per_h =
      r.earth_rate_given ? *options.earth_rate_deg_per_h : vertical_earth_rate(options.latitude_deg);
  r.bias_deg_per_h = r.mean_rate_deg_per_h - r.earth_rate_deg_per_h;
}

/// The fit of the octave points: over the range the user gave, else from 10 τf when the shortest τ
/// shows an output filter (check_output_filter), else over every point; a fit the goodness of fit
/// rejects (p < 0.001) is refitted with its intervals scaled by √(χ²/dof) (FitOptions::dispersion).
/// The octave points less the Allan variance of the rate's spectral lines (spectral_lines.hpp): a
/// line the five-term model lacks would otherwise be read as white noise and bias-instability near
/// τ ≈ 1/f. Only lines whose AV peaks (at τ = 0.371/f) at or beyond the short-τ check's reference τ
/// are taken off: faster ones are short-τ structure, which the fit range leaves out
/// (check_output_filter). Points the lines dominate (over 90 % of the AV) are left out: what
/// remains there is the difference of two close numbers.
std::vector<FitPoint> without_spectral_lines(const std::vector<FitPoint>& points, const PhaseSeries& x,
                                             FitRangeChoice& range) {
  std::vector<FitPoint> out = points;
  for (const SpectralLineFound& found : find_spectral_lines(x)) {
    if (kLinePeakTau / found.f_hz < short_tau_reference_s(x.tau0_s)) continue;
    FitRangeChoice::Line line{found.f_hz, std::sqrt(found.power), found.peak_ratio, 0, 0};
    for (const FitPoint& p : points) {
      const double share = spectral_lines_avar({found}, p.tau_s) / p.var;
      if (share > line.max_share) line.max_share = share, line.tau_at_max_s = p.tau_s;
    }
    if (line.max_share < kLineShareIgnored) continue;
    range.lines.push_back(line);
    for (FitPoint& p : out) p.var -= spectral_lines_avar({found}, p.tau_s);
  }
  const auto dominated = [&](const FitPoint& p) {
    const auto it = std::find_if(points.begin(), points.end(), [&](const FitPoint& q) { return q.tau_s == p.tau_s; });
    return !(p.var > (1 - kLineShareLeftOut) * it->var);
  };
  range.line_points_left_out = static_cast<int>(std::count_if(out.begin(), out.end(), dominated));
  std::erase_if(out, dominated);
  return out;
}

void fit_with_checks(const std::vector<FitPoint>& all_points, const PhaseSeries& x, const AnalysisOptions& options,
                     AnalysisResult& r) {
  const bool exact_counts = x.exact();
  // Pulse counts are a ring-laser read-out: no vibration line to take off.
  const std::vector<FitPoint> points =
      options.fit_checks && !exact_counts ? without_spectral_lines(all_points, x, r.fit_range) : all_points;
  FitOptions fopt = options.fit;
  if (exact_counts && x.points() > 1)  // the counter's read-out, from the record's mean rate
    fopt.counter =
        CounterReadout{static_cast<double>(x.count(x.points() - 1) - x.count(0)) / static_cast<double>(x.points() - 1),
                       x.arcsec_per_count, x.tau0_s, x.points()};
  FitRangeChoice& range = r.fit_range;
  const bool default_range = fopt.tau_min_s == 0 && std::isinf(fopt.tau_max_s);
  if (options.fit_range_given || !default_range) {
    range.source = FitRangeChoice::Source::Option;
  } else if (options.fit_checks &&
             !exact_counts) {  // pulse counts have no output filter: their short τ is the read-out
    const OutputFilterCheck check = check_output_filter(points, fopt);
    if (check.found || check.departures) {
      range.source = FitRangeChoice::Source::ShortTau;
      range.shortest_ratio = check.ratio;
      range.filter_tc_s = check.found ? check.tc_s : 0.0;
      range.departure_tau_s = check.departure_tau_s;
      range.departure_ratio = check.departure_ratio;
      range.reference_tau_s = check.reference_tau_s;
      fopt.tau_min_s = check.tau_min_s;
    }
  }
  r.fit = fit_noise(points, fopt);
  if (options.fit_checks && !exact_counts && range.source != FitRangeChoice::Source::Option && r.fit_rejected())
    move_past_short_tau_misfit(points, x.tau0_s, fopt, r);
  if (options.fit_checks && r.fit_rejected() && r.fit.chi2_per_dof > 1) {
    range.intervals_scaled = true;
    range.interval_scale = std::sqrt(r.fit.chi2_per_dof);
    fopt.dispersion *= r.fit.chi2_per_dof;
    r.fit = fit_noise(points, fopt);
  }
  range.tau_min_s = fopt.tau_min_s;
  range.tau_max_s = fopt.tau_max_s;
}

/// Allan variance, fit and classic readout. A finer grid (--tau) is reported in full, but the fit
/// and the slope readout use its octave points, so the coefficients and the verdict do not depend
/// on the grid. The reported bounds of the overlapping AV are the fitted model's (apply_model_bounds).
void allan_and_fit(const Recording& rec, const PhaseSeries& longest, const AnalysisOptions& options,
                   AnalysisResult& r) {
  AllanOptions aopt = options.allan;
  const bool octave = aopt.grid.kind == TauGrid::Kind::Octave;
  if (!octave) {
    aopt.grid.with_octave = true;
    if (aopt.grid.kind == TauGrid::Kind::Dense && aopt.grid.max_m == 0)  // dense to N/10
      aopt.grid.max_m = std::max<std::int64_t>(1, static_cast<std::int64_t>(rec.phase.points() / 10));
  }
  r.allan = allan_of_record(rec, aopt);
  const AllanResult octave_points = octave ? AllanResult{} : octave_points_of(r.allan, aopt);
  const AllanResult& fitted = octave ? r.allan : octave_points;
  try {
    fit_with_checks(fit_points(fitted), longest, options, r);
  } catch (const AnalysisError& e) {
    throw AnalysisError(fmt::format("{}: {}", rec.source, e.what()));
  }
  r.slope = slope_readout(fitted);
  if (options.fit_checks) r.model_bounds = apply_model_bounds(r.allan, r.fit, &longest);
}

/// A record whose samples are all the same value (a dead or stuck channel) has no noise: its Allan
/// deviation is zero at every τ and nothing can be fitted. Said as such, not as a fit without points.
void require_noise(const Recording& rec) {
  const PhaseSeries& x = rec.phase;
  for (std::size_t i = 2; i < x.points(); ++i)
    if (x.diff(i, i - 1) != x.diff(1, 0)) return;
  throw AnalysisError(
      trf("{}: every sample has the same value, so there is no noise to analyse (a dead or stuck channel?)",
          rec.source));
}

/// The paper's methods as unbiased estimators (direct N, B from the 100-s averages, σ_min/0.6643
/// with its bias factor) and their discrepancies from the fit; the raw spread of 100-s means
/// beside its expectation under the fit.
void cross_checks(const PhaseSeries& x, const AnalysisOptions& options, AnalysisResult& r) {
  r.direct = direct_n(x, options.methods, &r.fit);
  attach_straight_line_bias(r.direct, r.fit, x.duration_s(), x.tau0_s);
  r.b100 = b_from_averages(x, r.fit, options.methods.block_s);
  r.b_min = b_from_minimum(r.allan, r.slope, r.fit);
  if (r.b_min.B.valid) r.slope_B_sigma = r.b_min.B.sigma;
  r.avg100 = block_spread(x, options.methods.block_s);
  attach_expectation(r.avg100, r.fit);
  const auto& fn = r.fit[Term::N];
  const auto& fb = r.fit[Term::B];
  if (r.direct.N.valid)
    r.N_direct_discrepancy_sigma = discrepancy_sigma(r.direct.N.value, r.direct.N.sigma, fn.value, fn.sigma);
  if (r.b100.B.valid)
    r.B_100s_discrepancy_sigma = discrepancy_sigma(r.b100.B.value, r.b100.B.sigma, fb.value, fb.sigma);
  if (r.avg100.spread.valid && r.avg100.expected > 0)
    r.B_100s_vs_model_sigma =
        discrepancy_sigma(r.avg100.spread.value, r.avg100.spread.sigma, r.avg100.expected, r.avg100.expected_sigma);
}

}  // namespace

AnalysisResult analyze(const Recording& read, const AnalysisOptions& options) {
  require_valid(options);
  const std::optional<SensorKind> sensor = sensor_kind(read.phase.kind);
  if (!sensor)
    throw UsageError(
        trf("{}: analyze needs gyro data (pulses, counter, angle in arcsec/deg/rad, or rate in "
            "deg/h, deg/s, rad/s) or accelerometer data (m/s^2, g, mg, ug); this input is clock data",
            read.source));
  AnalysisResult r;
  r.sensor = *sensor;
  // Shares of the time of the steps, in per cent, as measured on a 6-h record at 1 kHz: the outlier
  // screen, the Allan variance with the fit and its checks; the cross-checks take the last 20.
  constexpr std::uint64_t kScreen = 5, kAllanAndFit = 75;
  Progress progress(trf("analysing {}", printable(read.source)), 100, options.progress, Progress::Measure::Percent);
  Recording edited;
  const Recording& rec = screen_outliers(read, options.outlier_action, options.outlier_threshold, r.outliers, edited);
  progress.advance(kScreen);
  describe_record(rec, options, r);
  r.input = input_json(read);  // as read: the outlier screen's copy keeps no notes
  decide_applicability(read, options, r);
  if (rec.phase.points() < 3)
    throw AnalysisError(trf("{}: the record holds {} sample(s); far too short to analyse", rec.source, rec.samples));
  require_noise(rec);
  earth_rate_and_bias(rec, options, r);
  // A record split at gaps: the spectral-line search, the per-τ bounds and the cross-checks use the
  // longest segment (they need one contiguous stretch); the Allan variance pools every segment.
  const bool segmented = rec.segments.size() > 1;
  const PhaseSeries longest = segmented ? longest_segment(rec) : PhaseSeries{};
  const PhaseSeries& contiguous = segmented ? longest : rec.phase;
  allan_and_fit(rec, contiguous, options, r);
  progress.advance(kAllanAndFit);
  if (options.cross_checks) {
    cross_checks(contiguous, options, r);
    if (r.sensor == SensorKind::Gyro) r.verdict = verdict_of(r, options);  // made, shown only if it applies
    if (r.sensor == SensorKind::Gyro && r.fit_rejected()) withhold_verdict(r);
  }
  if (options.fit_checks) r.warnings = fit_warnings(r);
  return r;
}

static nlohmann::json to_json_fields(const AnalysisResult& r);

namespace {

using nlohmann::json;

/// The spectral lines taken off the fit's points; rms in the phase unit per second.
json spectral_lines_json(const FitRangeChoice& range) {
  json lines = json::array();
  for (const auto& l : range.lines)
    lines.push_back({{"frequency_hz", l.f_hz},
                     {"rms", l.rms},
                     {"peak_over_local_level", l.peak_ratio},
                     {"max_share_of_av", l.max_share},
                     {"tau_at_max_share_s", l.tau_at_max_s}});
  return lines;
}

json fit_json(const AnalysisResult& r) {
  const auto& f = r.fit;
  return {{"Q_arcsec", coef_json(f[Term::Q])},
          {"N_deg_per_sqrt_h", coef_json(f[Term::N])},
          {"B_deg_per_h", coef_json(f[Term::B])},
          {"K_deg_per_h_per_sqrt_h", coef_json(f[Term::K])},
          {"R_deg_per_h2", coef_json(f[Term::R])},
          {"chi2_per_dof", f.chi2_per_dof},
          {"chi2", f.chi2},
          {"dof", f.dof},
          {"p_value", f.p_value},
          {"termination", to_json(f.termination)},
          {"corr_NQ", f.corr_NQ},
          {"corr_NB", f.corr_NB},
          {"points", f.used.size()},
          {"tau_min_s", f.used.empty() ? 0.0 : f.used.front().tau_s},
          {"tau_max_s", f.used.empty() ? 0.0 : f.used.back().tau_s},
          {"dispersion", f.options.dispersion},
          {"edf_inflation", f.options.edf_inflation},
          {"edf_cap", f.options.edf_cap},
          {"phi_N", f.phi[static_cast<std::size_t>(Term::N)]},
          {"phi_B", f.phi[static_cast<std::size_t>(Term::B)]},
          {"K_weight", f.k_alternative ? json(f.k_weight) : json(nullptr)},
          {"confidence", f.options.confidence},
          {"readout", !f.options.counter  ? "floating"
                      : f.counter_readout ? "counter"
                                          : "white"},
          {"range",
           {{"tau_min_s", r.fit_range.tau_min_s},
            {"tau_max_s", std::isinf(r.fit_range.tau_max_s) ? json(nullptr) : json(r.fit_range.tau_max_s)},
            {"chosen_by", range_source_name(r.fit_range.source)},
            {"reason", r.fit_range.reason()},
            {"shortest_tau_ratio", r.fit_range.shortest_ratio},
            {"filter_time_constant_s", r.fit_range.filter_tc_s},
            {"departure_tau_s", r.fit_range.departure_tau_s},
            {"departure_ratio", r.fit_range.departure_ratio},
            {"reference_tau_min_s", r.fit_range.reference_tau_s},
            {"spectral_lines", spectral_lines_json(r.fit_range)},
            {"line_points_left_out", r.fit_range.line_points_left_out},
            {"rejected_chi2_per_dof", r.fit_range.rejected_chi2},
            {"rejected_from_tau_s", r.fit_range.rejected_from_tau_s}}},
          {"misfit", misfit_json(r)},
          {"intervals_scaled", r.fit_range.intervals_scaled},
          {"interval_scale", r.fit_range.interval_scale}};
}

json warnings_json(const AnalysisResult& r) {
  json warnings = json::array();
  for (const auto& w : r.warnings)
    warnings.push_back({{"code", w.code}, {"message", w.message}, {"command", w.command}});
  return warnings;
}

json allan_bounds_json(const AnalysisResult& r) {
  json allan = allan_json(r.allan);
  allan["bounds"] = r.model_bounds ? "fitted model: EDF = 2 sigma^4/Var(sigma^2 estimate), alpha of the leading term"
                                   : "Stable32 noise identification and Greenhall-Riley EDF";
  return allan;
}

/// Direct N: the unbiased estimate, its regression curve (the seed paper's Fig. 2) and, for the
/// figure, the paper's straight line.
json direct_n_json(const AnalysisResult& r) {
  json n_direct = method_json(r.direct.N);
  if (!n_direct.is_null()) {
    n_direct["estimator"] = "overlapping increments, regression on the exact expectations of Q, N, B";
    n_direct["interval"] = "parametric bootstrap";
    n_direct["replicates"] = r.direct.replicates;
    n_direct["discrepancy_sigma"] = r.N_direct_discrepancy_sigma;
    n_direct["Q2_arcsec2"] = r.direct.q2_arcsec2;
    n_direct["N2_arcsec2_per_s"] = r.direct.n2_arcsec2_per_s;
    n_direct["B2_arcsec2_per_s2"] = r.direct.b2_arcsec2_per_s2;
    // The points of the regression (the seed paper's Fig. 2): interval length, number of
    // overlapping increments, their variance about the mean (Earth rate and bias removed) and the
    // regression's value there. The line drawn with them is the paper's straight line.
    nlohmann::json curve = nlohmann::json::array();
    for (std::size_t i = 0; i < r.direct.points.size(); ++i) {
      const auto& p = r.direct.points[i];
      const auto& g = r.direct.basis[i];
      curve.push_back({{"t_s", p.t_s},
                       {"intervals", p.intervals},
                       {"var_arcsec2", p.var_arcsec2},
                       {"model_arcsec2", g.q * r.direct.q2_arcsec2 + g.n * r.direct.n2_arcsec2_per_s +
                                             g.b * r.direct.b2_arcsec2_per_s2}});
    }
    n_direct["curve"] = std::move(curve);
    n_direct["t_min_s"] = r.direct.points.front().t_s;
    n_direct["t_max_s"] = r.direct.points.back().t_s;
    if (r.direct.straight.valid) {
      n_direct["intercept_arcsec2"] = r.direct.straight.intercept_arcsec2;
      n_direct["slope_arcsec2_per_s"] = r.direct.straight.slope_arcsec2_per_s;
    }
  }
  return n_direct;
}

json methods_json(const AnalysisResult& r) {
  json n_direct = direct_n_json(r);
  json straight = nullptr;
  if (r.direct.straight.valid)
    straight = {{"value", r.direct.straight.value},
                {"intercept_arcsec2", r.direct.straight.intercept_arcsec2},
                {"slope_arcsec2_per_s", r.direct.straight.slope_arcsec2_per_s},
                {"bias_factor", r.direct.straight.bias_factor},
                {"note", "biased: expected value/true N = bias_factor under the fitted Q, N, B"}};
  json b100 = method_json(r.b100.B);
  if (!b100.is_null()) {
    b100["estimator"] = "overlapping AV at the block length minus the fitted terms other than B";
    b100["tau_s"] = r.b100.tau_s;
    b100["avar"] = r.b100.var;
    b100["white_removed"] = r.b100.white;
    b100["edf"] = r.b100.edf;
    b100["discrepancy_sigma"] = r.B_100s_discrepancy_sigma;
  }
  json spread = method_json(r.avg100.spread);
  if (!spread.is_null()) {
    spread["blocks"] = r.avg100.blocks;
    spread["block_s"] = r.avg100.block_s;
    spread["expected"] = r.avg100.expected;
    spread["expected_sigma"] = r.avg100.expected_sigma;
    spread["discrepancy_model_sigma"] = r.B_100s_vs_model_sigma;
  }
  return {{"N_direct_deg_per_sqrt_h", n_direct},
          {"N_straight_line_paper_deg_per_sqrt_h", straight},
          {"B_100s_deg_per_h", b100},
          {"spread_100s_deg_per_h", spread}};
}

json slope_json(const AnalysisResult& r) {
  return {{"N_deg_per_sqrt_h", opt_num(r.slope.N)},
          {"tau_N_s", r.slope.tau_N_s},
          {"B_deg_per_h", opt_num(r.slope.B)},
          {"B_sigma", r.slope_B_sigma},
          {"B_low95", r.b_min.B.valid ? json(r.b_min.B.low) : json(nullptr)},
          {"B_high95", r.b_min.B.valid ? json(r.b_min.B.high) : json(nullptr)},
          {"B_edf", r.b_min.edf},
          {"B_bias_factor", r.b_min.bias_factor},
          {"sigma_min_deg_per_h", r.slope.sigma_min},
          {"tau_min_s", r.slope.tau_min_s},
          {"K_deg_per_h_per_sqrt_h", opt_num(r.slope.K)},
          {"tau_K_s", r.slope.tau_K_s}};
}

json conventions_json() {
  return {{"Q", "rms white angle error, sigma^2 = 3 Q^2/tau^2 (IEEE 952); the paper's eq. (2) Q is sqrt(3) Q"},
          {"N", "sigma^2 = N^2/tau; N = sigma at tau = 1 h"},
          {"B", "sigma^2 = (2 ln2/pi) B^2, floor 0.6643 B (the paper prints B where B^2 is meant)"},
          {"K", "sigma^2 = K^2 tau/3; K = sigma at tau = 3 h"},
          {"R", "sigma^2 = R^2 tau^2/2"},
          {"deviation_unit", "deg/h (1 arcsec/s = 1 deg/h)"},
          {"intervals", "95 % profile-likelihood; resolved=false: value is the 95 % upper bound"}};
}

}  // namespace

nlohmann::json to_json(const AnalysisResult& r) {
  json j = to_json_fields(r);
  if (!r.not_applied_reason.empty()) {  // keys present only when something is off
    j["earth_rate_subtracted"] = r.earth_rate_applied;
    j["verdict"]["applies"] = r.verdict_applies;
    j["not_applied_reason"] = r.not_applied_reason;
  }
  return j;
}

nlohmann::json segments_json(const AnalysisResult& r) {
  if (r.segments.size() < 2) return nullptr;
  nlohmann::json samples = nlohmann::json::array(), durations = nlohmann::json::array(), gaps = nlohmann::json::array();
  for (const auto& g : r.segments) {
    samples.push_back(g.samples);
    durations.push_back(static_cast<double>(g.samples) / r.rate_hz);
    if (g.gap_s > 0) gaps.push_back({{"line", g.line}, {"missing_s", g.gap_s}, {"before_sample", g.first}});
  }
  return {{"count", r.segments.size()},
          {"samples", samples},
          {"durations_s", durations},
          {"gaps", gaps},
          {"allan", "pooled over the segments: no difference spans a gap; EDF the sum of the segments'"},
          {"cross_checks", "on the longest segment"}};
}

static nlohmann::json to_json_fields(const AnalysisResult& r) {
  return {{"source", r.source},
          {"input", r.input},
          {"samples", r.samples},
          {"rate_hz", r.rate_hz},
          {"duration_s", r.duration_s},
          {"temperature_c", opt_num(r.temperature_c)},
          {"temperature_source", r.temperature_source},
          {"mean_rate_deg_per_h", r.mean_rate_deg_per_h},
          {"earth_rate_deg_per_h", r.earth_rate_deg_per_h},
          {"latitude_deg", r.earth_rate_given || !r.earth_rate_applied ? json(nullptr) : json(r.latitude_deg)},
          {"bias_deg_per_h", r.bias_deg_per_h},
          {"segments", segments_json(r)},
          {"warnings", warnings_json(r)},
          {"allan", allan_bounds_json(r)},
          {"fit", fit_json(r)},
          {"slope_readout", slope_json(r)},
          {"methods", methods_json(r)},
          {"outliers", to_json(r.outliers)},
          {"verdict", to_json(r.verdict)},
          {"conventions", conventions_json()}};
}

}  // namespace rwcalc
