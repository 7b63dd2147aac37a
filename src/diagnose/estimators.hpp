#pragma once
/// @file estimators.hpp
/// The statistics of the diagnosis's detectors and the least-squares estimates of their effects
/// (docs/diagnosis.md explains each). Each detector_*.cpp defines its own.
#include <cstdint>
#include <vector>

#include "diagnose/signal.hpp"
#include "rwcalc/series.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

struct SinusoidEstimate {
  double statistic = 0;   ///< max over f of periodogram / local level
  double f_hz = 0, amp = 0, phase = 0;
  double f_sigma = 0, amp_sigma = 0;
};
/// Periodogram line search on 0.5-s block rates. `f_hint` > 0 restricts the search to ±3 bins.
SinusoidEstimate sinusoid_detect(const Decimated& d, double f_hint = 0, bool estimate = true);

/// The least-squares coefficients of a·cos(2πft) + b·sin(2πft) on rates `y` over consecutive
/// blocks of `tb` s (t at the block centres, from 0; level and linear trend removed), and their
/// common standard error √(S/T) from the noise PSD S at f: the Hann periodogram's median over ±24
/// bins, main lobe left out, as sinusoid_detect. sigma 0: too few blocks. A rate line A·cos(2πft
/// + φ) gives a = A·s·cos φ, b = −A·s·sin φ with s = sinc(πf·tb) (block means).
struct LineCoefficients {
  double a = 0, b = 0, sigma = 0;
};
LineCoefficients line_coefficients(std::vector<double> y, double tb, double f);

/// Lower end of the high-frequency line search, Hz: the upper end of sinusoid_detect's.
constexpr double kHighLineMinHz = 0.25;
struct LineEstimate : SinusoidEstimate {
  double resolution_hz = 0;  ///< bin width of the periodogram that showed the line
  bool coherent = true;      ///< found at the whole record's resolution: one phase-stable line
  double width_hz = 0;       ///< spread (standard deviation) of a broadened line's power, Hz
};
/// Line search on the raw rate samples of a floating series, from `f_min` to the Nyquist
/// frequency, at several resolutions: the Hann-windowed periodogram of the whole record (zero-
/// padded 2×) and Welch means of 16384-, 4096- and 1024-sample segments, each over its local
/// median level (±24 bins). The statistic is the largest, over the resolutions, of −ln of the
/// peak's tail probability less ln of the number of bins searched. A line found at the whole
/// record's resolution is estimated by a least-squares sinusoid on the samples; a broadened one
/// by its excess power over the surrounding level (amplitude √(2·power)), its centroid and
/// spread, phase 0. The amplitude is the continuous rate's; the phase is that of
/// amp·cos(2πf t + phase), t from x(0). `f_hint` > 0: the whole record's resolution only, ±3 bins.
LineEstimate line_detect(const PhaseSeries& x, double f_min = kHighLineMinHz, double f_hint = 0,
                         bool estimate = true);

struct StepEstimate {
  double statistic = 0;   ///< max local two-window |z|
  double t_s = 0, size = 0, t_sigma = 0, size_sigma = 0;
  double rss = 0;         ///< RSS of level + trend + step on 10-s block means, (°/h)²
};
StepEstimate step_detect(const Decimated& d);
/// A bias step at a known time `ts`: its size from the mean rates over up to 30 min each side.
StepEstimate step_at(const Decimated& d, double ts);

struct WarmupEstimate {
  double statistic = 0;   ///< (RSS(level+trend) − RSS(+exp))/σ̂² on 10-s block means
  double amp = 0, tc = 0, amp_sigma = 0, tc_sigma = 0;
  double rss = 0;
};
WarmupEstimate warmup_detect(const Decimated& d);

/// A record's own candidate, as the deterministic terms of a model: the better (lower RSS on the
/// 10-s block means) of the best bias step and the best warm-up transient. The base model is
/// calibrated, and the mid-τ AV compared, on records without their own candidate — the
/// measurement and every simulated record alike.
NoiseModel own_candidates(const Decimated& d);
/// `d` without its own candidate.
Decimated without_own_candidates(const Decimated& d);

/// Overlapping AV at cluster size m (sample period tau0) of unit white angle noise (σ_θ = 1 ″,
/// 3/τ² unfiltered) after a first-order output-chain low-pass of time constant tf (0: none).
double output_lowpass_angle_avar(std::size_t m, double tau0, double tf);
/// The same for a unit white rate (AV 1/τ unfiltered, rate constant over each sample).
double output_lowpass_rate_avar(std::size_t m, double tau0, double tf);

struct OutputLowpassEstimate {
  double statistic = 0;     ///< χ² drop of the short-τ octave AV when the output low-pass joins
  double tf = 0, tf_low = 0, tf_high = 0;  ///< time constant, s, and its Δχ² range
  double white_angle2 = 0;  ///< white angle variance before the filter, ″²
  double white_rate = 0;    ///< white rate N² before the filter, (°/h)²·s
  double points = 0;        ///< octave points used
  double chi2 = 0;          ///< χ² of the best fit (with the filter)
};
/// Fit the octave AV `v` (cluster sizes `m`, EDF `edf`, τ ≤ min(20 s, T/100)) by white angle
/// noise, white rate noise and a constant floor, all through a first-order output-chain low-pass
/// of time constant tf (grid from τ0/4), against the same without the filter (weights EDF/(2v²)).
OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration);

}  // namespace rwcalc::diag
