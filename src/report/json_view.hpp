#pragma once
// Reading the analysis, batch and diagnosis JSON for figures and the report. The JSON may be
// saved or hand-made: an absent, null or non-finite value is "not available", never 0.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rwcalc/units.hpp"

namespace rwcalc::view {

using nlohmann::json;

inline const json& at(const json& j, std::string_view key) {
  static const json null_json;
  if (!j.is_object()) return null_json;
  const auto it = j.find(key);
  return it == j.end() ? null_json : *it;
}

inline std::optional<double> num(const json& j) {
  if (!j.is_number()) return std::nullopt;
  const double v = j.get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

inline std::optional<double> num(const json& j, std::string_view key) { return num(at(j, key)); }

inline std::string str(const json& j, std::string_view key) {
  const auto& v = at(j, key);
  return v.is_string() ? v.get<std::string>() : std::string();
}

/// "+25 °C", "−50 °C", "0 °C"; empty when not available.
inline std::string temperature_label(const json& t) {
  const auto v = num(t);
  if (!v) return {};
  return fmt::format("{}{:g} {}", *v > 0 ? "+" : *v < 0 ? "−" : "", std::fabs(*v), units::label::celsius);
}

/// Class limits of "B" or "N" as the verdict applied them (tolerance included), else the GOST
/// RV 52339 table.
inline std::vector<std::pair<int, double>> class_limits(const json& analysis, const char* parameter) {
  std::vector<std::pair<int, double>> r;
  const auto& verdict = at(analysis, "verdict");
  const auto& classes = at(verdict, "classes");
  const auto& limits = at(at(verdict, parameter), "limits");
  if (classes.is_array() && limits.is_array() && classes.size() == limits.size())
    for (std::size_t i = 0; i < classes.size(); ++i)
      if (const auto l = num(limits[i]); classes[i].is_number_integer() && l && *l > 0)
        r.emplace_back(classes[i].get<int>(), *l);
  if (!r.empty()) return r;
  if (std::string_view(parameter) == "B") return {{1, 0.005}, {2, 0.008}, {3, 0.015}};
  return {{1, 0.0010}, {2, 0.0015}, {3, 0.0030}};
}

/// Indices of `runs` (a vector or a JSON array of analyses) by temperature; runs without one
/// last, in input order.
template <class Runs>
std::vector<std::size_t> by_temperature(const Runs& runs) {
  std::vector<std::size_t> idx(runs.size());
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    const auto ta = num(runs[a], "temperature_c"), tb = num(runs[b], "temperature_c");
    if (ta && tb) return *ta < *tb;
    return ta.has_value() && !tb.has_value();
  });
  return idx;
}

}  // namespace rwcalc::view
