#pragma once
/// @file printable.hpp
/// Text from outside (file names, strings of saved results, command-line arguments) made safe
/// to show: in a message on a terminal, in a gnuplot string, in the HTML report.
#include <string>
#include <string_view>

namespace rwcalc {

/// `text` with every character that could act rather than show replaced by a visible escape:
/// newline, CR and tab as \n, \r, \t; the other C0 controls and DEL as \xNN; C1 controls, the
/// Unicode line/paragraph separators, bidirectional overrides and noncharacters (U+FFFE, U+FDD0…)
/// as \uNNNN (\UNNNNNNNN beyond U+FFFF); each byte that is not part of valid UTF-8 as \xNN.
/// Printable UTF-8 (°, τ, √, quotes, backslashes) is kept. The result is valid UTF-8 with no
/// control character and no noncharacter, so it stays on one line, cannot move the cursor, change
/// colours or end a line of a script, is a valid YAML comment, and never holds the marks of
/// as_typed() (i18n.hpp).
std::string printable(std::string_view text);

}  // namespace rwcalc
