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

/// Least-squares a·cos(2πft) + b·sin(2πft) on rates `y` of consecutive blocks of `tb` s (level
/// and trend removed) and their standard error √(S/T), S the noise PSD at f as sinusoid_detect
/// takes it (sigma 0: too few blocks). A line A·cos(2πft + φ) gives a = A·s·cos φ,
/// b = −A·s·sin φ, s = sinc(πf·tb).
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
/// Line search on the raw rate samples of a floating series from `f_min` to the Nyquist frequency,
/// at the whole record's resolution and at Welch resolutions, each peak over its local median
/// level; the statistic is the best −ln tail probability less ln of the bins searched. A coherent
/// line is a least-squares sinusoid on the samples, a broadened one its excess power, centroid and
/// spread (phase 0). `f_hint` > 0: the whole record's resolution only, ±3 bins around it.
LineEstimate line_detect(const PhaseSeries& x, double f_min = kHighLineMinHz, double f_hint = 0,
                         bool estimate = true);

struct StepEstimate {
  double statistic = 0;   ///< max local two-window |z|
  double t_s = 0, size = 0, t_sigma = 0, size_sigma = 0;
  double rss = 0;         ///< RSS of level + trend + step on 10-s block means, (°/h)²
};
StepEstimate step_detect(const Decimated& d);

struct WarmupEstimate {
  double statistic = 0;   ///< (RSS(level+trend) − RSS(+exp))/σ̂² on 10-s block means
  double amp = 0, tc = 0, amp_sigma = 0, tc_sigma = 0;
  double rss = 0;
};
WarmupEstimate warmup_detect(const Decimated& d);

/// A record's own candidate (as a model's deterministic terms): the better (lower RSS on the 10-s
/// block means) of its best step and best warm-up. The measurement and every simulated record
/// alike are compared without it.
NoiseModel own_candidates(const Decimated& d);
/// `d` without its own candidate.
Decimated without_own_candidates(const Decimated& d);

/// Overlapping AV at cluster size m of unit white angle noise (3/τ² unfiltered) and of a unit
/// white rate (1/τ) after a first-order output-chain low-pass of time constant tf (0: none).
double output_lowpass_angle_avar(std::size_t m, double tau0, double tf);
double output_lowpass_rate_avar(std::size_t m, double tau0, double tf);

struct OutputLowpassEstimate {
  double statistic = 0;     ///< χ² drop of the short-τ octave AV when the output low-pass joins
  double tf = 0, tf_low = 0, tf_high = 0;  ///< time constant, s, and its Δχ² range
  double white_angle2 = 0;  ///< white angle variance before the filter, ″²
  double white_rate = 0;    ///< white rate N² before the filter, (°/h)²·s
  double points = 0;        ///< octave points used
  double chi2 = 0;          ///< χ² of the best fit (with the filter)
};
/// Fit the octave AV `v` (sizes `m`, EDF `edf`, τ ≤ min(20 s, T/100)) by white angle and rate
/// noise and a floor through a low-pass of time constant tf, against the same without it.
OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration);

}  // namespace rwcalc::diag
