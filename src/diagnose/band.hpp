#pragma once
/// @file band.hpp
/// What the models predict of the Allan variance: the band of σ per τ from a model's theoretical AV
/// and the measured points' χ² EDF (no simulation), and the bands' misfit (docs/diagnosis.md).
#include "effects.hpp"
#include "rwcalc/diagnose.hpp"

namespace rwcalc::diag {

/// The base band (measured AV against the base model), the extended band (the AV of the record less
/// the named deterministic terms against the extended model), and their misfit and coverage.
void bands(const PhaseSeries& x, DiagnoseResult& r);

}  // namespace rwcalc::diag
