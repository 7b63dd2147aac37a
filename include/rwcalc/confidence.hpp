#pragma once
/// @file confidence.hpp
/// Noise identification and equivalent degrees of freedom for Allan-type variances, and the χ²
/// confidence interval that follows (NIST SP 1065 §5; Greenhall & Riley, PTTI 2003; Riley &
/// Greenhall, EFTF 2004).
#include <cstddef>
#include <cstdint>

#include "rwcalc/allan.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

/// Power-law noise exponent α (S_y(f) ∝ f^α, +2 white PM/quantization … −2 random-walk FM) of
/// `x` at averaging factor m, identified as Stable32 does:
///  - lag-1 autocorrelation (Riley & Greenhall 2004) of the series decimated to τ = mτ0 (phase
///    samples x[0], x[m], … or m-averaged frequencies, per `domain`) when at least 30 such points
///    remain; differencing up to d_max = 2 times;
///  - otherwise the B1 ratio (standard variance / Allan variance of the m-averaged frequencies)
///    against its expected values (Howe, Beard, Greenhall & Riley 2000) for N = the estimator's
///    number of terms, μ = −2 read as flicker PM except for MVAR, where the R(n) = MVAR/AVAR ratio
///    tells white from flicker PM.
/// (compute_allan also carries the previous τ's α over to the longest τ of a run, as Stable32.)
/// Returns an integer in [−2, 2]; 0 (white FM) when the data are constant or too short to tell.
int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est,
                   NoiseIdDomain domain = NoiseIdDomain::Phase);

/// Greenhall–Riley EDF. alpha: noise exponent (+2 … −4, α + 2d > 1); d: 1 first difference,
/// 2 Allan, 3 Hadamard; m: averaging factor; n_phase: number of phase points; overlapping:
/// stride 1 (true) or m; modified: filter factor 1 (true) or m. Uses the exact BasicSum up to
/// J = 100 terms and the paper's asymptotic tables beyond, as Stable32 and allantools do.
/// Returns 0 when m leaves no term.
double edf_greenhall(int alpha, int d, std::int64_t m, std::size_t n_phase, bool overlapping,
                     bool modified);

/// EDF of an estimator at cluster size m (edf_greenhall with d = 2 and the estimator's stride and
/// filter).
double edf_for(Estimator est, int alpha, std::int64_t m, std::size_t n_phase);

/// Two-sided χ² interval of a deviation: {low, high} of σ for a measured variance `var`,
/// EDF `edf` and confidence `p` (e.g. 0.683): σ² ∈ [ν·var/χ²_ν((1+p)/2), ν·var/χ²_ν((1−p)/2)].
/// Exact χ² quantiles (Boost.Math).
struct DevInterval {
  double low;
  double high;
};
DevInterval chi2_interval(double var, double edf, double p);

}  // namespace rwcalc
