#pragma once
/// @file output.hpp
/// Files written by rwcalc appear whole or not at all: content goes to a temporary file in the
/// target directory, is flushed, and is renamed over the target. An existing target is replaced
/// only with `force`. A ".gz" target is gzip-compressed.
#include <string>
#include <string_view>

namespace rwcalc {

/// Write `content` to `path` atomically. "-" writes to standard output. Throws OutputError.
void write_file_atomic(const std::string& path, std::string_view content, bool force);

/// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

}  // namespace rwcalc
