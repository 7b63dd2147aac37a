#pragma once
/// @file lowpass.hpp
/// The output-chain low-pass: the χ² drop of the short-τ octave AV when white angle and rate noise
/// (and a floor) pass through a first-order filter, and its null law.
#include <array>
#include <cstdint>
#include <vector>

namespace rwcalc::diag {

struct OutputLowpassEstimate {
  double statistic = 0;                    ///< χ² drop of the short-τ octave AV with the filter
  double tf = 0, tf_low = 0, tf_high = 0;  ///< time constant, s, and its 95 % interval (0: none)
  double white_angle2 = 0;                 ///< white angle variance before the filter, ″²
  double white_rate = 0;                   ///< white rate N² before the filter, (°/h)²·s
  double points = 0;                       ///< octave points used
  double chi2 = 0;                         ///< χ² of the best fit (with the filter)
  double p = 1;                            ///< bound on the statistic's false-alarm probability
  double threshold = 0;                    ///< the statistic whose bound is α
  double dispersion = 0;  ///< the rate spectrum's deviance per bin over its mean under the fitted filter
};
/// Fit the octave AV `v` (τ ≤ min(20 s, T/100)) by white angle and rate noise and a floor through
/// a low-pass, against the same without it. The statistic, scaled by the best fit's χ² per degree
/// of freedom when above 1, is χ²₁ at each time constant; the bound is Bonferroni over the octave
/// points (time constants an octave apart are the distinct alternatives). The time constant is the
/// AV fit's, without an interval (the octave points are correlated: see output_lowpass_estimate).
OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration, double alpha);

/// The named low-pass's time constant and 95 % interval from the Whittle likelihood of the rate
/// samples' periodogram (`rate`, τ0 apart; frequencies above 1/min(20 s, T/100)), the levels of
/// white angle noise, white rate and flicker profiled; the interval where the deviance rises by
/// χ²₁(0.95) times its overdispersion (deviance per bin over its mean, when above 1). The white
/// levels in `e` are then the octave AV's at that time constant. False (e unchanged) when the
/// record is too short for 8 segments of the spectrum.
bool output_lowpass_estimate(std::vector<double> rate, const std::vector<std::int64_t>& m, const std::vector<double>& v,
                             const std::vector<double>& edf, double tau0, double duration, OutputLowpassEstimate& e);

/// The low-pass out of sample: the octave AV of each half of the record (`v`, the same cluster
/// sizes `m`, EDF `edf` of a half, `duration` a half's) predicted by the filter and levels fitted to
/// the other half, against the same fitted without the filter: the χ² the filter saves, summed over
/// the halves (scaled by the fitted half's χ² per degree of freedom when above 1). NaN when a half
/// has fewer than 5 points.
double output_lowpass_holdout(const std::vector<std::int64_t>& m, const std::array<std::vector<double>, 2>& v,
                              const std::vector<double>& edf, double tau0, double duration);

}  // namespace rwcalc::diag
