// The readable report of an analysis (`rwcalc analyze` without --json): data, Allan deviation,
// noise coefficients, slope readout, cross-checks and verdict.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "rwcalc/analysis.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/option_words.hpp"

namespace rwcalc {

namespace {

/// A number with a sensible count of significant digits (never NaN: callers ensure finiteness).
std::string num(double v, int sig = 4) { return fmt::format("{:.{}g}", v, sig); }

std::string coef_line(const Coefficient& c, std::string_view name, std::string_view unit) {
  if (!c.enabled) return trf("  {:<2} not fitted\n", name);
  if (!c.resolved)
    return trf("  {:<2} < {} {:<14} (not resolved: 95 % upper bound{})\n", name, num(c.value, 3), unit,
               c.in_model ? "" : tr("; left out of the model"));
  return fmt::format("  {:<2} {} {:<14} ± {}  [{}, {}] (95 %)\n", name, num(c.value), unit, num(c.sigma, 2),
                     num(c.low, 3), num(c.high, 3));
}

std::string verdict_param_line(const Verdict& v, const ParameterVerdict& p) {
  std::string s = fmt::format("  {} = {}{} {}: {}", p.parameter, p.resolved ? "" : "< ", num(p.value, 3), tr(p.unit),
                              v.statement(p));
  if (p.cls != p.cls_strict)
    s += trf("  [with the +{:g} % tolerance; strict: class {}]", v.tolerance_pct, class_label(p.cls_strict));
  s += tr("\n    P(meets class):");
  for (std::size_t k = 0; k < p.limit.size(); ++k)
    s += fmt::format(" {} ≤ {}: {:.2f};", v.class_numbers[k], num(p.limit[k], 3), p.p_meets[k]);
  s += tr("\n    margin to limit:");
  for (std::size_t k = 0; k < p.limit.size(); ++k)
    s += trf(" class {} {:+.0f} %;", v.class_numbers[k], p.margin_pct[k]);
  s += "\n";
  return s;
}
}  // namespace

std::string format_warnings(const std::vector<AnalysisWarning>& warnings) {
  if (warnings.empty()) return {};
  std::string s = tr("WARNINGS\n");
  for (const auto& w : warnings) {
    s += fmt::format("  [{}] {}\n", w.code, w.message);
    if (!w.command.empty()) s += trf("    try: {}\n", as_typed(w.command));  // a command line: never localized
  }
  return s + "\n";
}

std::string format_segments(const AnalysisResult& r) {
  if (r.segments.size() < 2) return {};
  std::string lengths, gaps;
  for (const auto& g : r.segments) {
    lengths += fmt::format("{}{:.1f}", lengths.empty() ? "" : ", ", static_cast<double>(g.samples) / r.rate_hz);
    if (g.gap_s > 0) gaps += trf("{}{:.6g} s before line {}", gaps.empty() ? "" : ", ", g.gap_s, g.line);
  }
  return trf(
      "  segments: {} (split at the time column's gaps by --gaps segments: {}; lengths {} s); the Allan "
      "variance pools them (no difference spans a gap), the cross-checks use the longest\n",
      r.segments.size(), gaps, lengths);
}
namespace {

// "  input: rate samples in deg/s from column 'gyro_x_dps'; sample rate from the time column
// 'timestamp' (ns)": what was read, for the report's Data lines.
std::string input_line(const nlohmann::json& in) {
  if (!in.is_object()) return "";
  const std::string kind = in.value("kind", ""), unit = in.value("unit", "");
  std::string s = tr("  input: ") + (kind == "pulses"    ? std::string(tr("pulse counts"))
                                     : kind == "counter" ? std::string(tr("counter readings"))
                                                         : trf("{} samples in {}", kind, unit));
  s += trf(" from column '{}'; sample rate from {}", as_typed(in.value("column", "")), tr(in.value("rate_source", "")));
  if (in.contains("time_unit"))
    s += trf(" ('{}', in {} by {})", as_typed(in["time_column"].get<std::string>()), in.value("time_unit", ""),
             in.value("time_unit_source", ""));
  if (const auto id = in.find("identification"); id != in.end() && id->is_object()) {
    std::string who;
    for (const auto& [key, label] :
         {std::pair{"serial", N_("serial")}, std::pair{"operator", N_("operator")},
          std::pair{"test_date", N_("test date")}, std::pair{"conditions", N_("conditions")}})
      if (id->contains(key) && (*id)[key].is_string())
        who += fmt::format("{}{} {}", who.empty() ? "" : "; ", tr(label), as_typed((*id)[key].get<std::string>()));
    if (!who.empty()) s += tr("\n  gyro and test: ") + who;
  }
  if (in.contains("sha256"))
    s += trf("\n  file: {} bytes, SHA-256 {}", in.value("file_bytes", std::uint64_t{0}), in.value("sha256", ""));
  return s + "\n";
}

}  // namespace

namespace {

/// The record: source, warnings, samples, input, segments, temperature, mean rate, outliers.
std::string data_section(const AnalysisResult& r) {
  std::string s;
  s += trf("rwcalc analyze: {}\n\n", as_typed(r.source));
  s += format_warnings(r.warnings);
  s += tr("Data\n");
  s += trf("  {} samples at {:g} Hz (tau0 = {:g} ms), {:.1f} s ({:.2f} h), column '{}'", r.samples, r.rate_hz,
           1000.0 / r.rate_hz, r.duration_s, r.duration_s / 3600.0, as_typed(r.column));
  if (r.arcsec_per_count > 0) s += trf(", pulse weight {:g} arcsec", r.arcsec_per_count);
  s += "\n";
  s += input_line(r.input);
  s += format_segments(r);
  s += r.temperature_c ? trf("  temperature {:g} °C (from {})\n", *r.temperature_c, tr(r.temperature_source))
                       : std::string(tr("  temperature unknown\n"));
  if (r.earth_rate_applied)
    s += trf("  mean rate {:.4f} °/h; expected vertical Earth rate {:.4f} °/h ({}); bias {:+.4f} °/h\n\n",
             r.mean_rate_deg_per_h, r.earth_rate_deg_per_h,
             r.earth_rate_given ? std::string(tr("given")) : trf("latitude {:g}°", r.latitude_deg), r.bias_deg_per_h);
  else
    s += trf("  mean rate {:.4f} °/h, the bias (no Earth rate subtracted)\n  {}\n\n", r.mean_rate_deg_per_h,
             r.not_applied_reason);
  s += format_outliers(r.outliers);
  return s;
}

/// The Allan deviation table with the fitted model beside it.
std::string allan_section(const AnalysisResult& r) {
  std::string s;
  s += trf("Allan deviation ({}, bounds at {:g} %{}; * = used in the fit)\n", to_string(r.allan.estimator),
           100.0 * r.allan.confidence, r.model_bounds ? tr(" from the fitted model's EDF; α of its leading term") : "");
  s += fmt::format("  {:>11} {:>12} {:>12} {:>12} {:>10} {:>4} {:>12}\n", tr("tau (s)"), tr("sigma (°/h)"),
                   tr("low (°/h)"), tr("high (°/h)"), tr("EDF"), "α", tr("model (°/h)"));
  for (const auto& p : r.allan.points) {
    const bool used =
        std::any_of(r.fit.used.begin(), r.fit.used.end(), [&](const FitPoint& u) { return u.tau_s == p.tau_s; });
    s += fmt::format("  {:>11.5g} {:>12.5g} {:>12.5g} {:>12.5g} {:>10.4g} {:>4} {:>12.5g}{}\n", p.tau_s, p.dev,
                     p.dev_low, p.dev_high, p.edf, p.alpha, std::sqrt(r.fit.model_var(p.tau_s)), used ? " *" : "");
  }
  s += "\n";
  return s;
}

/// The noise coefficients of the fit, its range, read-out and goodness of fit.
std::string fit_section(const AnalysisResult& r) {
  std::string s;
  const auto& f = r.fit;
  s +=
      trf("Noise coefficients (Gamma-deviance fit of {} octave points, tau {:g}..{:g} s; 95 % profile "
          "intervals{})\n",
          f.used.size(), f.used.front().tau_s, f.used.back().tau_s,
          r.fit_range.intervals_scaled ? trf(", scaled by sqrt(chi2/dof) = {:.3g}", r.fit_range.interval_scale)
                                       : std::string());
  s += trf("  fit range: {}\n", r.fit_range.reason());
  if (f.options.counter)
    s += f.counter_readout
             ? trf("  read-out: a plain counter (its Allan variance from the mean rate, {:.6g} pulses per sample, "
                   "and the pulse weight; Q is white angle noise beyond it)\n",
                   f.options.counter->pulses_per_sample)
             : tr("  read-out: white angle noise Q (a dithered or randomised counter)\n");
  for (const Term t : kAllTerms)
    s += coef_line(f[t], term_name(t),
                   tr(std::array{N_("arcsec"), N_("°/√h"), N_("°/h"), N_("°/h/√h"),
                                 N_("°/h²")}[static_cast<std::size_t>(t)]));
  s += trf("  chi2/dof = {:.2f} (dof {}, p = {:.3g}); corr(N,Q) = {:+.2f}, corr(N,B) = {:+.2f}\n", f.chi2_per_dof,
           f.dof, f.p_value, f.corr_NQ, f.corr_NB);
  s += trf("  (variance inflation for correlated AV points and few EDF: N x{:.2f}, B x{:.2f})\n\n",
           f.phi[static_cast<std::size_t>(Term::N)], f.phi[static_cast<std::size_t>(Term::B)]);
  return s;
}

/// The classic single-term slope lines.
std::string slope_section(const AnalysisResult& r) {
  std::string s;
  s += tr("Classic slope-line readout (single-term lines; biased where terms overlap)\n");
  s += r.slope.N
           ? trf("  N = {} °/√h (−½ line through tau = {:.3g} s, read at 1 h)\n", num(*r.slope.N, 3), r.slope.tau_N_s)
           : std::string(tr("  N: no part of the curve has slope −½\n"));
  if (r.b_min.B.valid) {
    s +=
        trf("  B = sigma_min/0.6643 = {}{} °/h [{}, {}] (95 %, EDF {:.3g} under the fitted model; sigma_min {} °/h "
            "at tau = {:.4g} s <= T/10)\n",
            r.b_min.B.resolved ? "" : "< ", num(r.b_min.B.value, 3), num(r.b_min.B.low, 3), num(r.b_min.B.high, 3),
            r.b_min.edf, num(r.slope.sigma_min, 3), r.slope.tau_min_s);
    if (r.b_min.bias_factor > 0)
      s +=
          trf("    biased: estimates sigma(tau_min)/0.6643 = {:.2f} x B under the fitted model\n", r.b_min.bias_factor);
  }
  s += r.slope.K
           ? trf("  K = {} °/h/√h (+½ line through tau = {:.3g} s, read at 3 h)\n", num(*r.slope.K, 3), r.slope.tau_K_s)
           : std::string(tr("  K: no part of the curve has slope +½\n"));
  s += "\n";
  return s;
}

/// The paper's cross-checks as unbiased estimators.
std::string cross_check_section(const AnalysisResult& r) {
  std::string s;
  s += tr("Cross-checks (the paper's methods as unbiased estimators; 95 % intervals)\n");
  const auto& d = r.direct;
  if (d.N.valid)
    s += trnf(
        "  N direct (overlapping angle increments, {:g}..{:g} s, exact Q/N/B expectations): {}{} °/√h [{}, {}] "
        "(bootstrap, {} replicate); vs AV fit {:+.1f} sigma\n",
        "  N direct (overlapping angle increments, {:g}..{:g} s, exact Q/N/B expectations): {}{} °/√h [{}, {}] "
        "(bootstrap, {} replicates); vs AV fit {:+.1f} sigma\n",
        static_cast<unsigned long long>(d.replicates), d.points.front().t_s, d.points.back().t_s,
        d.N.resolved ? "" : "< ", num(d.N.value, 3), num(d.N.low, 3), num(d.N.high, 3), d.replicates,
        r.N_direct_discrepancy_sigma);
  else
    s += tr("  N direct: record too short\n");
  if (d.straight.valid) {
    s += trf("  N straight line (paper): {} °/√h", num(d.straight.value, 3));
    s += d.straight.bias_factor > 0
             ? trf("; biased, expected {:.2f} x N under the fitted Q, N, B\n", d.straight.bias_factor)
             : std::string(tr("; biased (the flicker term is not linear in t)\n"));
  }
  if (r.b100.B.valid)
    s += trf(
        "  B from {:g}-s averages (AV at {:g} s minus the fitted white and other non-B terms): {}{} °/h [{}, {}] (EDF "
        "{:.3g}); "
        "vs AV fit {:+.1f} sigma\n",
        r.b100.tau_s, r.b100.tau_s, r.b100.B.resolved ? "" : "< ", num(r.b100.B.value, 3), num(r.b100.B.low, 3),
        num(r.b100.B.high, 3), r.b100.edf, r.B_100s_discrepancy_sigma);
  else
    s += tr("  B from 100-s averages: record too short\n");
  if (r.avg100.spread.valid && r.avg100.expected > 0)
    s += trnf(
        "  spread of {:g}-s mean rates ({} block): {} ± {} °/h; expected from the fitted model {} ± {} °/h; "
        "{:+.1f} sigma\n",
        "  spread of {:g}-s mean rates ({} blocks): {} ± {} °/h; expected from the fitted model {} ± {} °/h; "
        "{:+.1f} sigma\n",
        r.avg100.blocks, r.avg100.block_s, r.avg100.blocks, num(r.avg100.spread.value, 3),
        num(r.avg100.spread.sigma, 2), num(r.avg100.expected, 3), num(r.avg100.expected_sigma, 2),
        r.B_100s_vs_model_sigma);
  s += "\n";
  return s;
}

}  // namespace

static std::string format_verdict(const AnalysisResult& r);

std::string format_report(const AnalysisResult& r) {
  std::string s;
  s += data_section(r);
  s += allan_section(r);
  s += fit_section(r);
  s += slope_section(r);
  s += cross_check_section(r);
  s += r.verdict_applies ? format_verdict(r) : trf("Verdict: not given ({})\n\n", r.not_applied_reason);
  s +=
      tr("Conventions: Q = rms white angle error, sigma² = 3Q²/tau² (IEEE 952; the paper's eq. (2) Q is √3·Q);\n"
         "  N = sigma(1 h) of the −½ line; B from sigma² = (2 ln2/π)·B², floor 0.6643·B (the paper prints B for B²);\n"
         "  K = sigma(3 h) of the +½ line; R from sigma² = R²tau²/2; 1 °/h = 1 arcsec/s.\n");
  return s;
}

std::string option_value_words(std::string_view option, const std::string& value) {
  struct Words {
    const char* option;
    const char* value;
    const char* words;
  };
  static constexpr Words kWords[] = {
      {"--b-estimate", "fit", N_("the five-term fit")},
      {"--b-estimate", "sigma-min", N_("the minimum of the Allan deviation")},
      {"--b-estimate", "avg100", N_("the 100-s averages")},
      {"--input", "pulses", N_("pulse increments")},
      {"--input", "counter", N_("a wrapping counter")},
      {"--input", "angle", N_("cumulative angle")},
      {"--input", "rate", N_("rate samples")},
      {"--input", "increment", N_("angle or velocity increments")},
      {"--outliers", "keep", N_("kept in the analysis")},
      {"--outliers", "remove", N_("removed")},
      {"--outliers", "replace", N_("replaced by the median of their neighbours")},
      {"--readout", "auto", N_("chosen by the data (counter or white)")},
      {"--readout", "counter", N_("a plain counter's sawtooth")},
      {"--readout", "white", N_("white angle noise (dithered counter)")},
  };
  for (const auto& w : kWords)
    if (option == w.option && value == w.value) return tr(w.words);
  return value;
}

static std::string format_verdict(const AnalysisResult& r) {
  std::string s;
  const auto& v = r.verdict;
  s += trf("Verdict ({}; B from {}{})\n", tr(v.table_name), option_value_words("--b-estimate", v.b_estimate),
           v.tolerance_pct > 0 ? trf("; heading-gyro tolerance +{:g} % on B", v.tolerance_pct)
                               : std::string(tr("; strict limits")));
  if (v.withheld)  // no class and no probability from a rejected fit
    return s + trf("  {}\n  why: {}\n  next: {}\n\n", v.statement(), v.withheld_reason, as_typed(v.next_command));
  s += verdict_param_line(v, v.B);
  s += verdict_param_line(v, v.N);
  s += trf("  overall: {}", v.statement());
  if (v.cls != v.cls_strict) s += trf("  [with the tolerance; strict: class {}]", class_label(v.cls_strict));
  s += "\n\n";
  return s;
}

}  // namespace rwcalc
