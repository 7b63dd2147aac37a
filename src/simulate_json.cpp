// JSON form of the simulator's noise model, shared by simulate, analyze and diagnose.
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "rwcalc/error.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc {

namespace {

using nlohmann::json;

double num(const json& j, const char* key, double fallback = 0.0) {
  if (!j.contains(key) || j.at(key).is_null()) return fallback;
  if (!j.at(key).is_number()) throw UsageError(fmt::format("model JSON: '{}' must be a number", key));
  return j.at(key).get<double>();
}

// Value of a fitted coefficient object {"value": …} (or a bare number); 0 when absent or null.
double fitted(const json& fit, const char* key) {
  if (!fit.contains(key) || fit.at(key).is_null()) return 0.0;
  const json& v = fit.at(key);
  if (v.is_number()) return v.get<double>();
  if (v.is_object()) return num(v, "value");
  throw UsageError(fmt::format("analysis JSON: fit.{} must be an object with a value", key));
}

json profile_json(const TemperatureProfile& p) {
  if (p.kind == TemperatureProfile::Kind::Ramp) return {{"kind", "ramp"}, {"start_c", p.start_c}, {"end_c", p.end_c}};
  return {{"kind", "cycle"}, {"amplitude_c", p.amp_c}, {"period_s", p.period_s}};
}

}  // namespace

void to_json(json& j, const NoiseModel& m) {
  j = json{{"arw_deg_per_sqrt_h", m.arw_deg_per_sqrt_h},
           {"bias_instability_deg_per_h", m.bias_instability_deg_per_h},
           {"rrw_deg_per_h_per_sqrt_h", m.rrw_deg_per_h_per_sqrt_h},
           {"ramp_deg_per_h2", m.ramp_deg_per_h2},
           {"bias_deg_per_h", m.bias_deg_per_h},
           {"earth_rate_deg_per_h", m.earth_rate_deg_per_h},
           {"readout", m.readout == ReadoutMode::White ? "white" : "counting"},
           {"white_angle_arcsec", m.white_angle_arcsec},
           {"lowpass_tc_s", m.lowpass_tc_s},
           {"output_lowpass_tc_s", m.output_lowpass_tc_s}};
  json s = json::array(), g = json::array(), st = json::array(), w = json::array();
  for (const auto& x : m.sinusoids)
    s.push_back({{"frequency_hz", x.f_hz}, {"amplitude_deg_per_h", x.amp_deg_per_h}, {"phase_rad", x.phase_rad}});
  for (const auto& x : m.gauss_markov)
    g.push_back({{"sigma_deg_per_h", x.sigma_deg_per_h}, {"correlation_time_s", x.tc_s}});
  for (const auto& x : m.bias_steps) st.push_back({{"time_s", x.t_s}, {"size_deg_per_h", x.size_deg_per_h}});
  for (const auto& x : m.warmups) w.push_back({{"amplitude_deg_per_h", x.amp_deg_per_h}, {"time_constant_s", x.tc_s}});
  j["sinusoids"] = s;
  j["gauss_markov"] = g;
  j["bias_steps"] = st;
  j["warmups"] = w;
  if (m.temperature_bias)
    j["temperature_bias"] = {{"coefficient_deg_per_h_per_c", m.temperature_bias->coefficient_deg_per_h_per_c},
                             {"profile", profile_json(m.temperature_bias->profile)}};
  else
    j["temperature_bias"] = nullptr;
}

void add_finding(const json& f, NoiseModel& m) {
  if (!f.is_object() || !f.contains("effect") || !f.at("effect").is_string())
    throw UsageError("model JSON: a term needs an \"effect\" name");
  const auto effect = f.at("effect").get<std::string>();
  if (effect == "sinusoid") {
    m.sinusoids.push_back({num(f, "frequency_hz"), num(f, "amplitude_deg_per_h"), num(f, "phase_rad")});
  } else if (effect == "gauss_markov") {
    m.gauss_markov.push_back({num(f, "sigma_deg_per_h"), num(f, "correlation_time_s")});
  } else if (effect == "bias_step") {
    m.bias_steps.push_back({num(f, "time_s"), num(f, "size_deg_per_h")});
  } else if (effect == "warmup_transient" || effect == "warmup") {
    m.warmups.push_back({num(f, "amplitude_deg_per_h"), num(f, "time_constant_s")});
  } else if (effect == "lowpass") {
    // The low-pass diagnose names is the filter in the output chain (a low-pass of the sensed
    // rate before counting is a Gauss–Markov rate and is named gauss_markov).
    m.output_lowpass_tc_s = num(f, "time_constant_s");
  } else {
    throw UsageError(fmt::format("model JSON: unknown effect '{}'", effect));
  }
}

void from_json(const json& j, NoiseModel& m) {
  if (!j.is_object()) throw UsageError("model JSON: expected an object");
  m = NoiseModel{};
  m.arw_deg_per_sqrt_h = num(j, "arw_deg_per_sqrt_h");
  m.bias_instability_deg_per_h = num(j, "bias_instability_deg_per_h");
  m.rrw_deg_per_h_per_sqrt_h = num(j, "rrw_deg_per_h_per_sqrt_h");
  m.ramp_deg_per_h2 = num(j, "ramp_deg_per_h2");
  m.bias_deg_per_h = num(j, "bias_deg_per_h");
  m.earth_rate_deg_per_h = num(j, "earth_rate_deg_per_h");
  m.white_angle_arcsec = num(j, "white_angle_arcsec");
  m.lowpass_tc_s = num(j, "lowpass_tc_s");
  m.output_lowpass_tc_s = num(j, "output_lowpass_tc_s");
  if (j.contains("readout") && !j.at("readout").is_null()) {
    const auto r = j.at("readout").get<std::string>();
    if (r == "white")
      m.readout = ReadoutMode::White;
    else if (r == "counting")
      m.readout = ReadoutMode::Counting;
    else
      throw UsageError(fmt::format("model JSON: readout must be \"counting\" or \"white\", got \"{}\"", r));
  }
  auto each = [&](const char* key, auto&& fn) {
    if (!j.contains(key) || j.at(key).is_null()) return;
    if (!j.at(key).is_array()) throw UsageError(fmt::format("model JSON: '{}' must be an array", key));
    for (const auto& x : j.at(key)) fn(x);
  };
  each("sinusoids", [&](const json& x) {
    m.sinusoids.push_back({num(x, "frequency_hz"), num(x, "amplitude_deg_per_h"), num(x, "phase_rad")});
  });
  each("gauss_markov", [&](const json& x) { m.gauss_markov.push_back({num(x, "sigma_deg_per_h"), num(x, "correlation_time_s")}); });
  each("bias_steps", [&](const json& x) { m.bias_steps.push_back({num(x, "time_s"), num(x, "size_deg_per_h")}); });
  each("warmups", [&](const json& x) { m.warmups.push_back({num(x, "amplitude_deg_per_h"), num(x, "time_constant_s")}); });
  each("terms", [&](const json& x) { add_finding(x, m); });
  if (j.contains("temperature_bias") && !j.at("temperature_bias").is_null()) {
    const json& t = j.at("temperature_bias");
    TemperatureBias tb;
    tb.coefficient_deg_per_h_per_c = num(t, "coefficient_deg_per_h_per_c");
    if (t.contains("profile")) {
      const json& p = t.at("profile");
      const auto kind = p.value("kind", std::string("ramp"));
      if (kind == "ramp") {
        tb.profile.kind = TemperatureProfile::Kind::Ramp;
        tb.profile.start_c = num(p, "start_c");
        tb.profile.end_c = num(p, "end_c");
      } else if (kind == "cycle") {
        tb.profile.kind = TemperatureProfile::Kind::Cycle;
        tb.profile.amp_c = num(p, "amplitude_c");
        tb.profile.period_s = num(p, "period_s");
      } else {
        throw UsageError(fmt::format("model JSON: temperature profile kind must be ramp or cycle, got \"{}\"", kind));
      }
    }
    m.temperature_bias = tb;
  }
}

void to_json(json& j, const SimulationSettings& s) {
  j = json{{"duration_s", s.duration_s},
           {"rate_hz", s.rate_hz},
           {"scale_arcsec_per_pulse", s.scale_arcsec},
           {"seed", s.seed},
           {"samples", s.samples()}};
  j["temperature_c"] = s.temperature_c ? json(*s.temperature_c) : json(nullptr);
}

NoiseModel model_from_analysis_json(const json& j, const std::string& name, SimulationSettings& settings) {
  try {
    if (!j.is_object()) throw UsageError("expected a JSON object");
    const json* root = &j;
    // Diagnose output: take its extended model (else the base model).
    if (j.contains("extended_model") && j.at("extended_model").is_object())
      root = &j.at("extended_model");
    else if (j.contains("base_model") && j.at("base_model").is_object())
      root = &j.at("base_model");

    auto take = [&](const char* key, auto&& fn) {
      for (const json* src : {root, &j})
        if (src->contains(key) && src->at(key).is_number()) {
          fn(src->at(key).get<double>());
          return;
        }
    };
    take("rate_hz", [&](double v) { settings.rate_hz = v; });
    take("duration_s", [&](double v) { settings.duration_s = v; });
    take("temperature_c", [&](double v) { settings.temperature_c = v; });
    take("scale_arcsec_per_pulse", [&](double v) { settings.scale_arcsec = v; });
    NoiseModel m;
    if (root->contains("fit")) {
      const json& fit = root->at("fit");
      m.arw_deg_per_sqrt_h = fitted(fit, "N_deg_per_sqrt_h");
      m.bias_instability_deg_per_h = fitted(fit, "B_deg_per_h");
      m.rrw_deg_per_h_per_sqrt_h = fitted(fit, "K_deg_per_h_per_sqrt_h");
      m.ramp_deg_per_h2 = fitted(fit, "R_deg_per_h2");
      // The fitted Q is white angle noise: a white read-out contributes q/√6 of it, the rest
      // is added as extra white angle noise before counting.
      m.readout = ReadoutMode::White;
      const double q_fit = fitted(fit, "Q_arcsec");
      const double q_read = readout_q_arcsec(ReadoutMode::White, settings.scale_arcsec);
      if (q_fit > q_read) m.white_angle_arcsec = std::sqrt(q_fit * q_fit - q_read * q_read);
      const double earth = num(*root, "earth_rate_deg_per_h", num(j, "earth_rate_deg_per_h"));
      const double mean = num(*root, "mean_rate_deg_per_h", num(j, "mean_rate_deg_per_h", earth));
      m.earth_rate_deg_per_h = earth;
      m.bias_deg_per_h = mean - earth;
    } else {
      from_json(*root, m);
    }
    // Extra terms: a model object's own "terms", and diagnose findings.
    if (root != &j && root->contains("terms") && root->contains("fit")) {
      for (const auto& t : root->at("terms")) add_finding(t, m);
    }
    return m;
  } catch (const UsageError& e) {
    throw InputError(name, 0, e.what());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(name, 0, e.what());
  }
}

}  // namespace rwcalc
