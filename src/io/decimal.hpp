#pragma once
// The seam of the reader's one speed-only piece: a decimal number read as std::from_chars reads it,
// quicker for the short decimals of recordings (bench/bench_parse.cpp, BM_ReadDecimal*).
#include <charconv>

namespace rwcalc::detail {

/// std::from_chars(p, end, v) for a double, bit for bit: the same value, the same end and the same
/// error. A plain decimal (an optional minus, up to 19 digits with at most one point between two of
/// them, a value below 2^53 before the point is placed, no exponent) is read by one correctly
/// rounded division; anything else by std::from_chars itself.
std::from_chars_result read_decimal(const char* p, const char* end, double& v) noexcept;

}  // namespace rwcalc::detail
