#pragma once
#ifndef RWCALC_USES_CLI
#error "rwcalc/cli.hpp belongs to the cli layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file cli.hpp
/// The command-line front end as a library call, so that the executable is a thin main and tests
/// can run every command in-process.
#include <cstdio>
#include <iosfwd>

namespace rwcalc::cli {

/// Parse argv, run the sub-command, print results to `out` and diagnostics to `err`.
/// Returns the process exit status (see error.hpp). Never throws. Long commands draw their
/// progress on `progress` (main gives standard error when it is a terminal; nullptr: none) unless
/// --quiet is given.
int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err, std::FILE* progress = nullptr);

/// Parse argv exactly as run() does, but run no command: returns 0 when a command would run (or
/// help/version was printed), else the exit status run() would give for the arguments. Never
/// throws an rwcalc error; anything else escaping is what run() would report as an internal
/// error (the argument-parsing fuzzer treats it as a finding).
int parse_only(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace rwcalc::cli
