// Numbers of the documents: no e-notation, values and uncertainties rounded to the same digit.
#include "rwcalc/quantity_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include "rwcalc/i18n.hpp"

namespace rwcalc {

namespace {

/// Plain decimals are written down to 10⁻⁶ and below 10⁶; beyond, a power of ten reads better.
constexpr int kMaxPlainDecimals = 6;
constexpr int kMinPlainExponent = -4, kMaxPlainExponent = 5;

/// The decimal exponent of |v| after rounding to `significant` digits (9.996 to 3 digits: 1).
int rounded_exponent(double v, int significant) {
  const std::string e = fmt::format("{:.{}e}", std::fabs(v), std::max(significant - 1, 0));
  return std::atoi(e.c_str() + e.find('e') + 1);
}

/// Trailing zeros of a decimal fraction dropped, and the point when nothing follows it.
std::string trimmed(std::string s) {
  if (s.find('.') == std::string::npos) return s;
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  return s;
}

/// `v` with `decimals` digits after the point (none when negative: rounded to 10^-decimals).
std::string fixed(double v, int decimals) {
  if (decimals >= 0) return fmt::format("{:.{}f}", v, decimals);
  const double step = std::pow(10.0, -decimals);
  return fmt::format("{:.0f}", std::round(v / step) * step);
}

std::string superscript(int n) {
  static constexpr const char* kDigits[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹"};
  std::string s = n < 0 ? "⁻" : "";
  for (char c : std::to_string(std::abs(n))) s += kDigits[c - '0'];
  return s;
}

bool plain(int exponent, int last_digit) { return exponent <= kMaxPlainExponent && -last_digit <= kMaxPlainDecimals; }

}  // namespace

std::string power_of_ten(int exponent) {
  return (language() == Language::Russian ? "·10" : " × 10") + superscript(exponent);
}

std::string number_text(double v, int significant) {
  if (!std::isfinite(v)) return fmt::format("{}", v);
  if (v == 0) return "0";
  significant = std::max(significant, 1);
  const int e = rounded_exponent(v, significant);
  if (e >= kMinPlainExponent && e <= kMaxPlainExponent) return trimmed(fixed(v, std::max(significant - 1 - e, 0)));
  return trimmed(fixed(v / std::pow(10.0, e), significant - 1)) + power_of_ten(e);
}

int gum_last_digit(double u) {
  int e = rounded_exponent(u, 2);
  const double lead = std::round(u / std::pow(10.0, e - 1));  // two digits, 10 … 99 (100 rounds up e)
  // 1.0 … 2.9: two significant digits; 3 … 9.9: one (and 9.5 … 9.9 round to 10, two digits again).
  if (lead < 30) return e - 1;
  if (std::round(u / std::pow(10.0, e)) >= 10) ++e;
  return std::round(u / std::pow(10.0, e)) < 3 ? e - 1 : e;
}

std::string number_at(double v, int last_digit) {
  if (!std::isfinite(v)) return fmt::format("{}", v);
  const double rounded = std::round(v / std::pow(10.0, last_digit)) * std::pow(10.0, last_digit);
  const int e = rounded == 0 ? last_digit : rounded_exponent(rounded, 15);
  if (plain(e, last_digit)) return fixed(rounded, -last_digit);
  const int p = std::max(e, last_digit);
  return fixed(rounded / std::pow(10.0, p), p - last_digit) + power_of_ten(p);
}

std::string value_with_uncertainty(double v, double u) {
  if (!(u > 0) || !std::isfinite(u) || !std::isfinite(v)) return number_text(v, 3);
  const int d = gum_last_digit(u);
  const double step = std::pow(10.0, d);
  const double rv = std::round(v / step) * step, ru = std::round(u / step) * step;
  const int e = rounded_exponent(std::max(std::fabs(rv), ru), 15);
  if (plain(e, d)) return fixed(rv, -d) + " ± " + fixed(ru, -d);
  const int p = std::max(e, d);
  const double scale = std::pow(10.0, p);
  return fmt::format("({} ± {}){}", fixed(rv / scale, p - d), fixed(ru / scale, p - d), power_of_ten(p));
}

std::string interval_at(double lo, double hi, int last_digit) {
  const double m = std::max(std::fabs(lo), std::fabs(hi));
  const int e = m == 0 ? last_digit : rounded_exponent(m, 15);
  if (plain(e, last_digit)) return fmt::format("[{}, {}]", fixed(lo, -last_digit), fixed(hi, -last_digit));
  const int p = std::max(e, last_digit);
  const double scale = std::pow(10.0, p);
  return fmt::format("[{}, {}]{}", fixed(lo / scale, p - last_digit), fixed(hi / scale, p - last_digit),
                     power_of_ten(p));
}

std::string unit_text(std::string_view ascii) {
  static constexpr std::array<std::array<const char*, 2>, 19> kLabels{{{"deg/h", N_("°/h")},
                                                                       {"Hz", N_("Hz")},
                                                                       {"s", N_("s")},
                                                                       {"deg/s", N_("°/s")},
                                                                       {"deg/sqrt(h)", N_("°/√h")},
                                                                       {"deg/h/sqrt(h)", N_("°/h/√h")},
                                                                       {"deg/h^2", N_("°/h²")},
                                                                       {"arcsec", N_("″")},
                                                                       {"ug", N_("µg")},
                                                                       {"m/s^2", N_("m/s²")},
                                                                       {"m/s/sqrt(h)", N_("m/s/√h")},
                                                                       {"m/s/h/sqrt(h)", N_("m/s/h/√h")},
                                                                       {"m/s/h^2", N_("m/s/h²")},
                                                                       {"rad/s/sqrt(Hz)", N_("rad/s/√Hz")},
                                                                       {"rad/s^2/sqrt(Hz)", N_("rad/s²/√Hz")},
                                                                       {"m/s^2/sqrt(Hz)", N_("m/s²/√Hz")},
                                                                       {"m/s^3/sqrt(Hz)", N_("m/s³/√Hz")},
                                                                       {"m/s", N_("m/s")},
                                                                       {"rad", N_("rad")}}};
  for (const auto& [ascii_name, label] : kLabels)
    if (ascii == ascii_name) return tr(label);
  return std::string(ascii);
}

}  // namespace rwcalc
