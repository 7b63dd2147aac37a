#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/output_filter.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
// The first-order output filter (time constant tf) of a sensor's read-out chain, as the Allan
// variance sees it.
#include <cstddef>

namespace rwcalc {

/// Overlapping AV at cluster size m of unit white angle noise and of a unit white rate after a
/// first-order output-chain low-pass of time constant tf (0: none).
double output_lowpass_angle_avar(std::size_t m, double tau0, double tf);
double output_lowpass_rate_avar(std::size_t m, double tau0, double tf);

}  // namespace rwcalc
