#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/option_words.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file option_words.hpp
/// The values of the enumerated options (--input pulses, --b-estimate fit, --outliers keep…) in
/// words of the output's language, for the reports' settings and the verdict's header.
#include <string>
#include <string_view>

namespace rwcalc {

/// An option's value in words of the current language ("fit" of --b-estimate: "the five-term
/// fit"); a value it does not know is returned as given.
[[nodiscard]] std::string option_value_words(std::string_view option, const std::string& value);

}  // namespace rwcalc
