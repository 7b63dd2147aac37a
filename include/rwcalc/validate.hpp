#pragma once
/// @file validate.hpp
/// Options that check themselves (as Ceres' Options::IsValid): each options struct of the library
/// has `validate()`, which returns the first rule it breaks in words (naming the command-line
/// option where there is one, else the field) or nothing; each entry point that takes the options
/// refuses them through require_valid, so a library user meets the refusal the command line gives.
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "rwcalc/error.hpp"

namespace rwcalc {

/// The first rule an options struct breaks, in words; empty when it keeps them all.
using Violation = std::optional<std::string>;

/// Throws UsageError with `options.validate()`'s message when the options break a rule.
template <class Options>
void require_valid(const Options& options) {
  if (Violation why = options.validate()) throw UsageError(*why);
}

/// The first violation among rules checked in order (each already evaluated).
[[nodiscard]] Violation first_of(std::initializer_list<Violation> rules);

/// Whether an end of a range is included.
enum class Ends { Closed, OpenLow, OpenHigh, Open };

/// A range as messages write it: "[0, 1000] %", "(0, 1)", "(0, inf) s".
[[nodiscard]] std::string range_text(double lo, double hi, std::string_view unit, Ends ends = Ends::Closed);

/// `value` of `what` (an option or field name, never translated) must be a finite number in the range.
[[nodiscard]] Violation check_in(std::string_view what, double value, double lo, double hi, std::string_view unit = {},
                                 Ends ends = Ends::Closed);

}  // namespace rwcalc
