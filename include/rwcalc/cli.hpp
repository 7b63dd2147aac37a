#pragma once
/// @file cli.hpp
/// The command-line front end as a library call, so that the executable is a thin main and tests
/// can run every command in-process.
#include <iosfwd>

namespace rwcalc::cli {

/// Parse argv, run the sub-command, print results to `out` and diagnostics to `err`.
/// Returns the process exit status (see error.hpp). Never throws.
int run(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace rwcalc::cli
