// The version and the commit (written into the build tree by cmake/commit.cmake at each build).
#include "rwcalc/version.hpp"

#include "rwcalc_commit.hpp"

namespace rwcalc {

std::string_view version() { return RWCALC_VERSION; }

std::string_view commit() { return RWCALC_COMMIT; }

std::string version_line() { return "rwcalc " + std::string(version()) + " (commit " + std::string(commit()) + ")"; }

}  // namespace rwcalc
