#include "numeric_options.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::cli {

CLI::Validator real_in(double lo, double hi, const std::string& unit, Ends ends) {
  const std::string range = range_text(lo, hi, unit, ends);
  auto check = [lo, hi, ends, range](std::string& text) -> std::string {
    double v = 0;
    const char* b = text.data();
    const char* e = b + text.size();
    if (b != e && *b == '+') ++b;
    const auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range)
      return trf("'{}' is beyond the range of a double; allowed: a finite number in {}", text, range);
    if (b == e || ec != std::errc() || ptr != e)
      return trf("'{}' is not a number; allowed: a finite number in {}", text, range);
    const bool low_ok = (ends == Ends::OpenLow || ends == Ends::Open) ? v > lo : v >= lo;
    const bool high_ok = (ends == Ends::OpenHigh || ends == Ends::Open) ? v < hi : v <= hi;
    if (!std::isfinite(v) || !low_ok || !high_ok)
      return trf("'{}' is out of range; allowed: a finite number in {}", text, range);
    return {};
  };
  return CLI::Validator(check, "NUMBER in " + range, kNumberCheck);
}

CLI::Validator whole_in(std::int64_t lo, std::uint64_t hi) {
  const std::string range = fmt::format("[{}, {}]", lo, hi);
  auto check = [lo, hi, range](std::string& text) -> std::string {
    const char* b = text.data();
    const char* e = b + text.size();
    if (b != e && *b == '+') ++b;
    bool in_range = false;
    std::from_chars_result r{};
    if (b != e && *b == '-') {
      std::int64_t v = 0;
      r = std::from_chars(b, e, v);
      in_range = v >= lo;
    } else {
      std::uint64_t v = 0;
      r = std::from_chars(b, e, v);
      in_range = v <= hi && (lo <= 0 || v >= static_cast<std::uint64_t>(lo));
    }
    const auto [ptr, ec] = r;
    if (b == e || (ec != std::errc() && ec != std::errc::result_out_of_range) || ptr != e)
      return trf("'{}' is not a whole number; allowed: a whole number in {}", text, range);
    if (ec == std::errc::result_out_of_range || !in_range)
      return trf("'{}' is out of range; allowed: a whole number in {}", text, range);
    return {};
  };
  return CLI::Validator(check, "INTEGER in " + range, kNumberCheck);
}

namespace {

void find_non_finite(const nlohmann::json& j, const std::string& path, const std::string& source) {
  if (j.is_number_float()) {
    const double v = j.get<double>();
    if (!std::isfinite(v))
      throw AnalysisError(trf("{}: the result {} is {} (a number overflowed a double); nothing was printed", source,
                              path.empty() ? "value" : path, v));
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) find_non_finite(value, path.empty() ? key : path + "." + key, source);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) find_non_finite(j[i], fmt::format("{}[{}]", path, i), source);
  }
}

}  // namespace

void require_finite(const nlohmann::json& result, const std::string& source) { find_non_finite(result, "", source); }

}  // namespace rwcalc::cli
