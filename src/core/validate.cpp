#include "rwcalc/validate.hpp"

#include <fmt/format.h>

#include <cmath>

#include "rwcalc/i18n.hpp"

namespace rwcalc {

Violation first_of(std::initializer_list<Violation> rules) {
  for (const Violation& v : rules)
    if (v) return v;
  return std::nullopt;
}

std::string range_text(double lo, double hi, std::string_view unit, Ends ends) {
  const bool open_lo = ends == Ends::OpenLow || ends == Ends::Open;
  const bool open_hi = ends == Ends::OpenHigh || ends == Ends::Open;
  return fmt::format("{}{:g}, {:g}{}{}{}", open_lo ? '(' : '[', lo, hi, open_hi ? ')' : ']', unit.empty() ? "" : " ",
                     unit);
}

Violation check_in(std::string_view what, double value, double lo, double hi, std::string_view unit, Ends ends) {
  const bool low_ok = (ends == Ends::OpenLow || ends == Ends::Open) ? value > lo : value >= lo;
  const bool high_ok = (ends == Ends::OpenHigh || ends == Ends::Open) ? value < hi : value <= hi;
  if (std::isfinite(value) && low_ok && high_ok) return std::nullopt;
  return trf("{} must be a finite number in {}, got {:g}", what, range_text(lo, hi, unit, ends), value);
}

}  // namespace rwcalc
