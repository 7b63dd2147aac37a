// Built by the test `layering_numerics_include` only, where it must fail: the io layer may use core
// alone (docs/architecture.md), so a header of the numerics layer stops the compiler.
#include "rwcalc/nnls.hpp"
