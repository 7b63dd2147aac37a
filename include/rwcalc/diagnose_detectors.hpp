#pragma once
/// @file diagnose_detectors.hpp
/// The building blocks of the diagnosis (diagnose.hpp): the angle decimated to about 10 Hz that
/// every detector reads, the detector statistics and their least-squares estimators, the
/// ensemble band and the Gumbel calibration of the thresholds. docs/diagnosis.md explains each.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/series.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::diag {

/// The angle decimated to about 10 Hz: θ_j = x(jD) − x(0), ″ (gyro phase units).
struct Decimated {
  double tau_d = 0.1;               ///< decimated period, s
  std::vector<double> theta;        ///< θ_0 = 0 … θ_L
  [[nodiscard]] double duration() const { return theta.size() > 1 ? tau_d * double(theta.size() - 1) : 0.0; }
};

/// Decimation factor for a sample rate (rate/D ≈ 10 Hz; 1 below 20 Hz).
std::size_t decimation(double rate_hz);
Decimated decimate(const PhaseSeries& x, std::size_t first = 0, std::size_t last = 0);

/// Mean rates over blocks of `per_block` decimated periods, °/h.
std::vector<double> block_rates(const Decimated& d, std::size_t per_block);

/// Dense τ grid of the mid-τ detectors (cluster sizes in decimated periods).
std::vector<std::size_t> mid_tau_grid(const Decimated& d);
/// Overlapping AV of the decimated angle at those cluster sizes, (°/h)².
std::vector<double> decimated_avar(const Decimated& d, const std::vector<std::size_t>& grid);

// ---- deterministic effects -----------------------------------------------------------------

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
/// (a Welch resolution wins) by its excess power over the surrounding level (amplitude √(2·power)),
/// its centroid and spread, phase 0. The amplitude is the continuous rate's (the sample mean
/// attenuates it by sinc(π f τ0)); the phase is that of amp·cos(2πf t + phase), t from x(0).
/// `f_hint` > 0: the whole record's resolution only, ±3 bins around it.
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

/// Angle (″) at time t of the deterministic terms of a model that a finding adds (sinusoids,
/// steps, warm-ups), relative to t = 0.
double deterministic_angle(const NoiseModel& m, double t);
/// Subtract the deterministic findings of `m` from the decimated angle (t0: time of θ_0).
void subtract_deterministic(Decimated& d, const NoiseModel& m, double t0 = 0);

/// A record's own candidate, as the deterministic terms of a model: the better (lower RSS on the
/// 10-s block means) of the best bias step and the best warm-up transient. The base model is
/// calibrated, and the mid-τ AV compared, on records without their own candidate — the
/// measurement and every simulated record alike, so that the shrinking of the AV by the removal
/// is the same on both sides.
NoiseModel own_candidates(const Decimated& d);
/// `d` without its own candidates.
Decimated without_own_candidates(const Decimated& d);
/// `d` without its own mean-shape candidate only: what the sinusoid detector reads (a step left
/// in spreads over the low-frequency periodogram and can stand out as a line).
Decimated without_mean_shape(const Decimated& d);

// ---- stochastic effects in the mid-τ Allan variance -----------------------------------------

/// Ensemble reference of the mid-τ AV: mean and variance over the runs per τ.
struct MidTauReference {
  std::vector<std::size_t> grid;
  std::vector<double> tau;
  std::vector<double> mean, var;
  /// Sample covariance of the runs' AV between grid points (row-major, grid.size()²; the
  /// overlapping AV at neighbouring τ is strongly correlated); empty: treated as independent.
  std::vector<double> cov;
};

struct ShapeEstimate {
  double statistic = 0;   ///< χ² drop when a Gauss–Markov bump joins the free Q, N, B, K corrections
  double scale = 0, scale_sigma = 0;   ///< its variance σ², (°/h)², and standard error
  double time = 0, time_low = 0, time_high = 0;  ///< its correlation time and the Δχ² = 1 range, s
  std::array<double, 4> dc{0, 0, 0, 0};  ///< corrections of the fit-scale Q², N², B², K² at the optimum
  /// White rate noise left beside the bump, c_N,base + ΔN² ≥ 0 (fit scale, (°/h)²·s), and its
  /// standard error. A bump with no white noise left is a low-pass of the white noise.
  double white_rest = 0, white_rest_sigma = 0;
  /// Largest rise of the fitted mid-τ AV (bump plus corrections) above the reference, in
  /// ensemble standard deviations: a Gauss–Markov term adds variance somewhere; a fit that only
  /// lowers the AV (a deficit) is not one.
  double excess = 0;
  /// The bump's AV at its peak (τ = 1.89·Tc) over the reference's mean AV there: how far it stands
  /// above the local Allan variance.
  double peak_ratio = 0;
};
enum class Shape { GaussMarkov, Lowpass };
/// AV of a unit-variance Gauss–Markov process (Shape::GaussMarkov, time = Tc) or minus the AV
/// removed from a unit white rate (°/h·√s)² by a first-order low-pass (Shape::Lowpass, time = τf).
/// A low-passed white rate is a Gauss–Markov process: white(τ) + lowpass(τ) = GM(τ)/(2τf).
double shape_avar(Shape s, double tau, double time);
/// Fit `v` (measured mid-τ AV) against the reference plus Q, N, B, K corrections plus a
/// Gauss–Markov bump; `c_base` holds the reference model's Q², N², B², K² on the fit scale: the
/// corrected N², B², K² are kept ≥ 0 (Q² is free). `fixed_time` > 0: the correlation time is
/// given (only σ² and the corrections are fitted), else searched on a grid.
ShapeEstimate shape_detect(const std::vector<double>& v, const MidTauReference& ref,
                           const std::array<double, 4>& c_base, double fixed_time = 0.0);
/// Corrections of the fit-scale Q², N², B², K² that bring the reference to `v` (weighted least
/// squares with the ensemble's variances, corrected N², B², K² kept ≥ 0): the calibration of the
/// base model by a pilot ensemble.
std::array<double, 4> power_law_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                            const std::array<double, 4>& c_base);
/// The pilot calibration of the base model: as power_law_corrections on τ ≤ tau_max, with K held
/// at the reference model's value (Q², B² and, when `n_free`, N² corrected).
std::array<double, 4> calibration_corrections(const std::vector<double>& v, const MidTauReference& ref,
                                              const std::array<double, 4>& c_base, double tau_max,
                                              bool n_free = true);
/// `v_j` being one ensemble member, its statistic against the leave-one-out reference.
MidTauReference leave_one_out(const MidTauReference& ref, const std::vector<double>& v, std::size_t runs);

// ---- output-chain low-pass in the short-τ Allan variance --------------------------------------

/// Overlapping AV at cluster size m (sample period tau0) of unit white angle noise (σ_θ = 1 ″,
/// 3/τ² unfiltered) after a first-order output-chain low-pass of time constant tf (0: none):
/// ((1 − φ)/(1 + φ))·(3 − 4φ^m + φ^{2m})/τ², φ = e^{−τ0/tf}.
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

// ---- calibration, bands ---------------------------------------------------------------------

/// (1 − α) quantile of a maximum-type statistic from ensemble values (Gumbel fit by moments),
/// never below the largest ensemble value.
double gumbel_threshold(const std::vector<double>& values, double alpha);
double quantile(std::vector<double> v, double p);

/// Per-run Allan variances at the octave cluster sizes and the mid-τ grid, plus detector
/// statistics when `with_detectors`.
struct RunStats {
  std::vector<double> octave_var;
  std::vector<double> mid_var;
  /// With detectors or `clean_mid`: the mid-τ AV after the record's own mean-shape candidate (the
  /// better of the best step and the best warm-up) is removed, as it is from the measurement.
  std::vector<double> mid_var_clean;
  double sin_stat = 0, step_stat = 0, warm_stat = 0;
  double line_stat = 0;  ///< line_detect on the raw samples (only when asked: floating data)
  double mean_rate = 0;  ///< the record's mean rate, °/h
};

/// Simulate `runs` records of `model` and collect their statistics; with `clean_mid` (or
/// `with_detectors`) also the mid-τ AV of each record without its own candidate (own_candidates);
/// with `high_line` also line_detect's statistic of each record.
std::vector<RunStats> run_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                   const std::vector<std::int64_t>& octave_m, const std::vector<std::size_t>& mid_grid,
                                   bool with_detectors, const DiagnoseOptions& options, bool clean_mid = true,
                                   bool high_line = false);

/// The band from the ensemble's octave variances and the measured points.
std::vector<BandPoint> make_band(const std::vector<AllanPoint>& measured, const std::vector<RunStats>& runs,
                                 double level);
MidTauReference make_reference(const std::vector<std::size_t>& grid, double tau_d, const std::vector<RunStats>& runs);

/// The weight of a band point in the misfit: the measured EDF combined with the ensemble's own
/// sampling error (`runs` records) and a 1000-EDF model floor (band_misfit).
double band_nu(double edf, std::size_t runs);
/// Whether a band point enters the misfit (positive measured σ, ensemble mean σ² and EDF).
bool band_point_valid(const BandPoint& b);
/// The band's Gamma deviance terms ν·(r − 1 − ln r), summed, and their number (band_misfit is
/// their mean).
struct BandDeviance {
  double sum = 0;
  std::size_t points = 0;
};
BandDeviance band_deviance(const std::vector<BandPoint>& band, std::size_t runs);

/// Re-fit of a simulated model's N, B and K to the whole band: the changes of their fit-scale c
/// (order N, B, K; term_basis) that minimise the band's Gamma deviance (band_misfit's ν) when the
/// ensemble mean σ² moves by Σ Δc·basis(τ), with every c + Δc ≥ 0 (Fisher scoring with a bounded
/// active set and a halving line search); the terms not in `free` are held. All zero when no
/// change lowers the deviance.
std::array<double, 3> band_refit(const std::vector<BandPoint>& band, std::size_t runs, const std::array<double, 3>& c,
                                 const std::array<bool, 3>& free = {true, true, true});

}  // namespace rwcalc::diag
