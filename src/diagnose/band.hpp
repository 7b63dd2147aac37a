#pragma once
/// @file band.hpp
/// What the models predict of the Allan variance and of held-out data: the band of σ per τ from a
/// model's theoretical AV and the measured points' χ² EDF (no simulation), and the gain of the
/// extended model in and out of sample (docs/diagnosis.md).
#include "effects.hpp"
#include "rwcalc/diagnose.hpp"

namespace rwcalc::diag {

/// The base band (measured AV against the base model), the extended band (the AV of the record less
/// the named deterministic terms against the extended model), and the gain: the bands' misfit and
/// coverage, and the mean −2 ln L per block of each half predicted from the other (levels and
/// coefficients fitted on one half, the terms' forms from the whole record).
void bands_and_gain(const PhaseSeries& x, const Blocks& b, const GlsModel& base, const GlsModel& extended,
                    DiagnoseResult& r);

}  // namespace rwcalc::diag
