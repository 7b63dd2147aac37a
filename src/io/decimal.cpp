// Clinger's exact case (W. D. Clinger, "How to read floating point numbers accurately", PLDI 1990):
// a decimal w·10^−k whose digits w are below 2^53 and whose k is at most 22 has w and 10^k exact in
// a double, so the one division w / 10^k, correctly rounded by IEEE 754 arithmetic (SSE2 on
// x86-64: no extended-precision double rounding), is the decimal correctly rounded, which is what
// std::from_chars gives. std::from_chars spends most of its time on the general case this skips.
#include "decimal.hpp"

#include <cstdint>

namespace rwcalc::detail {

namespace {

constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

constexpr bool digit(char c) noexcept { return c >= '0' && c <= '9'; }

// The digits from q on added to w (modulo 2^64 past 19 digits: such a number is refused by count).
const char* digits(const char* q, const char* end, std::uint64_t& w) noexcept {
  for (; q < end && digit(*q); ++q) w = w * 10 + static_cast<unsigned char>(*q - '0');
  return q;
}

}  // namespace

std::from_chars_result read_decimal(const char* p, const char* end, double& v) noexcept {
  const bool neg = p < end && *p == '-';
  const char* const whole = p + neg;
  std::uint64_t w = 0;
  const char* q = digits(whole, end, w);
  const auto int_digits = q - whole;
  std::ptrdiff_t frac = 0;
  bool plain = int_digits > 0;
  if (q < end && *q == '.') {
    const char* const point = q;
    q = digits(point + 1, end, w);
    frac = q - point - 1;
    plain = plain && frac > 0;  // "5." and ".5" go to from_chars
  }
  // At most 19 digits, so at most 18 after the point (far within the 22 powers that are exact).
  const bool exact_case =
      plain && int_digits + frac <= 19 && w <= (std::uint64_t{1} << 53) && !(q < end && (*q == 'e' || *q == 'E'));
  if (!exact_case) return std::from_chars(p, end, v);
  const double x = static_cast<double>(w) / kPow10[frac];
  v = neg ? -x : x;
  return {q, std::errc()};
}

}  // namespace rwcalc::detail
