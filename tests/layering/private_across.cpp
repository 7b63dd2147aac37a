// Built by the test `layering_private_include` only, where it must fail: analysis' private header
// is found beside analysis' sources, never through an include path of another layer.
#include "analysis/fit_range.hpp"
