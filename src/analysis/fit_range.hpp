#pragma once
// The analysis layer's checks of the fit: the output-filter test that chooses the fit's lower τ,
// the model-based per-τ bounds, and the warnings that say when the fit fails.
#include <span>
#include <vector>

#include "rwcalc/analysis.hpp"

namespace rwcalc {

/// The AV of a sinusoid of frequency f, ∝ sin⁴(πfτ)/(πfτ)², peaks at τ = this / f.
inline constexpr double kLinePeakTau = 0.371;

/// The short-τ octave points against the extrapolation of the model fitted from τ ≥ 16 τ0: a
/// roll-off of the shortest τ (an output filter) and other departures (a line, a resonance), each
/// more than 10 % of the AV and 5 standard errors (the point's EDF and the extrapolation's variance).
struct OutputFilterCheck {
  bool found = false;          ///< an output filter: the AV at τ0 rolls off below the extrapolation
  double ratio = 1;            ///< measured / extrapolated AV at τ0
  double tc_s = 0;             ///< equivalent first-order time constant, s (when found)
  bool departures = false;     ///< a point above τ0 departs from the extrapolation
  double departure_tau_s = 0;  ///< the largest such τ, s
  double departure_ratio = 1;  ///< measured / extrapolated AV there
  double reference_tau_s = 0;  ///< lower τ of the extrapolating fit, s
  double tau_min_s = 0;        ///< the fit's lower τ that leaves them out (10 τf; twice the departing τ)
};

/// Octave points (τ ascending, the first at m = 1); `fit` as the analysis would fit. Nothing is found
/// for too few points or a failed reference fit.
OutputFilterCheck check_output_filter(std::span<const FitPoint> octave, const FitOptions& fit);

/// The fit's lower τ that leaves a filter of time constant tc_s out (10·τf).
double filter_free_tau_s(double tc_s);

/// The lower τ of the model fit against which check_output_filter compares the short-τ points
/// (16 τ0): structure below it is left out of the fit by the range; above it, it is in the fit.
double short_tau_reference_s(double tau0_s);

/// Variance of the overlapping AV estimate at cluster size m measured from the data, relative to
/// its Gaussian value, over the lags at which white phase noise makes two terms share samples (0, m,
/// 2m; products taken against the disjoint lag 3m). A pulse read-out's count errors are far from
/// Gaussian and their variance follows the fraction of a pulse the angle stands at: the AV of
/// quantization-led points varies less than a Gaussian model says. 1 when the record is too short.
double measured_variance_ratio(const PhaseSeries& x, std::int64_t m);

/// EDF, bounds (at allan.confidence) and α of each overlapping AV point under the fitted model:
/// EDF = 2σ⁴_model/Var(σ̂²), Var from av_covariance (Gaussian), times measured_variance_ratio where
/// white phase noise carries at least half the model AV (when `x` is given); α of the term that leads
/// σ²_model. Other estimators are left as computed (Stable32's noise id). Returns whether it applied.
bool apply_model_bounds(AllanResult& allan, const FitResult& fit, const PhaseSeries* x);

/// A fit the goodness of fit rejects, whose range the short-τ check chose: the lower τ moves up an
/// octave at a time, to at most 32 τ0, until the fit of `points` is accepted (FitRangeChoice::
/// rejected_chi2); `fit` and `fopt` then hold that fit and its options. Unchanged when none is.
void move_past_short_tau_misfit(const std::vector<FitPoint>& points, double tau0_s, FitOptions& fopt,
                                AnalysisResult& r);

/// Where and how a rejected fit departs from its points (empty structure for an accepted fit).
FitMisfit fit_misfit(const AnalysisResult& r);
/// fit_misfit as the JSON of the fit's "misfit" (null for an accepted fit).
nlohmann::json misfit_json(const AnalysisResult& r);

/// A rejected fit gives no class: the verdict is withheld with the reason (the goodness of fit, the
/// range and what the short-τ check and the line search took off) and the command to run next.
void withhold_verdict(const AnalysisResult& r, Verdict& v);

/// The warnings of a result's fit range and goodness of fit (a withheld verdict's first).
std::vector<AnalysisWarning> fit_warnings(const AnalysisResult& r);

}  // namespace rwcalc
