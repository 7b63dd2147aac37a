// Built by the test `trf_checks_its_format_string` only, where it must fail: trf() checks its
// English format string against the arguments at compile time, and this one has two replacement
// fields for one argument.
#include <string>

#include "rwcalc/i18n.hpp"

std::string two_fields_one_argument() { return rwcalc::trf("{} samples in {}", 1); }
