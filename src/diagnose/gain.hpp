#pragma once
/// @file gain.hpp
/// What the extended model gains over the base on the block means' likelihood (gls.hpp), in sample
/// and on held-out data (docs/diagnosis.md, "Band and gain").
#include "effects.hpp"

namespace rwcalc::diag {

/// −2 Δ ln L of the base against the extended model: in sample, less 2 per parameter the
/// extended model adds (Akaike's charge: a line 3, a step or a transient 2, a Gauss–Markov term 2);
/// out of sample, the sum over the two halves of the block means of each half's −2 ln L given the
/// other half, every level, coefficient and term fitted on that other half (the terms' forms, a
/// line's frequency, a step's time, a time constant, from the whole record; a term whose columns
/// vanish on the fitted half is left out of both scores).
struct LikelihoodGain {
  double in_sample = 0;
  double holdout = 0;
};
LikelihoodGain block_gain(const Blocks& b, const GlsModel& base, const GlsModel& extended);

/// Akaike's charge, in −2 ln L, of the parameters the extended model adds to the base.
double added_parameter_charge(const GlsModel& base, const GlsModel& extended);

}  // namespace rwcalc::diag
