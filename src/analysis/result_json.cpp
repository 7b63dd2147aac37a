// The JSON of an analysis: one schema for every sensor kind and shown unit (docs/result-json.md,
// docs/result.schema.json). Keys carry no unit; the "units" object names the unit of each family
// of quantities, and every coefficient object carries its own "unit" too.
#include <cmath>
#include <optional>

#include "fit_range.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/imu.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/outlier_screen.hpp"
#include "rwcalc/sensor.hpp"

namespace rwcalc {

namespace {

using nlohmann::json;

json opt_num(const std::optional<double>& v, double factor = 1) { return v ? json(*v * factor) : json(nullptr); }

std::string_view range_source_name(FitRangeChoice::Source s) {
  switch (s) {
    case FitRangeChoice::Source::Option: return "option";
    case FitRangeChoice::Source::ShortTau: return "short_tau_check";
    case FitRangeChoice::Source::All: break;
  }
  return "all";
}

/// The shown units and the factors from the fit's scale into them, for one analysis.
struct Shown {
  const UnitSet& units;
  UnitSet si;
  [[nodiscard]] double rate() const { return units.deviation.factor; }
  [[nodiscard]] double phase() const { return units[Term::Q].factor; }
};

json coef_json(const Coefficient& c, const ShownUnit& u) {
  const double f = u.factor;
  return {{"value", c.value * f},   {"sigma", c.sigma * f},   {"low95", c.low * f},
          {"high95", c.high * f},   {"resolved", c.resolved}, {"estimate", c.estimate * f},
          {"in_model", c.in_model}, {"fitted", c.enabled},    {"model_value", c.curve * f},
          {"unit", u.ascii}};
}

json method_json(const MethodEstimate& m, const ShownUnit& u) {
  if (!m.valid) return nullptr;
  const double f = u.factor;
  return {{"value", m.value * f},   {"sigma", m.sigma * f}, {"low95", m.low * f},        {"high95", m.high * f},
          {"resolved", m.resolved}, {"unit", u.ascii},      {"estimate", m.estimate * f}};
}

/// The spectral lines taken off the fit's points; rms in units.rate.
json spectral_lines_json(const FitRangeChoice& range, const Shown& sh) {
  json lines = json::array();
  for (const auto& l : range.lines)
    lines.push_back({{"frequency_hz", l.f_hz},
                     {"rms", l.rms * sh.rate()},
                     {"peak_over_local_level", l.peak_ratio},
                     {"max_share_of_av", l.max_share},
                     {"tau_at_max_share_s", l.tau_at_max_s}});
  return lines;
}

json range_json(const AnalysisResult& r, const Shown& sh) {
  const auto& c = r.fit_range;
  return {{"tau_min_s", c.tau_min_s},
          {"tau_max_s", std::isinf(c.tau_max_s) ? json(nullptr) : json(c.tau_max_s)},
          {"chosen_by", range_source_name(c.source)},
          {"reason", c.reason()},
          {"shortest_tau_ratio", c.shortest_ratio},
          {"filter_time_constant_s", c.filter_tc_s},
          {"departure_tau_s", c.departure_tau_s},
          {"departure_ratio", c.departure_ratio},
          {"reference_tau_min_s", c.reference_tau_s},
          {"spectral_lines", spectral_lines_json(c, sh)},
          {"line_points_left_out", c.line_points_left_out},
          {"rejected_chi2_per_dof", c.rejected_chi2},
          {"rejected_from_tau_s", c.rejected_from_tau_s}};
}

/// Each term's coefficient in the shown unit, with its meaning for the sensor and its SI twin.
json fit_json(const AnalysisResult& r, const Shown& sh) {
  const auto& f = r.fit;
  json j = json::object();
  for (const Term t : kAllTerms) {
    json c = coef_json(f[t], sh.units[t]);
    c["meaning"] = std::string(term_meaning(r.sensor, t));
    c["si"] = coef_json(f[t], sh.si[t]);
    c["termination"] = to_json(f[t].termination);  // how its bounds' profile searches ended
    j[std::string(term_name(t))] = std::move(c);
  }
  j.update(json{{"chi2_per_dof", f.chi2_per_dof},
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
                {"range", range_json(r, sh)},
                {"misfit", misfit_json(r)},
                {"intervals_scaled", r.fit_range.intervals_scaled},
                {"interval_scale", r.fit_range.interval_scale}});
  return j;
}

json warnings_json(const AnalysisResult& r) {
  json warnings = json::array();
  for (const auto& w : r.warnings)
    warnings.push_back({{"code", w.code}, {"message", w.message}, {"command", w.command}});
  return warnings;
}

json allan_bounds_json(const AnalysisResult& r, const Shown& sh) {
  json allan = allan_json(r.allan, sh.rate(), sh.units.deviation.ascii);
  allan["bounds"] = r.model_bounds ? "fitted model: EDF = 2 sigma^4/Var(sigma^2 estimate), alpha of the leading term"
                                   : "Stable32 noise identification and Greenhall-Riley EDF";
  // The deviation's unit per SI unit: what a figure scales the SI model (fit.X.si) by.
  allan["unit_per_si"] = sh.rate() / sh.si.deviation.factor;
  return allan;
}

/// Direct N: the unbiased estimate, its regression curve (the seed paper's Fig. 2) and, for the
/// figure, the paper's straight line. The regression's variances are in units.phase squared.
json direct_n_json(const AnalysisResult& r, const Shown& sh) {
  json n_direct = method_json(r.direct.N, sh.units[Term::N]);
  if (n_direct.is_null()) return n_direct;
  const double f2 = sh.phase() * sh.phase();
  n_direct["estimator"] = "overlapping increments, regression on the exact expectations of Q, N, B";
  n_direct["interval"] = "parametric bootstrap";
  n_direct["replicates"] = r.direct.replicates;
  n_direct["discrepancy_sigma"] = r.N_direct_discrepancy_sigma;
  n_direct["Q2"] = r.direct.q2_arcsec2 * f2;
  n_direct["N2"] = r.direct.n2_arcsec2_per_s * f2;
  n_direct["B2"] = r.direct.b2_arcsec2_per_s2 * f2;
  // The points of the regression (the seed paper's Fig. 2): interval length, number of
  // overlapping increments, their variance about the mean (Earth rate and bias removed) and the
  // regression's value there. The line drawn with them is the paper's straight line.
  json curve = json::array();
  for (std::size_t i = 0; i < r.direct.points.size(); ++i) {
    const auto& p = r.direct.points[i];
    const auto& g = r.direct.basis[i];
    curve.push_back(
        {{"t_s", p.t_s},
         {"intervals", p.intervals},
         {"var", p.var_arcsec2 * f2},
         {"model",
          (g.q * r.direct.q2_arcsec2 + g.n * r.direct.n2_arcsec2_per_s + g.b * r.direct.b2_arcsec2_per_s2) * f2}});
  }
  n_direct["curve"] = std::move(curve);
  n_direct["t_min_s"] = r.direct.points.front().t_s;
  n_direct["t_max_s"] = r.direct.points.back().t_s;
  if (r.direct.straight.valid) {
    n_direct["intercept"] = r.direct.straight.intercept_arcsec2 * f2;
    n_direct["slope"] = r.direct.straight.slope_arcsec2_per_s * f2;
  }
  return n_direct;
}

json methods_json(const AnalysisResult& r, const Shown& sh) {
  const double f2 = sh.phase() * sh.phase(), r2 = sh.rate() * sh.rate();
  json straight = nullptr;
  if (r.direct.straight.valid)
    straight = {{"value", r.direct.straight.value * sh.units[Term::N].factor},
                {"unit", sh.units[Term::N].ascii},
                {"intercept", r.direct.straight.intercept_arcsec2 * f2},
                {"slope", r.direct.straight.slope_arcsec2_per_s * f2},
                {"bias_factor", r.direct.straight.bias_factor},
                {"note", "biased: expected value/true N = bias_factor under the fitted Q, N, B"}};
  json b100 = method_json(r.b100.B, sh.units[Term::B]);
  if (!b100.is_null()) {
    b100["estimator"] = "overlapping AV at the block length minus the fitted terms other than B";
    b100["tau_s"] = r.b100.tau_s;
    b100["avar"] = r.b100.var * r2;
    b100["white_removed"] = r.b100.white * r2;
    b100["edf"] = r.b100.edf;
    b100["discrepancy_sigma"] = r.B_100s_discrepancy_sigma;
  }
  json spread = method_json(r.avg100.spread, sh.units.deviation);
  if (!spread.is_null()) {
    spread["blocks"] = r.avg100.blocks;
    spread["block_s"] = r.avg100.block_s;
    spread["expected"] = r.avg100.expected * sh.rate();
    spread["expected_sigma"] = r.avg100.expected_sigma * sh.rate();
    spread["discrepancy_model_sigma"] = r.B_100s_vs_model_sigma;
  }
  return {{"N_direct", direct_n_json(r, sh)},
          {"N_straight_line_paper", straight},
          {"B_100s", b100},
          {"spread_100s", spread}};
}

json slope_json(const AnalysisResult& r, const Shown& sh) {
  const double b = sh.units[Term::B].factor;
  return {{"N", opt_num(r.slope.N, sh.units[Term::N].factor)},
          {"tau_N_s", r.slope.tau_N_s},
          {"B", opt_num(r.slope.B, b)},
          {"B_sigma", r.slope_B_sigma * b},
          {"B_low95", r.b_min.B.valid ? json(r.b_min.B.low * b) : json(nullptr)},
          {"B_high95", r.b_min.B.valid ? json(r.b_min.B.high * b) : json(nullptr)},
          {"B_edf", r.b_min.edf},
          {"B_bias_factor", r.b_min.bias_factor},
          {"sigma_min", r.slope.sigma_min * sh.rate()},
          {"tau_min_s", r.slope.tau_min_s},
          {"K", opt_num(r.slope.K, sh.units[Term::K].factor)},
          {"tau_K_s", r.slope.tau_K_s}};
}

/// The unit of each family of quantities (docs/result-json.md).
json units_json(const Shown& sh) {
  json u = {{"rate", sh.units.deviation.ascii}, {"phase", sh.units[Term::Q].ascii}};
  for (const Term t : kAllTerms) u[std::string(term_name(t))] = sh.units[t].ascii;
  return u;
}

json conventions_json() {
  return {{"Q",
           "rms white angle (velocity) error, sigma^2 = 3 Q^2/tau^2 (IEEE 952); the paper's eq. (2) Q is "
           "sqrt(3) Q"},
          {"N", "sigma^2 = N^2/tau; N = sigma at tau = 1 h"},
          {"B", "sigma^2 = (2 ln2/pi) B^2, floor 0.6643 B (the paper prints B where B^2 is meant)"},
          {"K", "sigma^2 = K^2 tau/3; K = sigma at tau = 3 h"},
          {"R", "sigma^2 = R^2 tau^2/2"},
          {"units",
           "keys carry no unit: units.rate is the unit of the mean, Earth rate, bias, Allan deviation and "
           "spectral lines; units.Q..R of each term wherever it appears; units.phase (squared) of the direct "
           "method's variances; every coefficient object names its own unit"},
          {"intervals", "95 % profile-likelihood; resolved=false: value is the 95 % upper bound"}};
}

json verdict_json(const AnalysisResult& r) {
  if (r.sensor != SensorKind::Gyro) return nullptr;  // accelerometers have no class table
  json v = to_json(r.verdict);
  if (!r.not_applied_reason.empty()) v["applies"] = r.verdict_applies;
  return v;
}

json fields_json(const AnalysisResult& r, const Shown& sh) {
  const double f = sh.rate();
  return {{"schema_version", json_input::kResultSchemaVersion},
          {"source", r.source},
          {"column", r.column},
          {"sensor", std::string(to_string(r.sensor))},
          {"units", units_json(sh)},
          {"input", r.input},
          {"samples", r.samples},
          {"rate_hz", r.rate_hz},
          {"duration_s", r.duration_s},
          {"temperature_c", opt_num(r.temperature_c)},
          {"temperature_source", r.temperature_source},
          {"mean_rate", r.mean_rate_deg_per_h * f},
          {"earth_rate", r.earth_rate_deg_per_h * f},
          {"latitude_deg", r.earth_rate_given || !r.earth_rate_applied ? json(nullptr) : json(r.latitude_deg)},
          {"bias", r.bias_deg_per_h * f},
          {"segments", segments_json(r)},
          {"warnings", warnings_json(r)},
          {"allan", allan_bounds_json(r, sh)},
          {"fit", fit_json(r, sh)},
          {"slope_readout", slope_json(r, sh)},
          {"methods", methods_json(r, sh)},
          {"outliers", to_json(r.outliers, f)},
          {"verdict", verdict_json(r)},
          {"conventions", conventions_json()}};
}

}  // namespace

nlohmann::json allan_json(const AllanResult& a, double factor, const std::string& unit) {
  json pts = json::array();
  for (const auto& p : a.points)
    pts.push_back({{"m", p.m},
                   {"tau_s", p.tau_s},
                   {"n", p.n},
                   {"alpha", p.alpha},
                   {"edf", p.edf},
                   {"var", p.var * factor * factor},
                   {"dev", p.dev * factor},
                   {"dev_low", p.dev_low * factor},
                   {"dev_high", p.dev_high * factor}});
  return {{"estimator", std::string(to_string(a.estimator))},
          {"unit", unit},
          {"tau0_s", a.tau0_s},
          {"points_in", a.points_in},
          {"confidence", a.confidence},
          {"points", pts}};
}

nlohmann::json allan_json(const AllanResult& a) { return allan_json(a, 1.0, a.unit); }

nlohmann::json to_json(const AnalysisResult& r, const UnitSet& shown) {
  const Shown sh{shown, si_units(r.sensor)};
  json j = fields_json(r, sh);
  if (!r.not_applied_reason.empty()) {  // keys present only when something is off
    j["earth_rate_subtracted"] = r.earth_rate_applied;
    j["not_applied_reason"] = r.not_applied_reason;
  }
  return j;
}

nlohmann::json to_json(const AnalysisResult& r) { return to_json(r, output_units(r.sensor)); }

nlohmann::json segments_json(const AnalysisResult& r) {
  if (r.segments.size() < 2) return nullptr;
  json samples = json::array(), durations = json::array(), gaps = json::array();
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

}  // namespace rwcalc
