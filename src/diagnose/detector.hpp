#pragma once
/// @file detector.hpp
/// The detectors of the diagnosis (one file each, detector_*.cpp): their statistics and estimates
/// (docs/diagnosis.md), and the interface through which the pipeline tests and estimates effects.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diagnose/ensemble.hpp"
#include "diagnose/signal.hpp"
#include "model/output_filter.hpp"
#include "rwcalc/diagnose.hpp"

namespace rwcalc::diag {

struct SinusoidEstimate {
  double statistic = 0;  ///< max over f of periodogram / local level
  double f_hz = 0, amp = 0, phase = 0;
  double f_sigma = 0, amp_sigma = 0;
};
/// Periodogram line search on the 0.5-s block rates of `d` (the record without its mean-shape
/// candidate), and from 2.8 to 12 cycles per record a least-squares search on the 10-s block
/// rates of `raw` (default d) with `candidate` fitted jointly. `f_hint` > 0 restricts the search
/// to ±3 bins (in the slow band: the frequency is the hint).
SinusoidEstimate sinusoid_detect(const Decimated& d, double f_hint = 0, bool estimate = true,
                                 const Decimated* raw = nullptr, const NoiseModel* candidate = nullptr);

/// Least-squares a·cos(2πft) + b·sin(2πft) on block rates `y` (`tb` s each) and its standard
/// error (0: too few blocks). A line A·cos(2πft + φ) gives a = A·s·cos φ, b = −A·s·sin φ,
/// s = sinc(πf·tb).
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
/// Line search on the rate samples of a floating series from `f_min` to Nyquist, at the whole
/// record's and at Welch resolutions. `f_hint` > 0: the whole record's resolution, ±3 bins.
LineEstimate line_detect(const PhaseSeries& x, double f_min = kHighLineMinHz, double f_hint = 0, bool estimate = true);

struct StepEstimate {
  double statistic = 0;  ///< max likelihood ratio of one change of the mean
  double t_s = 0, size = 0, t_sigma = 0, size_sigma = 0;
  double rss = 0;  ///< RSS of level + trend + step on 10-s block means, (°/h)²
};
StepEstimate step_detect(const Decimated& d);

/// A change of the mean of exponential form on a linear trend, A·e^{−t/τ} + r·t (+ level): a
/// warm-up transient, or a drift A'·(1 − e^{−t/τ}) + r·t (A' = −A), τ from 20 s to 2T. The linear
/// part r is the rate ramp R of the five-term model, estimated with the exponential.
struct WarmupEstimate {
  double statistic = 0;  ///< RSS drop on 10-s block means when an exponential joins
  double amp = 0, tc = 0, amp_sigma = 0, tc_sigma = 0;
  double ramp = 0, ramp_sigma = 0;  ///< r, °/h² (signed)
  double rss = 0;
  /// The drift's rate slope and curvature at mid-record, °/h² and °/h³ (what a record shorter than
  /// a few τ determines), with their standard errors.
  double slope_mid = 0, slope_mid_sigma = 0, curvature_mid = 0, curvature_mid_sigma = 0;
  /// Whether A, τ and r are separately determined (σ_τ/τ ≤ kDriftSeparableSigma); if not, only
  /// the mid-record slope and curvature are.
  bool separable = true;
};
/// Relative standard error of τ above which A, τ and r are reported as not separately determined.
inline constexpr double kDriftSeparableSigma = 0.5;  // τ within a factor e^{0.5} ≈ 1.65 at 1σ
/// The estimate's noise beyond the 10-s blocks' white scatter: the base model's flicker floor (its
/// Allan variance at T/4 enlarges the standard errors). Not its rate random walk: beside a drift
/// the base takes part of the drift into K (K 0.015 °/h/√h on a warm-up record without any made
/// the errors ×2.3).
struct DriftNoise {
  double b_deg_per_h = 0;
};
/// `tc_hint` > 0: the time constant is that one (a block of the record keeps the record's).
/// Without `noise` the detection statistic (τ searched from 2 blocks to T/3); with it the estimate:
/// τ searched up to 2T, standard errors over all four parameters jointly (τ included, the noise's
/// flicker counted) and the mid-record slope and curvature.
WarmupEstimate warmup_detect(const Decimated& d, double tc_hint = 0, const DriftNoise* noise = nullptr);

/// A record's own mean-shape candidate: its best step or warm-up, whichever has the lower RSS.
/// The measurement and every simulated record alike are compared without it.
NoiseModel own_candidates(const Decimated& d);
/// The same from the step and warm-up fits of the record.
NoiseModel own_candidates(const StepEstimate& st, const WarmupEstimate& w);
Decimated without_own_candidates(const Decimated& d);


struct OutputLowpassEstimate {
  double statistic = 0;                    ///< χ² drop of the short-τ octave AV with the filter
  double tf = 0, tf_low = 0, tf_high = 0;  ///< time constant, s, and its Δχ² range
  double white_angle2 = 0;                 ///< white angle variance before the filter, ″²
  double white_rate = 0;                   ///< white rate N² before the filter, (°/h)²·s
  double points = 0;                       ///< octave points used
  double chi2 = 0;                         ///< χ² of the best fit (with the filter)
};
/// Fit the octave AV `v` (τ ≤ min(20 s, T/100)) by white angle and rate noise and a floor
/// through a low-pass, against the same without it.
OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration);

/// One stretch of data (the whole record or a fold's fitting block) with its base model and
/// that model's ensemble references.
struct Stretch {
  const Recording* rec = nullptr;
  const AnalysisResult* analysis = nullptr;
  const AnalysisOptions* aopt = nullptr;  ///< the five-term fit's options
  const DiagnoseOptions* opt = nullptr;
  NoiseModel base;
  Decimated dec;
  Decimated clean;            ///< dec without its own mean-shape candidate
  MidTauReference ref;        ///< mid-τ AV reference of the base model's ensemble
  MidTauReference clean_ref;  ///< the same of its records without their own candidate
  std::vector<std::int64_t> octave_m;
  SimulationSettings pilot;    ///< settings (and seed) of the base model's pilot ensemble
  std::size_t pilot_runs = 0;  ///< 0: the extended model gets no pilot calibration
  // What the whole record tells the estimates on a block of it:
  double sin_hint_hz = 0;   ///< a named sinusoid's frequency (0: search)
  double line_hint_hz = 0;  ///< a named coherent high-frequency line's frequency (0: search)
  double step_time_s = -1;  ///< a named step's time in stretch time (< 0: estimate it)
  double gm_tc_s = 0;       ///< a named Gauss–Markov term's correlation time (0: fit it)
  double warmup_tc_s = 0;   ///< a named transient's or drift's time constant (0: fit it)
};

/// The extended model under construction: the named terms, the findings in naming order.
struct Extension {
  NoiseModel det;               ///< deterministic terms subtracted from the data
  std::vector<Sinusoid> broad;  ///< broadened lines: in the model, not subtracted
  std::optional<OutputLowpassEstimate> lowpass;
  std::optional<double> ramp;     ///< a named drift's linear part, °/h²: the model's R
  double ramp_sigma = 0;          ///< its standard error, °/h²
  std::vector<double> mid_var;    ///< mid-τ AV of the data without the named terms
  NoiseModel model;               ///< extended model (time origin: the stretch start)
  std::vector<Finding> findings;  ///< parameters only (the caller adds the evidence)
};

/// One record as a detector's statistic reads it: the measurement or a simulated record.
struct RecordView {
  const PhaseSeries& series;
  const Decimated& dec;
  const Decimated& clean;                 ///< dec without its own mean-shape candidate
  const std::vector<double>& octave_var;  ///< overlapping AV at the octave cluster sizes
  /// The step and warm-up fits of dec when already made (for its own candidate), else null.
  const StepEstimate* step = nullptr;
  const WarmupEstimate* warmup = nullptr;
};

/// A record under test and its base model's ensemble.
struct Trial {
  RecordView data;
  const std::vector<RunStats>& runs;
  const Stretch& stretch;
  const SimulationSettings& settings;            ///< of the base ensemble (alternatives reuse its seeds)
  const std::vector<double>* mid_var = nullptr;  ///< mid-τ AV without candidate and named lines
};

class Detector {
 public:
  virtual ~Detector() = default;
  [[nodiscard]] virtual Effect effect() const = 0;
  /// The verdict on the measurement against its base ensemble.
  [[nodiscard]] virtual DetectorResult test(const Trial& t) const = 0;
  /// Whether a fold's fitting block (with its own base ensemble) shows the effect.
  [[nodiscard]] virtual bool shows_in(const Trial& t) const { return test(t).fired; }
  /// Whether the effect is fitted on the mid-τ AV jointly with N, B, K (after the re-fit).
  [[nodiscard]] virtual bool mid_tau() const { return false; }
  /// Whether the effect changes the mean rate (a step or a transient).
  [[nodiscard]] virtual bool mean_shape() const { return false; }
  /// Estimate the effect on a stretch and add it (terms and finding) to the extension.
  virtual void estimate(const Stretch& s, Extension& x) const = 0;
};

/// A detector whose statistic is a function of one record, computed alike on the measurement and
/// on every ensemble record; the threshold is the ensemble's Gumbel (1 − α) quantile.
class RecordDetector : public Detector {
 public:
  [[nodiscard]] virtual double statistic(const RecordView& r) const = 0;
  /// Whether shows_in reads the statistic on a block's own ensemble (which then scores it).
  [[nodiscard]] virtual bool block_statistic() const { return true; }
  /// Whether the statistic reads the raw samples (its nulls are then simulated at full rate).
  [[nodiscard]] virtual bool full_rate() const { return false; }
  [[nodiscard]] DetectorResult test(const Trial& t) const override;
  [[nodiscard]] DetectorResult calibrate(double statistic, const std::vector<RunStats>& runs, double alpha) const;
};

/// z of the threshold's one-sided upper 95 % confidence limit.
inline constexpr double kThresholdUpperZ = 1.645;
/// fired (statistic > threshold), named (> `upper`, at least the threshold) and the excess between.
void set_verdict(DetectorResult& d, double upper);

/// What a detector's statistic is, as the evidence of a finding says.
std::string_view detector_description(Effect e);

/// The detectors of a record in the order of the report. Pulse counts, whole or as numbers
/// (`lattice`), get neither the line nor the low-pass: the counting read-out's beat of the pulse
/// rate against the sampling makes lines and short-τ structure.
std::vector<std::unique_ptr<Detector>> make_detectors(const AnalysisResult& analysis, const PhaseSeries& x,
                                                      bool lattice);
std::unique_ptr<RecordDetector> sinusoid_detector();
std::unique_ptr<RecordDetector> line_detector();
std::unique_ptr<RecordDetector> step_detector();
std::unique_ptr<RecordDetector> warmup_detector();
std::unique_ptr<Detector> gauss_markov_detector();
/// `skip`: why the record cannot have passed through an output-chain filter (empty: it can).
std::unique_ptr<RecordDetector> lowpass_detector(const AnalysisResult& analysis, double duration_s, std::string skip);

}  // namespace rwcalc::diag
