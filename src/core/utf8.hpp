#pragma once
// Decoding UTF-8 one sequence at a time, for the encoders of outside text (printable.cpp,
// encode.cpp): each decides per code point, and per byte where the text is not UTF-8.
#include <cstddef>
#include <string_view>

namespace rwcalc::detail {

/// Length of the valid UTF-8 sequence at `s[i]` and its code point, or 0 when the bytes there
/// are not valid UTF-8 (a stray continuation byte, a truncated or overlong sequence, a UTF-16
/// surrogate, a code point beyond U+10FFFF).
std::size_t utf8_sequence(std::string_view s, std::size_t i, char32_t& code);

/// Unicode's noncharacters (U+FDD0–U+FDEF and the last two code points of every plane, U+FFFE
/// and U+FFFF among them): reserved for a program's internal use, never text to show or exchange.
constexpr bool noncharacter(char32_t c) { return (c >= 0xFDD0 && c <= 0xFDEF) || (c & 0xFFFE) == 0xFFFE; }

/// Code points that act on a terminal or on the layout of text rather than show: the C1
/// controls, the line and paragraph separators, and the bidirectional embeddings, overrides and
/// isolates (which can make a name read differently from its bytes).
constexpr bool acting_code_point(char32_t c) {
  return (c >= 0x80 && c <= 0x9F) || c == 0x2028 || c == 0x2029 || (c >= 0x202A && c <= 0x202E) ||
         (c >= 0x2066 && c <= 0x2069);
}

}  // namespace rwcalc::detail
