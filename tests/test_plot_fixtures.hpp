#pragma once
// JSON objects shaped exactly like the output of `rwcalc analyze --json`, `rwcalc batch --json`
// and `rwcalc diagnose --json` (docs/plots-and-reports.md), built from known
// coefficients so the figures and the report can be tested without the analysis pipeline.
// The Allan points follow the 5-term model of a GL-2D-like 2-h run (400 Hz, octave τ grid),
// scattered by a seeded relative error of 1/√(n/m) so they look measured.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rwcalc/plot.hpp"

/// Skip the current test with a clear message when gnuplot cannot be run.
#define REQUIRE_GNUPLOT()                                                          \
  do {                                                                             \
    if (!rwcalc::gnuplot_available())                                              \
      GTEST_SKIP() << "gnuplot not found ('" << rwcalc::gnuplot_command()          \
                   << "'): install gnuplot-nox to run the figure rendering tests"; \
  } while (0)

namespace rwcalc::test {

struct FixtureCoefficients {
  double temperature_c = 25;
  double Q = 0.2656;  // ″
  double N = 0.0009;  // °/√h
  double B = 0.0075;  // °/h
  double K = 0.0004;  // °/h/√h
  double R = 0;       // °/h²
  bool K_resolved = true;
};

inline double fixture_sigma(const FixtureCoefficients& c, double tau) {
  const double v = 3 * c.Q * c.Q / (tau * tau) + std::pow(60 * c.N, 2) / tau + 2 * std::log(2.0) / M_PI * c.B * c.B +
                   c.K * c.K * tau / (3 * 3600) + c.R * c.R * tau * tau / (2 * 3600.0 * 3600.0);
  return std::sqrt(v);
}

/// A coefficient object as `rwcalc analyze --json` writes it. Unresolved: `value` is the 95 %
/// upper bound (here `bound`), the model's estimate is 0.
inline nlohmann::json fixture_coefficient(double value, double rel_sigma, bool resolved = true, double bound = 0) {
  if (!resolved)
    return {{"value", bound},  {"sigma", bound / (2 * 1.96)}, {"low95", 0.0},  {"high95", bound}, {"resolved", false},
            {"estimate", 0.0}, {"in_model", false},           {"fitted", true}};
  const double s = value * rel_sigma;
  return {{"value", value},
          {"sigma", s},
          {"low95", std::max(0.0, value - 1.96 * s)},
          {"high95", value + 1.96 * s},
          {"resolved", true},
          {"estimate", value},
          {"in_model", true},
          {"fitted", true}};
}

/// One `rwcalc analyze --json` object.
inline nlohmann::json fixture_analysis(const FixtureCoefficients& c, unsigned seed = 1, bool with_direct_curve = true) {
  using nlohmann::json;
  std::mt19937 rng(seed);
  std::normal_distribution<double> z;
  const double rate = 400, tau0 = 1 / rate;
  const std::int64_t samples = 2 * 3600 * 400;
  json points = json::array();
  for (std::int64_t m = 1; 2 * m + 1 <= samples / 2; m *= 2) {
    const double tau = static_cast<double>(m) * tau0;
    const double edf = std::max(1.0, static_cast<double>(samples) / static_cast<double>(m) * 0.5);
    const double dev = fixture_sigma(c, tau) * std::max(0.2, 1 + z(rng) / std::sqrt(edf));
    const double rel = 1 / std::sqrt(edf);
    points.push_back({{"m", m},
                      {"tau_s", tau},
                      {"n", samples - 2 * m},
                      {"alpha", 0},
                      {"edf", edf},
                      {"var", dev * dev},
                      {"dev", dev},
                      {"dev_low", dev * std::max(0.05, 1 - rel)},
                      {"dev_high", dev * (1 + 1.4 * rel)}});
  }
  json direct = fixture_coefficient(c.N, 0.2);
  direct["intercept"] = 2 * c.Q * c.Q;
  if (with_direct_curve) {
    json curve = json::array();
    const double slope = std::pow(60 * c.N, 2), intercept = 2 * c.Q * c.Q;
    for (int i = 1; i <= 20; ++i) {
      const double t = 10.0 * i;
      curve.push_back({{"t_s", t}, {"var", (intercept + slope * t) * (1 + 0.1 * z(rng))}});
    }
    direct["curve"] = curve;
    direct["slope"] = slope;
  }
  const auto class_of = [](double v, double l1, double l2, double l3) -> json {
    if (v <= l1) return 1;
    if (v <= l2) return 2;
    if (v <= l3) return 3;
    return nullptr;
  };
  const json class_B = class_of(c.B, 0.005, 0.008, 0.015), class_N = class_of(c.N, 0.0010, 0.0015, 0.0030);
  const json cls =
      class_B.is_null() || class_N.is_null() ? json(nullptr) : json(std::max(class_B.get<int>(), class_N.get<int>()));
  auto param = [](double v, const char* unit, const json& k, std::vector<double> limits) {
    return json{{"value", v},        {"unit", unit},     {"resolved", true}, {"class", k},
                {"class_strict", k}, {"limits", limits}, {"p_class", 0.8}};
  };
  json verdict = {{"class_B", class_B},
                  {"class_N", class_N},
                  {"class", cls},
                  {"p_class", 0.83},
                  {"p_class_B", 0.86},
                  {"p_class_N", 0.9},
                  {"statement", cls.is_null() ? std::string("outside class 3 (P=0.83)")
                                              : "class " + std::to_string(cls.get<int>()) + " (P=0.83)"},
                  {"tolerance_pct", 0.0},
                  {"tolerance_changed", false},
                  {"b_estimate", "fit"},
                  {"table", "GOST RV 52339-2005 (as reported by Bolotnov & Fomin 2021)"},
                  {"classes", {1, 2, 3}},
                  {"p_is", {0.05, 0.83, 0.1, 0.02}},
                  {"B", param(c.B, "deg/h", class_B, {0.005, 0.008, 0.015})},
                  {"N", param(c.N, "deg/sqrt(h)", class_N, {0.0010, 0.0015, 0.0030})}};
  return {
      {"schema_version", 2},
      {"source", "gl2d_" + std::to_string(static_cast<int>(c.temperature_c)) + "C.csv"},
      {"samples", samples},
      {"rate_hz", rate},
      {"duration_s", samples / rate},
      {"temperature_c", c.temperature_c},
      {"mean_rate", 12.44},
      {"earth_rate", 12.43},
      {"allan",
       {{"estimator", "overlapping"}, {"unit", "deg/h"}, {"tau0_s", tau0}, {"confidence", 0.683}, {"points", points}}},
      {"fit",
       {{"Q", fixture_coefficient(c.Q, 0.02)},
        {"N", fixture_coefficient(c.N, 0.15)},
        {"B", fixture_coefficient(c.B, 0.2)},
        {"K", c.K_resolved ? fixture_coefficient(c.K, 0.4) : fixture_coefficient(0, 0, false, 2 * c.K)},
        {"R", fixture_coefficient(0, 0, false)},  // unresolved, no bound: not drawn
        {"chi2_per_dof", 1.08}}},
      {"methods", {{"N_direct", direct}, {"B_100s", fixture_coefficient(c.B * 0.95, 0.25)}}},
      {"verdict", verdict}};
}

/// The paper's five temperatures, `rwcalc batch --json` shape.
inline nlohmann::json fixture_batch(bool with_direct_curve = true) {
  using nlohmann::json;
  const double temps[] = {-50, -20, 0, 25, 50};
  const double ns[] = {0.00082, 0.00085, 0.00090, 0.00093, 0.00098};
  const double bs[] = {0.0073, 0.0076, 0.0078, 0.0080, 0.0083};
  json runs = json::array();
  for (int i = 0; i < 5; ++i) {
    FixtureCoefficients c;
    c.temperature_c = temps[i];
    c.N = ns[i];
    c.B = bs[i];
    c.K_resolved = i % 2 == 0;
    runs.push_back(fixture_analysis(c, 10 + i, with_direct_curve));
  }
  // Input order is not temperature order: the figures and tables must sort.
  std::swap(runs[0], runs[3]);
  return {{"schema_version", 2}, {"runs", runs}, {"overall", {{"class_B", 2}, {"class_N", 1}, {"class", 2}}}};
}

/// A diagnosis of a run with a sinusoid the base model misses: the measurement leaves the base
/// band around τ = 0.371/f0 and lies inside the extended model's band. Layout of
/// `rwcalc diagnose --json` (top-level "band" and "band_extended"), or with `nested` the bands
/// inside "base_model" / "extended_model".
inline nlohmann::json fixture_diagnosis(bool with_extended = true, bool nested = false) {
  using nlohmann::json;
  FixtureCoefficients c;
  const double f0 = 0.0125, amp = 0.03;  // Hz, °/h peak
  json base_band = json::array(), ext_band = json::array();
  for (double tau = 0.0025; tau < 1500; tau *= 2) {
    const double model = fixture_sigma(c, tau);
    const double x = M_PI * f0 * tau;
    const double sin_var = amp * amp * std::pow(std::sin(x) * std::sin(x) / x, 2);
    const double measured = std::sqrt(model * model + sin_var);
    const double ext = measured;  // the extended model follows the measurement
    const double w = 0.05 + 0.3 * std::sqrt(tau / 1500);
    base_band.push_back({{"tau_s", tau},
                         {"dev", measured},
                         {"band_low", model * (1 - w)},
                         {"band_high", model * (1 + w)},
                         {"median", model}});
    ext_band.push_back({{"tau_s", tau},
                        {"dev", measured},
                        {"band_low", ext * (1 - w)},
                        {"band_high", ext * (1 + w)},
                        {"median", ext}});
  }
  json d = {{"schema_version", 2},
            {"source", "gl2d_25C.csv"},
            {"units", {{"dev", "deg/h"}, {"tau", "s"}, {"band", "2.5-97.5 % quantiles of the simulated ADEV"}}},
            {"base_model", {{"misfit_per_point", 14.2}}},
            {"findings",
             json::array({{{"effect", "sinusoid"},
                           {"parameters",
                            {{"frequency", {{"value", f0}, {"unit", "Hz"}, {"standard_uncertainty", nullptr}}},
                             {"amplitude", {{"value", amp}, {"unit", "deg/h"}, {"standard_uncertainty", 0.0021}}}}},
                           {"evidence", {{"statistic", 40.0}}}}})},
            {"extended_model", {{"sinusoids", json::array({{{"frequency_hz", f0}, {"amplitude_deg_per_h", amp}}})}}},
            {"gain",
             {{"misfit_base", 14.2},
              {"misfit_extended", 1.1},
              {"coverage_base", 0.55},
              {"coverage_extended", 1.0},
              {"likelihood_in_sample", 12.0},
              {"likelihood_holdout", 1.4}}}};
  if (nested) {
    d["base_model"]["band"] = base_band;
    if (with_extended) d["extended_model"]["band"] = ext_band;
  } else {
    d["band"] = base_band;
    if (with_extended) d["band_extended"] = ext_band;
  }
  return d;
}

// ---- checks on rendered figures ---------------------------------------------------------------

/// Well-formedness of an XML document (enough of XML 1.0 for SVG): one root element, every tag
/// closed in order, attributes quoted and unique, entities well formed, comments/CDATA/PIs
/// terminated. Returns an empty string when well formed, else what is wrong and where.
inline std::string xml_problem(std::string_view s) {
  std::vector<std::string> stack;
  int roots = 0;
  std::size_t i = 0;
  auto name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == ':' || c == '_' || c == '-' || c == '.' ||
           static_cast<unsigned char>(c) >= 0x80;
  };
  auto where = [&](std::size_t at) { return " at byte " + std::to_string(at); };
  auto check_entities = [&](std::string_view text, std::size_t base) -> std::string {
    for (std::size_t k = 0; k < text.size(); ++k) {
      if (text[k] == '<') return "'<' in text or attribute" + where(base + k);
      if (text[k] != '&') continue;
      const auto semi = text.find(';', k);
      if (semi == std::string_view::npos || semi - k > 10) return "bad entity" + where(base + k);
      const auto ent = text.substr(k + 1, semi - k - 1);
      if (ent.empty()) return "empty entity" + where(base + k);
      if (ent[0] != '#' && ent != "lt" && ent != "gt" && ent != "amp" && ent != "quot" && ent != "apos")
        return "undefined entity &" + std::string(ent) + ";" + where(base + k);
      k = semi;
    }
    return {};
  };
  while (i < s.size()) {
    if (s[i] != '<') {
      const auto next = s.find('<', i);
      const auto text = s.substr(i, next == std::string_view::npos ? s.size() - i : next - i);
      if (stack.empty() && text.find_first_not_of(" \t\r\n") != std::string_view::npos)
        return "text outside the root element" + where(i);
      if (auto p = check_entities(text, i); !p.empty()) return p;
      i += text.size();
      continue;
    }
    auto skip_to = [&](std::string_view end) -> bool {
      const auto e = s.find(end, i);
      if (e == std::string_view::npos) return false;
      i = e + end.size();
      return true;
    };
    if (s.substr(i, 4) == "<!--") {
      if (!skip_to("-->")) return "unterminated comment" + where(i);
    } else if (s.substr(i, 9) == "<![CDATA[") {
      if (stack.empty()) return "CDATA outside the root" + where(i);
      if (!skip_to("]]>")) return "unterminated CDATA" + where(i);
    } else if (s.substr(i, 2) == "<?") {
      if (!skip_to("?>")) return "unterminated processing instruction" + where(i);
    } else if (s.substr(i, 2) == "<!") {
      if (!stack.empty() || roots > 0) return "declaration inside the document" + where(i);
      if (!skip_to(">")) return "unterminated declaration" + where(i);
    } else if (s.substr(i, 2) == "</") {
      std::size_t k = i + 2;
      while (k < s.size() && name_char(s[k])) ++k;
      const std::string name(s.substr(i + 2, k - i - 2));
      while (k < s.size() && std::isspace(static_cast<unsigned char>(s[k]))) ++k;
      if (k >= s.size() || s[k] != '>') return "bad end tag" + where(i);
      if (stack.empty() || stack.back() != name)
        return "end tag </" + name + "> does not close <" + (stack.empty() ? "" : stack.back()) + ">" + where(i);
      stack.pop_back();
      i = k + 1;
    } else {
      std::size_t k = i + 1;
      while (k < s.size() && name_char(s[k])) ++k;
      const std::string name(s.substr(i + 1, k - i - 1));
      if (name.empty()) return "bad start tag" + where(i);
      std::set<std::string> attrs;
      bool closed = false, self_closing = false;
      while (k < s.size()) {
        while (k < s.size() && std::isspace(static_cast<unsigned char>(s[k]))) ++k;
        if (k >= s.size()) break;
        if (s[k] == '>') {
          closed = true;
          ++k;
          break;
        }
        if (s.substr(k, 2) == "/>") {
          closed = self_closing = true;
          k += 2;
          break;
        }
        const std::size_t a0 = k;
        while (k < s.size() && name_char(s[k])) ++k;
        const std::string attr(s.substr(a0, k - a0));
        if (attr.empty()) return "bad attribute in <" + name + ">" + where(k);
        if (!attrs.insert(attr).second) return "duplicate attribute " + attr + where(a0);
        while (k < s.size() && std::isspace(static_cast<unsigned char>(s[k]))) ++k;
        if (k >= s.size() || s[k] != '=') return "attribute " + attr + " without value" + where(k);
        ++k;
        while (k < s.size() && std::isspace(static_cast<unsigned char>(s[k]))) ++k;
        if (k >= s.size() || (s[k] != '"' && s[k] != '\'')) return "unquoted attribute " + attr + where(k);
        const char quote = s[k];
        const auto end = s.find(quote, k + 1);
        if (end == std::string_view::npos) return "unterminated attribute " + attr + where(k);
        if (auto p = check_entities(s.substr(k + 1, end - k - 1), k + 1); !p.empty()) return p;
        k = end + 1;
      }
      if (!closed) return "unterminated start tag <" + name + ">" + where(i);
      if (stack.empty()) {
        if (++roots > 1) return "more than one root element" + where(i);
      }
      if (!self_closing) stack.push_back(name);
      i = k;
    }
  }
  if (!stack.empty()) return "unclosed element <" + stack.back() + ">";
  if (roots != 1) return "no root element";
  return {};
}

/// The distinct gnuplot plot elements of an SVG: ids "gnuplot_plot_<n><panel letter>".
inline std::set<std::string> svg_series(std::string_view svg) {
  std::set<std::string> ids;
  const std::string_view key = "id=\"gnuplot_plot_";
  for (auto p = svg.find(key); p != std::string_view::npos; p = svg.find(key, p + 1)) {
    const auto end = svg.find('"', p + key.size());
    ids.insert(std::string(svg.substr(p + key.size(), end - p - key.size())));
  }
  return ids;
}

// ---- checks on the HTML report ----------------------------------------------------------------

/// Standard base64 (RFC 4648) decoding; stops at the first character outside the alphabet.
inline std::string base64_decode(std::string_view s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::string out;
  unsigned acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = val(c);
    if (v < 0) break;
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  return out;
}

/// figure id → decoded SVG of every inline figure (parsed by hand: std::regex recurses per
/// character and overflows the stack on a long base64 string).
inline std::map<std::string, std::string> inline_figures(const std::string& html) {
  std::map<std::string, std::string> figs;
  const std::string open = "<figure id=\"", data = "src=\"data:image/svg+xml;base64,";
  for (auto p = html.find(open); p != std::string::npos; p = html.find(open, p + 1)) {
    const auto id_end = html.find('"', p + open.size());
    const auto id = html.substr(p + open.size(), id_end - p - open.size());
    const auto img = html.find("<img ", id_end);
    const auto src = html.find(data, img);
    if (img == std::string::npos || src == std::string::npos || html.find("</figure>", id_end) < src) continue;
    const auto b0 = src + data.size();
    figs[id] = base64_decode(std::string_view(html).substr(b0, html.find('"', b0) - b0));
  }
  return figs;
}

}  // namespace rwcalc::test
