#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/quantity_text.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file quantity_text.hpp
/// Numbers as a metrology document writes them: never in e-notation (a power of ten is written
/// ·10⁻⁵ in Russian text, × 10⁻⁵ in English), and a value with its uncertainty rounded by the GUM
/// rule (ГОСТ 34100.3-2017, 7.2.6): the uncertainty to two significant digits when its first digit
/// is 1 or 2, else to one, and the value to the same decimal place. The decimal point is written
/// as a point; localize_html() (i18n.hpp) turns it into the Russian comma in the report.
#include <string>
#include <string_view>

namespace rwcalc {

/// `v` to `significant` digits, trailing zeros dropped (as %g), plain for 10⁻⁴ ≤ |v| < 10⁶ and
/// as mantissa and power of ten outside (2.1·10⁻⁵); "nan" and "inf" as such.
[[nodiscard]] std::string number_text(double v, int significant = 3);

/// The power of ten of the last digit the GUM rule keeps of an uncertainty u > 0 (−6 for 2.1·10⁻⁵,
/// 0 for 4.3, 1 for 87).
[[nodiscard]] int gum_last_digit(double u);

/// `v` rounded to the decimal place 10^last_digit and written with every digit down to it
/// (0.000845 for last_digit −6; 1200 for 2), or with a power of ten when that would take more than
/// six decimals or |v| ≥ 10⁶.
[[nodiscard]] std::string number_at(double v, int last_digit);

/// "v ± u" by the GUM rule, a common power of ten put outside ("(8.45 ± 0.21)·10⁻⁸"); u ≤ 0 or not
/// finite: the value alone to three significant digits.
[[nodiscard]] std::string value_with_uncertainty(double v, double u);

/// "[lo, hi]" rounded to the decimal place 10^last_digit (that of the value's uncertainty).
[[nodiscard]] std::string interval_at(double lo, double hi, int last_digit);

/// A unit's ASCII name as JSON writes it ("deg/sqrt(h)", "ug") as a document prints it ("°/√h",
/// "µg"), in the current language; a name it does not know, unchanged. Not encoded for HTML.
[[nodiscard]] std::string unit_text(std::string_view ascii);

/// "·10⁻⁵" (Russian) or " × 10⁻⁵" (English): the factor written after a mantissa.
[[nodiscard]] std::string power_of_ten(int exponent);

}  // namespace rwcalc
