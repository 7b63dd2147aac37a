// The results of the diagnosis as JSON (`rwcalc diagnose --json`, docs/diagnosis.md) and as the
// readable report.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "rwcalc/diagnose.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/sensor.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

using nlohmann::json;

namespace {

/// The units a diagnosis is shown in. A gyro's numbers are the fit's own (°/h, ″), as they always
/// were; an accelerometer's are the fit's twins (m/s in place of °, units.hpp), shown in its usual
/// units (sensor.hpp): levels, amplitudes, steps and σ in µg, ramps in m/s/h².
struct Shown {
  bool accel = false;
  UnitSet units;
  explicit Shown(const DiagnoseResult& r)
      : accel(r.analysis.sensor == SensorKind::Accelerometer), units(output_units(r.analysis.sensor)) {}
  [[nodiscard]] double level(double v) const { return accel ? v * units.deviation.factor : v; }
};

/// A JSON key's unit part from a unit's ASCII name: "m/s/h^2" → "m_per_s_per_h2", "ug" → "ug".
std::string key_suffix(std::string a) {
  std::string out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.compare(i, 5, "sqrt(") == 0) {
      out += "sqrt_";
      i += 4;
    } else if (a[i] == '/') {
      out += "_per_";
    } else if (a[i] != '^' && a[i] != ')') {
      out += a[i];
    }
  }
  return out;
}

/// A simulated model with its band and how well the measurement sits in it.
json model_json(const NoiseModel& model, const std::vector<BandPoint>& band, double level, double misfit,
                double coverage, const Shown& sh) {
  json m;
  to_json(m, model);
  m["band"] = json::array();
  for (const auto& b : band)
    m["band"].push_back({{"tau_s", b.tau_s},
                         {"dev", sh.level(b.dev)},
                         {"band_low", sh.level(b.low)},
                         {"band_high", sh.level(b.high)},
                         {"median", sh.level(b.median)},
                         {"edf", b.edf}});
  m["band_level"] = level;
  m["misfit"] = misfit;
  m["coverage"] = coverage;
  return m;
}

/// Non-finite numbers become 0 (JSON has none).
json clean_json(json j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>()) ? j.get<double>() : 0.0;
  if (j.is_object() || j.is_array())
    for (auto& v : j) v = clean_json(v);
  return j;
}

/// A figure not computed (NaN) is null in the JSON.
json finite_or_null(double x) { return std::isnan(x) ? json(nullptr) : json(x); }

/// N, B, K and R of a model, as the report prints them.
std::string power_laws(const NoiseModel& m, const Shown& sh) {
  const UnitSet& u = sh.units;  // gyro: °/√h, °/h, °/h/√h, °/h² at factor 1
  return fmt::format("N = {:.4g} {}, B = {:.4g} {}, K = {:.4g} {}, R = {:.4g} {}",
                     m.arw_deg_per_sqrt_h * u[Term::N].factor, localized_label(u[Term::N]),
                     m.bias_instability_deg_per_h * u[Term::B].factor, localized_label(u[Term::B]),
                     m.rrw_deg_per_h_per_sqrt_h * u[Term::K].factor, localized_label(u[Term::K]),
                     m.ramp_deg_per_h2 * u[Term::R].factor, localized_label(u[Term::R]));
}

/// The N, B, K and R of a model under keys named with the accelerometer's units.
json coefficients_json(const NoiseModel& m, const Shown& sh) {
  const UnitSet& u = sh.units;
  return {{"N_" + key_suffix(u[Term::N].ascii), m.arw_deg_per_sqrt_h * u[Term::N].factor},
          {"B_" + key_suffix(u[Term::B].ascii), m.bias_instability_deg_per_h * u[Term::B].factor},
          {"K_" + key_suffix(u[Term::K].ascii), m.rrw_deg_per_h_per_sqrt_h * u[Term::K].factor},
          {"R_" + key_suffix(u[Term::R].ascii), m.ramp_deg_per_h2 * u[Term::R].factor}};
}

/// A finding parameter's unit as shown: its ASCII name (JSON), its label (text) and the factor
/// from the fit's units.
struct ParameterUnit {
  std::string ascii, label;
  double factor = 1;
};

ParameterUnit unit_of(Quantity q, const Shown& sh) {
  switch (q) {
    case Quantity::Frequency: return {"Hz", tr("Hz"), 1};
    case Quantity::Time: return {"s", tr("s"), 1};
    case Quantity::Phase: return {"rad", tr("rad"), 1};
    case Quantity::Rate: break;
  }
  if (sh.accel) return {sh.units.deviation.ascii, localized_label(sh.units.deviation), sh.units.deviation.factor};
  return {"deg/h", tr("°/h"), 1};
}

/// A finding's parameters under their names, each with its value, unit, standard uncertainty and
/// 95 % interval (null where not estimated): one shape for every sensor and unit.
json parameters_json(const Finding& f, const Shown& sh) {
  json out = json::object();
  for (const auto& p : f.parameters) {
    const ParameterUnit u = unit_of(p.quantity, sh);
    const auto shown = [&](double x) { return std::isnan(x) ? json(nullptr) : json(x * u.factor); };
    out[p.name] = {{"value", p.value * u.factor},
                   {"unit", u.ascii},
                   {"standard_uncertainty", shown(p.standard_uncertainty)},
                   {"interval95",
                    std::isnan(p.low95) ? json(nullptr) : json::array({shown(p.low95), shown(p.high95)})}};
  }
  return out;
}

/// One line per finding: its parameters with their standard uncertainties and units.
std::string format_findings(const std::vector<Finding>& fs, const Shown& sh) {
  std::string s;
  for (const auto& f : fs) {
    s += fmt::format("  {}:", finding_name(f.effect));
    for (const auto& p : f.parameters) {
      const ParameterUnit u = unit_of(p.quantity, sh);
      s += fmt::format(" {} = {:.4g}", p.name, p.value * u.factor);
      if (!std::isnan(p.standard_uncertainty)) s += fmt::format(" ± {:.2g}", p.standard_uncertainty * u.factor);
      s += fmt::format(" {};", u.label);
    }
    s.pop_back();
    s += "\n";
  }
  return s;
}

/// The named findings' names, comma-separated.
std::string named_terms(const std::vector<Finding>& fs) {
  std::string s;
  for (const auto& f : fs) s += (s.empty() ? "" : ", ") + std::string(finding_name(f.effect));
  return s;
}

/// How much B the base (the five-term model of the data with the named terms in them) has over B
/// without them (the extended model), %: a term the five-term fit cannot represent is taken up
/// into the flicker floor and moves the class verdict. NaN when nothing is named.
double b_excess_percent(const DiagnoseResult& r) {
  const double with = r.base.bias_instability_deg_per_h, without = r.extended.bias_instability_deg_per_h;
  if (r.findings.empty() || !(without > 0)) return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * (with / without - 1.0);
}

}  // namespace

namespace {

/// What an accelerometer's diagnosis states beside the gyro's keys: the column, the sensor kind,
/// the input's unit and the units of its numbers. The models keep the simulator's keys (`rwcalc
/// simulate --from` reads them), whose ° stands for m/s; their N, B, K, R are also given in the
/// accelerometer's units ("coefficients").
void accelerometer_json(const DiagnoseResult& r, const Shown& sh, json& j) {
  const UnitSet& u = sh.units;
  j["sensor"] = std::string(to_string(r.analysis.sensor));
  j["column"] = r.analysis.input.value("column", r.analysis.column);
  j["input_unit"] = r.analysis.input.value("unit", "");
  j["units"] = {{"level", u.deviation.ascii},
                {"ramp", u[Term::R].ascii},
                {"band", u.deviation.ascii},
                {"models",
                 "simulator keys in fit-scale units: m/s in place of deg (deg/h = m/s/h, arcsec = m/s/3600)"}};
  j.erase("scale_arcsec_per_pulse");
  j["simulation_quantum_m_per_s"] = r.settings.scale_arcsec / units::velocity_units_per_mps;
  const auto& f = r.analysis.fit;
  json fc = {{"Q_" + key_suffix(u[Term::Q].ascii), f[Term::Q].estimate * u[Term::Q].factor},
             {"chi2_per_dof", f.chi2_per_dof}};
  for (Term t : {Term::N, Term::B, Term::K, Term::R})
    fc[std::string(term_name(t)) + "_" + key_suffix(u[t].ascii)] = f[t].estimate * u[t].factor;
  j["base_model"]["fitted_coefficients"] = fc;
  j["base_model"]["coefficients"] = coefficients_json(r.base, sh);
  j["extended_model"]["coefficients"] = coefficients_json(r.extended, sh);
  const std::string b = "_" + key_suffix(u[Term::B].ascii);
  auto& named = j["bias_instability_named_terms"];
  named["with" + b] = r.base.bias_instability_deg_per_h * u[Term::B].factor;
  named["without" + b] = r.extended.bias_instability_deg_per_h * u[Term::B].factor;
  named.erase("with_deg_per_h");
  named.erase("without_deg_per_h");
}

}  // namespace

json to_json(const DiagnoseResult& r) {
  const Shown sh(r);
  json j;
  j["schema_version"] = json_input::kResultSchemaVersion;
  j["source"] = r.analysis.source;
  j["samples"] = r.analysis.samples;
  j["rate_hz"] = r.settings.rate_hz;
  j["duration_s"] = r.settings.duration_s;
  j["scale_arcsec_per_pulse"] = r.settings.scale_arcsec;
  j["temperature_c"] = r.analysis.temperature_c ? json(*r.analysis.temperature_c) : json(nullptr);
  j["runs"] = r.runs;
  j["seed"] = r.seed;
  j["false_alarm_level_per_detector"] = r.alpha;
  j["method"] = "likelihood";
  j["outliers"] = to_json(r.analysis.outliers, sh.level(1.0));  // in units.level for an accelerometer
  json base = model_json(r.base, r.base_band, r.band_level, r.gain.misfit_base, r.gain.coverage_base, sh);
  // Not under "fit": model_from_analysis_json would read those coefficients instead of this model.
  base["fitted_coefficients"] = {{"Q_arcsec", r.analysis.fit[Term::Q].estimate},
                                 {"N_deg_per_sqrt_h", r.analysis.fit[Term::N].estimate},
                                 {"B_deg_per_h", r.analysis.fit[Term::B].estimate},
                                 {"K_deg_per_h_per_sqrt_h", r.analysis.fit[Term::K].estimate},
                                 {"R_deg_per_h2", r.analysis.fit[Term::R].estimate},
                                 {"chi2_per_dof", r.analysis.fit.chi2_per_dof}};
  j["base_model"] = base;
  json det = json::array();
  for (const auto& d : r.detectors) {
    json o = {{"effect", std::string(detector_name(d.effect))},
              {"statistic", d.statistic},
              {"threshold", d.threshold},
              {"threshold_upper", d.threshold_upper},
              {"p_value", d.p_value},
              {"fired", d.fired},
              {"excess", d.excess},
              {"named", d.named}};
    if (!d.test.empty()) o["test"] = d.test;
    if (!d.note.empty()) o["note"] = d.note;
    det.push_back(o);
  }
  j["detectors"] = det;
  const auto findings_json = [&sh](const std::vector<Finding>& fs) {
    json fnd = json::array();
    for (const auto& f : fs) {
      fnd.push_back({{"effect", std::string(finding_name(f.effect))},
                     {"parameters", parameters_json(f, sh)},
                     {"evidence", f.evidence}});
    }
    return fnd;
  };
  j["findings"] = findings_json(r.findings);
  j["extended_model"] =
      model_json(r.extended, r.extended_band, r.band_level, r.gain.misfit_extended, r.gain.coverage_extended, sh);
  j["bias_instability_named_terms"] = {{"with_deg_per_h", r.base.bias_instability_deg_per_h},
                                       {"without_deg_per_h", r.extended.bias_instability_deg_per_h},
                                       {"with_over_without_percent", finite_or_null(b_excess_percent(r))},
                                       {"named_terms", json::array()}};
  for (const auto& f : r.findings)
    j["bias_instability_named_terms"]["named_terms"].push_back(std::string(finding_name(f.effect)));
  j["gain"] = {{"misfit_base", r.gain.misfit_base},
               {"misfit_extended", r.gain.misfit_extended},
               {"coverage_base", r.gain.coverage_base},
               {"coverage_extended", r.gain.coverage_extended},
               {"likelihood_in_sample", finite_or_null(r.gain.likelihood_in_sample)},
               {"likelihood_holdout", finite_or_null(r.gain.likelihood_holdout)}};
  j["seconds"] = r.seconds;
  j["termination"] = to_json(r.termination);
  if (sh.accel) accelerometer_json(r, sh, j);
  return clean_json(j);
}

namespace {

/// The record's line and the base model's: a gyro's with its pulse weight and Earth rate, an
/// accelerometer's with its column and units (no Earth rate).
std::string record_and_base(const DiagnoseResult& r, const Shown& sh) {
  std::string s;
  const auto& m = r.base;
  const std::string readout = m.readout == ReadoutMode::Counting ? tr("counting") : tr("white");
  if (!sh.accel) {
    s +=
        trf("  record: {:.0f} s at {:g} Hz, pulse weight {:g}″; band {:g} % per τ (the model's AV and the points' χ² "
            "EDF)\n\n",
            r.settings.duration_s, r.settings.rate_hz, r.settings.scale_arcsec, r.band_level * 100);
    s += format_outliers(r.analysis.outliers);
    return s + tr("Base model (five-term fit): ") + power_laws(m, sh) +
           trf(", white angle {:.4g}″, {} read-out, Earth rate {:.4g} °/h, bias {:.4g} °/h\n", m.white_angle_arcsec,
               readout, m.earth_rate_deg_per_h, m.bias_deg_per_h);
  }
  const std::string level = localized_label(sh.units.deviation);
  s +=
      trf("  record: {:.0f} s at {:g} Hz, column '{}' of an accelerometer read in {} (levels in {}, no Earth rate, no "
          "class verdict); band {:g} % per τ (the model's AV and the points' χ² EDF)\n\n",
          r.settings.duration_s, r.settings.rate_hz, as_typed(r.analysis.input.value("column", r.analysis.column)),
          r.analysis.input.value("unit", ""), level, r.band_level * 100);
  s += format_outliers(r.analysis.outliers, level, sh.units.deviation.factor);
  return s + tr("Base model (five-term fit): ") + power_laws(m, sh) +
         trf(", white velocity {:.4g} m/s, {} read-out, bias (with gravity's projection) {:.4g} {}\n",
             m.white_angle_arcsec / units::velocity_units_per_mps, readout, sh.level(m.bias_deg_per_h), level);
}

/// A τ whose measured σ lies outside the band, one line, in the sensor's level unit (a gyro's °/h
/// at factor 1).
std::string outside_row(const BandPoint& b, const Shown& sh) {
  const bool above = b.dev > b.high;
  const double share = 100 * (above ? b.dev / b.high - 1 : 1 - b.dev / b.low);
  const std::string u = localized_label(sh.units.deviation);
  return trf("    τ = {:>9.4g} s: σ = {:.4g} {}, {:.1f} % {} the band's {} edge {:.4g} {}\n", b.tau_s, sh.level(b.dev),
             u, share, above ? tr("above") : tr("below"), above ? tr("upper") : tr("lower"),
             sh.level(above ? b.high : b.low), u);
}

}  // namespace

std::string format_report(const DiagnoseResult& r) {
  const Shown sh(r);
  std::string s;
  s += trf("Diagnosis of {}\n", as_typed(r.analysis.source));
  s += record_and_base(r, sh);
  std::size_t outside = 0;
  std::string rows;
  for (const auto& b : r.base_band) {
    if (b.dev >= b.low && b.dev <= b.high) continue;
    ++outside;
    rows += outside_row(b, sh);
  }
  s += trf("  measured Allan deviation inside the base band at {} of {} τ\n", r.base_band.size() - outside,
           r.base_band.size());
  s += rows;
  s += tr("\nDetectors (likelihood ratio of the block means, noise levels profiled, against the threshold of ") +
       trf("its null law, false-alarm level {:g} % each):\n", r.alpha * 100);
  for (const auto& d : r.detectors)
    s += d.test.empty() ? trf("  {:<17} {}\n", detector_name(d.effect), d.note)
                        : trf("  {:<17} statistic {:>9.3f} (dimensionless), threshold {:>8.3f}, p ≤ {:.3g}: {}{}\n",
                              detector_name(d.effect), d.statistic, d.threshold, d.p_value,
                              d.named ? tr("FOUND") : (d.fired ? tr("fired, not named") : tr("not found")),
                              d.note.empty() ? "" : " (" + d.note + ")");
  if (!r.termination.converged())
    s +=
        trf("  warning: the search over the noise levels stopped at its limit of {} evaluations before "
            "converging; the statistics above may be too small\n",
            r.termination.iterations);
  s += tr("\nFindings:\n");
  if (r.findings.empty()) s += tr("  none: the base model explains the measurement\n");
  s += format_findings(r.findings, sh);
  s += tr("\nExtended model: ") + power_laws(r.extended, sh) + trf(", {} extra term(s)\n", r.findings.size());
  // Without B in the extended model the ratio has no value (JSON: null), so none is printed.
  if (!r.findings.empty()) {
    const std::string u = localized_label(sh.units[Term::B]);
    const double with = sh.level(r.base.bias_instability_deg_per_h),
                 without = sh.level(r.extended.bias_instability_deg_per_h), pct = b_excess_percent(r);
    s += std::isfinite(pct)
             ? trf("  B with the named terms in the data (base model) {:.4g} {}, without them (extended model) {:.4g} "
                   "{}: {:+.1f} % with them ({})\n",
                   with, u, without, u, pct, named_terms(r.findings))
             : trf("  B with the named terms in the data (base model) {:.4g} {}, without them (extended model) {:.4g} "
                   "{} ({})\n",
                   with, u, without, u, named_terms(r.findings));
  }
  s += tr("\nGain (misfit: mean EDF-weighted Gamma deviance per τ, about 1 (dimensionless) when the model fits):\n");
  s += fmt::format("  {:<44} {:>10} {:>10}\n", "", tr("base"), tr("extended"));
  s += fmt::format("  {:<44} {:>10.3f} {:>10.3f}\n", tr("Allan-variance misfit (dimensionless)"), r.gain.misfit_base,
                   r.gain.misfit_extended);
  s += fmt::format("  {:<44} {:>9.1f}% {:>9.1f}%\n", tr("measured τ inside the model's band"),
                   100 * r.gain.coverage_base, 100 * r.gain.coverage_extended);
  if (std::isnan(r.gain.likelihood_in_sample)) {
    s += fmt::format("  {:<44} {:>21}\n", tr("likelihood gain (−2Δ ln L)"), tr("not needed: none named"));
  } else {
    s += fmt::format("  {:<44} {:>10} {:>10.1f}\n", tr("likelihood gain in sample (−2Δ ln L − 2k)"), "",
                     r.gain.likelihood_in_sample);
    s += fmt::format("  {:<44} {:>10} {:>10.1f}\n", tr("likelihood gain on held-out runs (−2Δ ln L)"), "",
                     r.gain.likelihood_holdout);
  }
  s += trf("\n  ({:.1f} s)\n", r.seconds);
  return s;
}

}  // namespace rwcalc
