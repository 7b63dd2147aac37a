// Outside text encoded for the programs that read rwcalc's outputs as data (encode.hpp).
#include "rwcalc/encode.hpp"

#include <fmt/format.h>

#include <cstdint>

#include "rwcalc/printable.hpp"
#include "utf8.hpp"

namespace rwcalc {

namespace {

/// The YAML escape of a code point that must not appear raw in a double-quoted scalar, or ""
/// when it may. YAML 1.1 allows raw only tab, LF, CR, U+0020–U+007E, NEL, U+00A0–U+D7FF,
/// U+E000–U+FFFD and beyond U+FFFF; NEL and the separators are line breaks that a loader folds
/// into a space, and the rest are escaped so that the file shows and reads the same everywhere.
std::string yaml_escape(char32_t c) {
  const auto code = static_cast<std::uint32_t>(c);
  switch (c) {
    case '"': return "\\\"";
    case '\\': return "\\\\";
    case '\t': return "\\t";
    case '\n': return "\\n";
    case '\r': return "\\r";
    default: break;
  }
  if (c < 0x20 || (c >= 0x7F && c <= 0x9F)) return fmt::format("\\x{:02x}", code);
  if (detail::acting_code_point(c) || detail::noncharacter(c) || c == 0xFEFF)
    return c > 0xFFFF ? fmt::format("\\U{:08x}", code) : fmt::format("\\u{:04x}", code);
  return {};
}

bool url_unreserved(unsigned char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.' ||
         c == '_' || c == '~';
}

}  // namespace

bool valid_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    char32_t code = 0;
    const std::size_t n = detail::utf8_sequence(text, i, code);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::optional<std::string> yaml_quoted(std::string_view text) {
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size();) {
    char32_t code = 0;
    const std::size_t n = detail::utf8_sequence(text, i, code);
    if (n == 0) return std::nullopt;
    const std::string escape = yaml_escape(code);
    out += escape.empty() ? text.substr(i, n) : std::string_view(escape);
    i += n;
  }
  return out + "\"";
}

std::string yaml_comment(std::string_view text) { return printable(text); }

std::string file_url(std::string_view absolute_path) {
  std::string out = "file://";
  for (const char ch : absolute_path) {
    const auto c = static_cast<unsigned char>(ch);
    if (url_unreserved(c) || c == '/')
      out += ch;
    else
      out += fmt::format("%{:02X}", c);
  }
  return out;
}

}  // namespace rwcalc
