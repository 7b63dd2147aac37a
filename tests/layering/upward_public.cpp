// Built by the test `layering_upward_include` only, where it must fail: the allan layer may use
// core alone (docs/architecture.md), so the simulator's header stops the compiler.
#include "rwcalc/simulate.hpp"
