#pragma once
/// @file encode.hpp
/// Outside text (file names, column names, option values) encoded for a program that reads it as
/// data: a YAML loader, a browser given a file URL. One encoder per consumer; every string of
/// outside origin reaching that consumer goes through it. (For people, gnuplot and HTML the text
/// is made printable: printable.hpp.)
#include <optional>
#include <string>
#include <string_view>

namespace rwcalc {

/// Is `text` valid UTF-8 (no stray, truncated or overlong sequence, surrogate or code point
/// beyond U+10FFFF)?
[[nodiscard]] bool valid_utf8(std::string_view text);

/// `text` as one YAML double-quoted scalar that every YAML 1.1 and 1.2 loader reads back as
/// exactly `text`: `"` and `\` escaped, and as \xNN, \uNNNN or \UNNNNNNNN every character YAML
/// does not allow raw or folds (C0 and C1 controls, DEL, NEL, the line and paragraph separators,
/// noncharacters such as U+FFFE), the byte-order mark and the bidirectional controls. Nothing
/// when `text` is not UTF-8: a YAML string is Unicode, so such bytes cannot be carried.
[[nodiscard]] std::optional<std::string> yaml_quoted(std::string_view text);

/// `text` for the inside of a YAML comment: printable() (one line, nothing YAML forbids).
[[nodiscard]] std::string yaml_comment(std::string_view text);

/// The file: URL of an absolute path (RFC 3986 and 8089): every byte other than the unreserved
/// characters A–Z a–z 0–9 - . _ ~ and the separator / percent-encoded, so that '#', '?', '%',
/// blanks and bytes that are not UTF-8 are part of the path the browser opens, never a fragment,
/// a query or an escape.
[[nodiscard]] std::string file_url(std::string_view absolute_path);

}  // namespace rwcalc
