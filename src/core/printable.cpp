// Text from outside made safe to show: one escaping for messages, gnuplot strings and HTML.
#include "rwcalc/printable.hpp"

#include <fmt/format.h>

#include <cstdint>

#include "utf8.hpp"

namespace rwcalc {

namespace detail {

std::size_t utf8_sequence(std::string_view s, std::size_t i, char32_t& code) {
  const auto lead = static_cast<unsigned char>(s[i]);
  std::size_t n = 0;
  char32_t min = 0;
  if (lead < 0x80) {
    code = lead;
    return 1;
  }
  if ((lead & 0xE0) == 0xC0)
    n = 2, code = lead & 0x1F, min = 0x80;
  else if ((lead & 0xF0) == 0xE0)
    n = 3, code = lead & 0x0F, min = 0x800;
  else if ((lead & 0xF8) == 0xF0)
    n = 4, code = lead & 0x07, min = 0x10000;
  else
    return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    const auto b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return 0;
    code = (code << 6) | (b & 0x3F);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return n;
}

}  // namespace detail

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    char32_t code = 0;
    const std::size_t n = detail::utf8_sequence(text, i, code);
    if (n == 0 || code == 0x7F || (code < 0x20 && code != '\n' && code != '\r' && code != '\t'))
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i]));  // invalid byte or C0 control
    else if (code < 0x20)
      out += code == '\n' ? "\\n" : code == '\r' ? "\\r" : "\\t";
    else if (detail::acting_code_point(code) || detail::noncharacter(code))
      out += code > 0xFFFF ? fmt::format("\\U{:08x}", static_cast<std::uint32_t>(code))
                           : fmt::format("\\u{:04x}", static_cast<std::uint32_t>(code));
    else
      out.append(text.substr(i, n));
    i += n == 0 ? 1 : n;
  }
  return out;
}

}  // namespace rwcalc
