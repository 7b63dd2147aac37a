#pragma once
/// @file version.hpp
/// Which rwcalc produced a result: the release version and the source commit it was built from.
#include <string>
#include <string_view>

namespace rwcalc {

/// The release version, e.g. "0.1.0".
std::string_view version();
/// The git commit of the build's source tree ("…-modified" when it had uncommitted changes,
/// "unknown" when built outside a git checkout).
std::string_view commit();
/// "rwcalc 0.1.0 (commit 1a2b3c4d5e6f)".
std::string version_line();

}  // namespace rwcalc
