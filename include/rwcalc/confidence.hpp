#pragma once
/// @file confidence.hpp
/// Noise identification and equivalent degrees of freedom for Allan-type variances, and the χ²
/// confidence interval that follows (NIST SP 1065 §5; Greenhall & Riley, PTTI 2003; Riley &
/// Greenhall, EFTF 2004).
#include <cstddef>
#include <cstdint>
#include <span>

namespace rwcalc {

/// Lag-1 autocorrelation noise identification (Riley & Greenhall 2004) of a phase series at
/// averaging factor m, for a variance of difference order d (2: Allan). Returns α rounded to an
/// integer in [−2, 2]. Where too few points remain for the lag-1 method, falls back to the B1
/// bias-ratio method as Stable32 does. `is_phase` is true for phase data.
int identify_noise(std::span<const double> phase, std::int64_t m, int d = 2);

/// Greenhall–Riley EDF. alpha: noise exponent; d: 1 first difference, 2 Allan, 3 Hadamard;
/// m: averaging factor; n_phase: number of phase points; overlapping: stride 1 (true) or m;
/// modified: filter factor 1 (true) or m.
double edf_greenhall(int alpha, int d, std::int64_t m, std::size_t n_phase, bool overlapping,
                     bool modified);

/// Two-sided χ² interval of a deviation: returns {low, high} of σ for a measured variance `var`,
/// EDF `edf` and confidence `p` (e.g. 0.683). Exact χ² quantiles (Boost.Math).
struct DevInterval {
  double low;
  double high;
};
DevInterval chi2_interval(double var, double edf, double p);

}  // namespace rwcalc
