#pragma once
// Checks for numeric command-line options. Every option that takes a number gets one of these:
// the value must be a finite number within the range the computation can carry, and the message
// names the value and the range (CLI11 puts the option's name in front). CLI11's own Range and
// PositiveNumber let "nan" through (every comparison with NaN is false), and its unsigned
// conversion turns "-1" into 2^64 − 1, so they are not used.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "rwcalc/limits.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc::cli {

/// Name every numeric check carries (the tests look for it on every numeric option).
inline constexpr const char* kNumberCheck = "NUMBER_CHECK";

/// A finite real number within [lo, hi] (ends as given: rwcalc::Ends), `unit` for the message ("s", "Hz"…).
CLI::Validator real_in(double lo, double hi, const std::string& unit, Ends ends = Ends::Closed);

/// A whole number (decimal digits, an optional '-') within [lo, hi].
CLI::Validator whole_in(std::int64_t lo, std::uint64_t hi);

/// Throws AnalysisError naming the first non-finite number in `result` (its key path) and
/// `source`: no output holds one (JSON would turn it into null, text into "inf").
void require_finite(const nlohmann::json& result, const std::string& source);

}  // namespace rwcalc::cli
