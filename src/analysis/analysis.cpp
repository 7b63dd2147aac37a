// The analyze pipeline (its JSON: result_json.cpp; the readable report: analysis_text.cpp).
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

Verdict verdict_under(const AnalysisResult& r, const AnalysisOptions& options) {
  Verdict v = verdict_of(r, options);
  if (r.fit_rejected()) withhold_verdict(r, v);
  return v;
}

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
    if (r.sensor == SensorKind::Gyro) r.verdict = verdict_under(r, options);  // made, shown only if it applies
  }
  if (options.fit_checks) r.warnings = fit_warnings(r);
  return r;
}

}  // namespace rwcalc
