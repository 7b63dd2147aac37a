#pragma once
#ifndef RWCALC_USES_ALLAN
#error "rwcalc/confidence.hpp belongs to the allan layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file confidence.hpp
/// Noise identification and equivalent degrees of freedom for Allan-type variances, and the χ²
/// confidence interval that follows (NIST SP 1065 §5; Greenhall & Riley, PTTI 2003; Riley &
/// Greenhall, EFTF 2004).
#include <cstddef>
#include <cstdint>

#include "rwcalc/allan.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

/// Power-law noise exponent α ∈ [−2, 2] (S_y(f) ∝ f^α) of `x` at averaging factor m, as Stable32
/// identifies it: the lag-1 autocorrelation (Riley & Greenhall 2004) of the phase or averaged
/// frequency decimated to τ = mτ0 (per `domain`) while 30 points remain, differencing up to twice;
/// else the B1 ratio (Howe et al. 2000) for N = the estimator's terms, with R(n) = MVAR/AVAR telling
/// white from flicker PM for MVAR. 0 (white FM) when the data are constant or too short to tell.
int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain = NoiseIdDomain::Phase);

/// Greenhall–Riley EDF for noise exponent alpha (+2 … −4, α + 2d > 1), difference order d (1, 2
/// Allan, 3 Hadamard), stride 1 or m (overlapping), filter 1 or m (modified): the exact BasicSum up
/// to J = 100 terms and the paper's asymptotic tables beyond, as Stable32; 0 when m leaves no term.
double edf_greenhall(int alpha, int d, std::int64_t m, std::size_t n_phase, bool overlapping, bool modified);

/// EDF of an estimator at cluster size m (edf_greenhall, d = 2, the estimator's stride and filter).
double edf_for(Estimator est, int alpha, std::int64_t m, std::size_t n_phase);

/// Two-sided χ² interval {low, high} of σ for a measured variance `var`, EDF `edf` and confidence
/// `p` (e.g. 0.683): σ² ∈ [ν·var/χ²_ν((1+p)/2), ν·var/χ²_ν((1−p)/2)], exact χ² quantiles.
struct DevInterval {
  double low, high;
};
DevInterval chi2_interval(double var, double edf, double p);

}  // namespace rwcalc
