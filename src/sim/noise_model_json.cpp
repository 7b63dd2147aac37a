// JSON form of the simulator's noise model (noise_model.hpp), shared by simulate, analyze and diagnose.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/noise_model.hpp"

namespace rwcalc {

namespace {

using json_input::Value;
using nlohmann::json;

/// A number of a model (absent or null: `fallback`); any other type is an input error.
double num(const Value& object, const char* key, double fallback = 0.0) {
  const auto v = object.find(key);
  return v ? v->number() : fallback;
}

/// How `simulate --from` takes the fitted coefficients, and what it says about them.
struct CoefficientPolicy {
  bool upper_bounds = false;                  ///< unresolved terms at their 95 % upper bounds
  std::vector<std::string>* notes = nullptr;  ///< one line per term left out or at its bound
};

// A fitted coefficient {"value", "estimate", "resolved", "in_model", …} (or a bare number) as the
// fitted model has it: a term in the model at its estimate; one the term selection left out, or
// one not resolved that has no estimate, at 0, or with `upper_bounds` at its upper bound ("value").
// Absent keys: in the model and resolved (a hand-written {"value": …}); absent or null: 0.
double fitted(const Value& fit, const char* key, const CoefficientPolicy& policy) {
  const auto v = fit.find(key);
  if (!v) return 0.0;
  if (!v->json().is_object()) return v->number();
  auto flag = [&](const char* k) {
    const auto f = v->find(k);
    return !f || f->boolean();
  };
  const bool in_model = flag("in_model"), resolved = flag("resolved");
  const double value = num(*v, "value");
  if (in_model && resolved) return num(*v, "estimate", value);
  const double estimate = in_model ? num(*v, "estimate") : 0.0;
  // The notes name the term with its unit, as the analysis gave it: "N (deg/sqrt(h))".
  const auto unit = v->find("unit");
  const std::string name = unit ? fmt::format("{} ({})", key, unit->string()) : std::string(key);
  auto note = [&](std::string line) {
    if (policy.notes) policy.notes->push_back(std::move(line));
  };
  if (policy.upper_bounds && value > estimate) {
    note(trf("{} = {:g}: its 95 % upper bound (not resolved; --upper-bounds)", name, value));
    return value;
  }
  if (value > 0)
    note(estimate > 0 ? trf("{} = {:g}: its estimate (not resolved; 95 % upper bound {:g})", name, estimate, value)
                      : trf("{} left out ({}; 95 % upper bound {:g}; --upper-bounds takes it)", name,
                            in_model ? tr("not resolved") : tr("left out of the model by the fit"), value));
  return estimate;
}

/// The model's scalar terms and their JSON keys, in the order they are read.
constexpr std::pair<const char*, double NoiseModel::*> kScalars[] = {
    {"arw_deg_per_sqrt_h", &NoiseModel::arw_deg_per_sqrt_h},
    {"bias_instability_deg_per_h", &NoiseModel::bias_instability_deg_per_h},
    {"rrw_deg_per_h_per_sqrt_h", &NoiseModel::rrw_deg_per_h_per_sqrt_h},
    {"ramp_deg_per_h2", &NoiseModel::ramp_deg_per_h2},
    {"bias_deg_per_h", &NoiseModel::bias_deg_per_h},
    {"earth_rate_deg_per_h", &NoiseModel::earth_rate_deg_per_h},
    {"white_angle_arcsec", &NoiseModel::white_angle_arcsec},
    {"lowpass_tc_s", &NoiseModel::lowpass_tc_s},
    {"output_lowpass_tc_s", &NoiseModel::output_lowpass_tc_s}};

json profile_json(const TemperatureProfile& p) {
  if (p.kind == TemperatureProfile::Kind::Ramp) return {{"kind", "ramp"}, {"start_c", p.start_c}, {"end_c", p.end_c}};
  return {{"kind", "cycle"}, {"amplitude_c", p.amp_c}, {"period_s", p.period_s}};
}

}  // namespace

void to_json(json& j, const NoiseModel& m) {
  j = json{{"readout", m.readout == ReadoutMode::White ? "white" : "counting"}};
  for (const auto& [key, member] : kScalars) j[key] = m.*member;
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

namespace {

// One term of the model, `effect` naming its kind as diagnose's findings do.
void add_effect(const std::string& effect, const Value& f, NoiseModel& m) {
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
    f.at("effect").fail(fmt::format("names an unknown effect '{}'", effect));
  }
}

void add_term(const Value& f, NoiseModel& m) { add_effect(f.object().at("effect").string(), f, m); }

void model_from(const Value& j, NoiseModel& m) {
  j.object();
  m = NoiseModel{};
  for (const auto& [key, member] : kScalars) m.*member = num(j, key);
  if (const auto readout = j.find("readout")) {
    const auto r = readout->string();
    if (r == "white")
      m.readout = ReadoutMode::White;
    else if (r == "counting")
      m.readout = ReadoutMode::Counting;
    else
      readout->fail(fmt::format("must be \"counting\" or \"white\", got \"{}\"", r));
  }
  for (const auto& [key, effect] : {std::pair{"sinusoids", "sinusoid"},
                                    {"gauss_markov", "gauss_markov"},
                                    {"bias_steps", "bias_step"},
                                    {"warmups", "warmup"}})
    if (const auto list = j.find(key))
      for (const auto& x : list->elements()) add_effect(effect, x.object(), m);
  if (const auto terms = j.find("terms"))
    for (const auto& x : terms->elements()) add_term(x, m);
  if (const auto tbias = j.find("temperature_bias")) {
    const Value& t = tbias->object();
    TemperatureBias tb;
    tb.coefficient_deg_per_h_per_c = num(t, "coefficient_deg_per_h_per_c");
    if (const auto profile = t.find("profile")) {
      const Value& p = profile->object();
      const auto kind_value = p.find("kind");
      const auto kind = kind_value ? kind_value->string() : std::string("ramp");
      if (kind == "ramp") {
        tb.profile.kind = TemperatureProfile::Kind::Ramp;
        tb.profile.start_c = num(p, "start_c");
        tb.profile.end_c = num(p, "end_c");
      } else if (kind == "cycle") {
        tb.profile.kind = TemperatureProfile::Kind::Cycle;
        tb.profile.amp_c = num(p, "amplitude_c");
        tb.profile.period_s = num(p, "period_s");
      } else {
        kind_value->fail(fmt::format("must be \"ramp\" or \"cycle\", got \"{}\"", kind));
      }
    }
    m.temperature_bias = tb;
  }
}

}  // namespace

// The nlohmann hooks read models built in code: a wrong value there is a usage error.
void add_finding(const json& f, NoiseModel& m) {
  try {
    const auto doc = json_input::Document::of_value(f, "model JSON");
    add_term(doc.root(), m);
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
}

void from_json(const json& j, NoiseModel& m) {
  try {
    const auto doc = json_input::Document::of_value(j, "model JSON");
    model_from(doc.root(), m);
  } catch (const InputError& e) {
    throw UsageError(e.what());
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

namespace {

/// The fitted coefficients of a gyro's analysis, in the order the model takes them.
constexpr const char* kCoefficientKeys[] = {"Q", "N", "B", "K", "R"};

/// A key of a noise model object's terms.
bool term_key(std::string_view key) {
  for (const auto& [name, member] : kScalars)
    if (key == name) return true;
  for (const char* name :
       {"readout", "sinusoids", "gauss_markov", "bias_steps", "warmups", "terms", "temperature_bias"})
    if (key == name) return true;
  return false;
}

/// A key of the record's settings, which a model object may hold beside its terms.
bool setting_key(std::string_view key) {
  for (const char* name : {"rate_hz", "duration_s", "temperature_c", "scale_arcsec_per_pulse"})
    if (key == name) return true;
  return false;
}

/// What --from takes: the analysis of a gyro with its five coefficients, a diagnosis (its models),
/// or a noise model of model keys only. Anything else, which used to give a noise-free record, is
/// an error naming what it lacks.
void require_model(const Value& j) {
  if (const auto fit = j.find("fit")) {
    if (const auto sensor = j.find("sensor"); sensor && sensor->string() != "gyro")
      sensor->fail(
          trf("is \"{}\": --from takes the analysis of a gyro (simulate writes gyro pulse records)", sensor->string()));
    json_input::require_schema_version(j);
    json_input::require_gyro_units(j, "--from");
    for (const char* key : kCoefficientKeys) (void)fit->at(key);
    return;
  }
  const auto& items = j.json().items();
  if (std::any_of(items.begin(), items.end(), [](const auto& item) { return term_key(item.key()); })) {
    for (const auto& item : items)
      if (!term_key(item.key()) && !setting_key(item.key()))
        j.at(item.key())
            .fail(tr("is not a key of a noise model (arw_deg_per_sqrt_h, bias_instability_deg_per_h, "
                     "readout, sinusoids, …)"));
    return;
  }
  std::vector<std::string> keys;
  for (const auto& item : items) keys.push_back(fmt::format("\"{}\"", item.key()));
  if (keys.size() > 6) keys.resize(6), keys.back() = "…";
  j.fail(
      trf("holds no model for --from: neither the \"fit\" of 'rwcalc analyze --json' (of a gyro), the "
          "\"extended_model\" of 'rwcalc diagnose --json', nor the keys of a noise model "
          "(arw_deg_per_sqrt_h, bias_instability_deg_per_h, …){}",
          keys.empty() ? std::string(tr("; it is an empty object")) : trf("; its keys: {}", fmt::join(keys, ", "))));
}

NoiseModel model_from_analysis(const Value& j, SimulationSettings& settings, const CoefficientPolicy& policy) {
  j.object();
  // Diagnose output: take its extended model (else the base model).
  auto model = [&](const char* key) -> std::optional<Value> {
    const auto v = j.find(key);
    return v && v->json().is_object() ? v : std::nullopt;
  };
  const Value root = model("extended_model").value_or(model("base_model").value_or(j));
  const bool nested = &root.json() != &j.json();
  if (nested) json_input::require_schema_version(j);  // a diagnosis, rwcalc's result
  if (!nested) require_model(j);
  // The record's settings, from the model or else the top level.
  auto setting = [&](const char* key) {
    auto v = root.find(key);
    return v || !nested ? v : j.find(key);
  };
  if (const auto v = setting("rate_hz")) settings.rate_hz = v->positive();
  if (const auto v = setting("duration_s")) settings.duration_s = v->positive();
  if (const auto v = setting("temperature_c"))
    settings.temperature_c = v->number_in(-273.15, 1000, "a temperature in °C in [-273.15, 1000]");
  if (const auto v = setting("scale_arcsec_per_pulse")) settings.scale_arcsec = v->positive();
  NoiseModel m;
  if (const auto fit = root.find("fit")) {
    fit->object();
    m.arw_deg_per_sqrt_h = fitted(*fit, "N", policy);
    m.bias_instability_deg_per_h = fitted(*fit, "B", policy);
    m.rrw_deg_per_h_per_sqrt_h = fitted(*fit, "K", policy);
    m.ramp_deg_per_h2 = fitted(*fit, "R", policy);
    // The fitted Q is white angle noise: a white read-out contributes q/√6 of it, the rest
    // is added as extra white angle noise before counting.
    m.readout = ReadoutMode::White;
    const double q_fit = fitted(*fit, "Q", policy);
    const double q_read = readout_q_arcsec(ReadoutMode::White, settings.scale_arcsec);
    if (q_fit > q_read) m.white_angle_arcsec = std::sqrt(q_fit * q_fit - q_read * q_read);
    const double earth = num(root, "earth_rate", num(j, "earth_rate"));
    const double mean = num(root, "mean_rate", num(j, "mean_rate", earth));
    m.earth_rate_deg_per_h = earth;
    m.bias_deg_per_h = mean - earth;
    // Extra terms: a model object's own "terms", and diagnose findings.
    if (nested)
      if (const auto terms = root.find("terms"))
        for (const auto& t : terms->elements()) add_term(t, m);
  } else {
    model_from(root, m);
  }
  return m;
}

}  // namespace

NoiseModel model_from_analysis_json(const json& j, const std::string& name, SimulationSettings& settings,
                                    bool upper_bounds, std::vector<std::string>* notes) {
  const auto doc = json_input::Document::of_value(j, name);
  return model_from_analysis(doc.root(), settings, {upper_bounds, notes});
}

NoiseModel model_from_analysis_file(const std::string& path, SimulationSettings& settings, bool upper_bounds,
                                    std::vector<std::string>* notes) {
  const auto doc = json_input::Document::load(path);
  return model_from_analysis(doc.root(), settings, {upper_bounds, notes});
}

}  // namespace rwcalc
