// The reader of what the report and the figures show (shown_results.hpp): every key of the
// analysis, batch, diagnosis and IMU JSON that the report layer uses is named in this file only.
#include "shown_results.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "rwcalc/units.hpp"

namespace rwcalc::shown {

namespace {

using nlohmann::json;

/// The member `key` of an object; null for a missing key or a value that is no object.
const json& at(const json& j, std::string_view key) {
  static const json null_json;
  if (!j.is_object()) return null_json;
  const auto it = j.find(key);
  return it == j.end() ? null_json : *it;
}

std::optional<double> num(const json& j) {
  if (!j.is_number()) return std::nullopt;
  const double v = j.get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::optional<double> num(const json& j, std::string_view key) { return num(at(j, key)); }

std::string str(const json& j, std::string_view key) {
  const auto& v = at(j, key);
  return v.is_string() ? v.get<std::string>() : std::string();
}

std::optional<bool> boolean(const json& j, std::string_view key) {
  const auto& v = at(j, key);
  return v.is_boolean() ? std::optional<bool>(v.get<bool>()) : std::nullopt;
}

bool is_true(const json& j, std::string_view key) { return boolean(j, key).value_or(false); }

ClassValue class_value(const json& c) {
  if (c.is_number_integer()) return {ClassValue::Kind::Number, c.get<int>()};
  if (c.is_null()) return {ClassValue::Kind::Outside, 0};
  return {ClassValue::Kind::NotAvailable, 0};
}

CoefficientValues coefficient_values(const json& c) {
  CoefficientValues r;
  r.value = num(c, "value");
  r.sigma = num(c, "sigma");
  r.low95 = num(c, "low95");
  r.high95 = num(c, "high95");
  r.resolved = boolean(c, "resolved");
  r.in_model = boolean(c, "in_model");
  r.model_value = num(c, "model_value");
  r.estimate = num(c, "estimate");
  r.unit = str(c, "unit");
  return r;
}

Coefficient coefficient(const json& c) {
  Coefficient r{coefficient_values(c), std::nullopt};
  if (const auto& si = at(c, "si"); si.is_object()) r.si = coefficient_values(si);
  return r;
}

Fit read_fit(const json& f) {
  static constexpr std::array<const char*, 5> kKeys{"Q", "N", "B", "K", "R"};  // by Term
  Fit r;
  r.present = f.is_object();
  for (std::size_t k = 0; k < kKeys.size(); ++k) r.terms[k] = coefficient(at(f, kKeys[k]));
  r.chi2_per_dof = num(f, "chi2_per_dof");
  r.p_value = num(f, "p_value");
  r.tau_min_s = num(f, "tau_min_s");
  r.tau_max_s = num(f, "tau_max_s");
  r.interval_scale = num(f, "interval_scale");
  if (const auto& range = at(f, "range"); range.is_object()) r.range_reason = str(range, "reason");
  r.intervals_scaled = is_true(f, "intervals_scaled");
  return r;
}

DirectN read_direct(const json& d) {
  DirectN r{coefficient(d), {}, std::nullopt, std::nullopt};
  if (const auto& curve = at(d, "curve"); curve.is_array())
    for (const auto& p : curve)
      if (const auto t = num(p, "t_s"), v = num(p, "var"); t && v) r.curve.emplace_back(*t, *v);
  r.slope = num(d, "slope");
  r.intercept = num(d, "intercept");
  return r;
}

/// A JSON array of numbers as they are (no finiteness check: a probability is shown as computed);
/// not available when anything else is in it.
template <class T>
std::optional<std::vector<T>> numbers(const json& a) {
  if (!a.is_array()) return std::nullopt;
  std::vector<T> r;
  for (const auto& e : a) {
    if (!e.is_number() && !e.is_boolean()) return std::nullopt;
    r.push_back(e.get<T>());
  }
  return r;
}

std::vector<ClassLimit> limits(const json& verdict, const char* parameter) {
  std::vector<ClassLimit> r;
  const auto& classes = at(verdict, "classes");
  const auto& values = at(at(verdict, parameter), "limits");
  if (classes.is_array() && values.is_array() && classes.size() == values.size())
    for (std::size_t i = 0; i < classes.size(); ++i)
      if (const auto l = num(values[i]); classes[i].is_number_integer() && l && *l > 0)
        r.push_back({classes[i].get<int>(), *l});
  return r;
}

Outliers read_outliers(const json& o) {
  Outliers r;
  r.present = o.is_object();
  r.action = str(o, "action");
  r.count = num(o, "count");
  r.removed = num(o, "removed");
  r.replaced = num(o, "replaced");
  r.threshold_robust_z = num(o, "threshold_robust_z");
  if (const auto& positions = at(o, "positions"); positions.is_array())
    for (const auto& p : positions) r.positions.push_back({num(p, "line"), num(p, "time_s"), num(p, "value")});
  return r;
}

Segments read_segments(const json& s) {
  Segments r;
  r.count = num(s, "count");
  for (const auto& gap : at(s, "gaps")) r.gaps.push_back({num(gap, "line"), num(gap, "missing_s")});
  for (const auto& d : at(s, "durations_s")) r.durations_s.push_back(num(d));
  return r;
}

Allan read_allan(const json& a) {
  Allan r;
  r.unit = str(a, "unit");
  r.confidence = num(a, "confidence");
  r.unit_per_si = num(a, "unit_per_si");
  if (const auto& pts = at(a, "points"); pts.is_array())
    for (const auto& p : pts)
      r.points.push_back({num(p, "tau_s"), num(p, "dev"), num(p, "dev_low"), num(p, "dev_high")});
  return r;
}

std::vector<Warning> read_warnings(const json& w) {
  std::vector<Warning> r;
  if (w.is_array())
    for (const auto& x : w) r.push_back({str(x, "code"), str(x, "message"), str(x, "command")});
  return r;
}

/// The band of the base or the extended model: `base_model.band` / `extended_model.band`, or the
/// top-level `band` / `band_extended` that `rwcalc diagnose --json` writes.
std::optional<std::vector<BandPoint>> read_band(const json& d, bool extended) {
  const auto& nested = at(at(d, extended ? "extended_model" : "base_model"), "band");
  const auto& band = nested.is_array() ? nested : at(d, extended ? "band_extended" : "band");
  if (!band.is_array()) return std::nullopt;
  std::vector<BandPoint> r;
  for (const auto& p : band)
    r.push_back({num(p, "tau_s"), num(p, "dev"), num(p, "band_low"), num(p, "band_high"), num(p, "median")});
  return r;
}

std::vector<Finding> read_findings(const json& findings) {
  std::vector<Finding> r;
  if (!findings.is_array()) return r;
  for (const auto& f : findings) {
    Finding finding{str(f, "effect"), {}};
    if (const auto& ps = at(f, "parameters"); ps.is_object())
      for (const auto& [k, p] : ps.items()) {
        // A parameter is shown as computed (no finiteness check), as the diagnosis wrote it.
        const auto& v = at(p, "value");
        const auto& u = at(p, "standard_uncertainty");
        finding.parameters.push_back({k, str(p, "unit"), v.is_number() ? std::optional(v.get<double>()) : std::nullopt,
                                      u.is_number() ? std::optional(u.get<double>()) : std::nullopt});
      }
    r.push_back(std::move(finding));
  }
  return r;
}

std::optional<NoiseWorst> read_worst(const json& worst) {
  if (!worst.is_object()) return std::nullopt;
  return NoiseWorst{num(worst, "noise_density"), num(worst, "random_walk"), str(worst, "noise_density_axis"),
                    str(worst, "random_walk_axis")};
}

}  // namespace

Verdict read_verdict(const json& v) {
  Verdict r;
  r.present = v.is_object();
  r.cls = class_value(at(v, "class"));
  r.class_B = class_value(at(v, "class_B"));
  r.class_N = class_value(at(v, "class_N"));
  r.withheld = is_true(v, "withheld");
  r.tolerance_changed = is_true(v, "tolerance_changed");
  r.statement = str(v, "statement");
  r.statement_B = str(v, "statement_B");
  r.statement_N = str(v, "statement_N");
  r.by_B_statement = str(at(v, "B"), "statement");
  r.by_N_statement = str(at(v, "N"), "statement");
  r.reason = str(v, "reason");
  r.command = str(v, "command");
  r.table = str(v, "table");
  r.b_estimate = str(v, "b_estimate");
  r.p_class = num(v, "p_class");
  r.tolerance_pct = num(v, "tolerance_pct");
  r.p_is = numbers<double>(at(v, "p_is"));
  r.classes = numbers<int>(at(v, "classes"));
  r.limits_B = limits(v, "B");
  r.limits_N = limits(v, "N");
  return r;
}

std::optional<double> read_temperature(const json& j) { return num(j); }

Analysis read_analysis(const json& j) {
  Analysis r;
  r.source = str(j, "source");
  r.column = str(j, "column");
  r.sensor = str(j, "sensor");
  r.rate_unit = str(at(j, "units"), "rate");
  r.temperature_c = num(j, "temperature_c");
  r.samples = num(j, "samples");
  r.rate_hz = num(j, "rate_hz");
  r.duration_s = num(j, "duration_s");
  r.mean_rate = num(j, "mean_rate");
  r.earth_rate = num(j, "earth_rate");
  r.bias = num(j, "bias");
  const auto& input = at(j, "input");
  static constexpr std::array<const char*, 4> kIdKeys{"serial", "operator", "test_date", "conditions"};  // by Id
  for (std::size_t k = 0; k < kIdKeys.size(); ++k) r.identification[k] = str(at(input, "identification"), kIdKeys[k]);
  r.sha256 = str(input, "sha256");
  r.file_bytes = num(input, "file_bytes");
  r.segments = read_segments(at(j, "segments"));
  r.outliers = read_outliers(at(j, "outliers"));
  r.warnings = read_warnings(at(j, "warnings"));
  r.fit = read_fit(at(j, "fit"));
  r.n_direct = read_direct(at(at(j, "methods"), "N_direct"));
  r.b_100s = coefficient(at(at(j, "methods"), "B_100s"));
  r.verdict = read_verdict(at(j, "verdict"));
  r.allan = read_allan(at(j, "allan"));
  // "units" says where the JSON names its units (docs/result-json.md); the report names each unit itself.
  static constexpr std::array<std::string_view, 9> kDefined{"Q",         "N",        "B",    "K", "R", "deviation_unit",
                                                            "intervals", "rounding", "units"};
  if (const auto& c = at(j, "conventions"); c.is_object())
    for (const auto& item : c.items())
      if (std::find(kDefined.begin(), kDefined.end(), item.key()) == kDefined.end())
        r.other_conventions.emplace_back(item.key(), item.value());
  return r;
}

std::vector<Analysis> read_analyses(const std::vector<json>& runs) {
  std::vector<Analysis> r;
  r.reserve(runs.size());
  for (const auto& run : runs) r.push_back(read_analysis(run));
  return r;
}

std::optional<Verdict> read_overall(const json& j) {
  if (!j.is_object()) return std::nullopt;
  return read_verdict(j);
}

std::vector<std::optional<Diagnosis>> read_diagnoses(const std::vector<json>& diagnoses) {
  std::vector<std::optional<Diagnosis>> r;
  r.reserve(diagnoses.size());
  for (const auto& d : diagnoses) r.push_back(d.is_object() ? std::optional(read_diagnosis(d)) : std::nullopt);
  return r;
}

std::vector<Analysis> read_runs(const json& runs) {
  std::vector<Analysis> r;
  if (runs.is_array())
    for (const auto& run : runs) r.push_back(read_analysis(run));
  return r;
}

const json& batch_runs(const json& batch) { return batch.is_array() ? batch : at(batch, "runs"); }

Diagnosis read_diagnosis(const json& d) {
  Diagnosis r;
  r.outliers = read_outliers(at(d, "outliers"));
  r.findings = read_findings(at(d, "findings"));
  if (const auto& gain = at(d, "gain"); gain.is_object())
    r.gain = Gain{num(gain, "misfit_base"),       num(gain, "misfit_extended"),      num(gain, "coverage_base"),
                  num(gain, "coverage_extended"), num(gain, "likelihood_in_sample"), num(gain, "likelihood_holdout")};
  r.band = read_band(d, false);
  r.band_extended = read_band(d, true);
  r.band_level = num(at(d, "base_model"), "band_level");
  r.band_level_extended = num(at(d, "extended_model"), "band_level");
  if (const auto& band_unit = at(at(d, "units"), "band"); band_unit.is_string())
    r.band_unit = band_unit.get<std::string>();
  return r;
}

Imu read_imu(const json& j) {
  Imu r;
  r.source = str(j, "source");
  r.rate_hz = num(j, "rate_hz");
  r.duration_s = num(j, "duration_s");
  if (const auto& samples = at(j, "samples"); samples.is_number()) r.samples = samples.dump();
  const auto& channels = at(j, "channels");
  if (channels.is_array())
    for (const auto& c : channels) r.channels.push_back(read_analysis(c));
  r.gyro_worst = read_worst(at(at(at(j, "noise"), "gyro"), "worst"));
  r.accelerometer_worst = read_worst(at(at(at(j, "noise"), "accelerometer"), "worst"));
  return r;
}

std::string temperature_label(std::optional<double> t) {
  if (!t) return {};
  return fmt::format("{}{:g} {}", *t > 0 ? "+" : *t < 0 ? "−" : "", std::fabs(*t), units::label::celsius);
}

std::vector<ClassLimit> class_limits(const Verdict& v, char parameter) {
  const auto& given = parameter == 'B' ? v.limits_B : v.limits_N;
  if (!given.empty()) return given;
  if (parameter == 'B') return {{1, 0.005}, {2, 0.008}, {3, 0.015}};
  return {{1, 0.0010}, {2, 0.0015}, {3, 0.0030}};
}

std::vector<std::size_t> by_temperature(const std::vector<Analysis>& runs) {
  std::vector<std::size_t> idx(runs.size());
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    const auto ta = runs[a].temperature_c, tb = runs[b].temperature_c;
    if (ta && tb) return *ta < *tb;
    return ta.has_value() && !tb.has_value();
  });
  return idx;
}

}  // namespace rwcalc::shown
