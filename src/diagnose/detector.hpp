#pragma once
/// @file detector.hpp
/// The detector interface of the diagnosis: each effect has one detector (one file each,
/// detector_*.cpp) that tests the measurement against the base model's ensemble, tells whether a
/// block of the out-of-sample check shows the effect, and estimates it on a stretch of data.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diagnose/ensemble.hpp"
#include "diagnose/estimators.hpp"
#include "diagnose/mid_tau.hpp"
#include "diagnose/signal.hpp"
#include "rwcalc/diagnose.hpp"

namespace rwcalc::diag {

/// One stretch of data (the whole record or the fitting block of a fold) with what the
/// estimates on it read: its base model and that model's ensemble references.
struct Stretch {
  const Recording* rec = nullptr;
  const AnalysisResult* analysis = nullptr;
  const AnalysisOptions* aopt = nullptr;  ///< the five-term fit's options
  const DiagnoseOptions* opt = nullptr;
  NoiseModel base;                  ///< its base model
  Decimated dec;                    ///< its decimated angle
  Decimated clean;                  ///< the same without its own mean-shape candidate
  MidTauReference ref;              ///< mid-τ AV reference of the base model's ensemble
  MidTauReference clean_ref;        ///< the same of its records without their own candidate
  std::vector<std::int64_t> octave_m;
  SimulationSettings pilot;         ///< settings (and seed) of the base model's pilot ensemble
  std::size_t pilot_runs = 0;       ///< 0: the extended model gets no pilot calibration
  // What the whole record tells the estimates on a block of it:
  double sin_hint_hz = 0;   ///< a named sinusoid's frequency (0: search)
  double line_hint_hz = 0;  ///< a named coherent high-frequency line's frequency (0: search)
  double step_time_s = -1;  ///< a named step's time in stretch time (< 0: estimate it)
  double gm_tc_s = 0;       ///< a named Gauss–Markov term's correlation time (0: fit it)
};

/// The extended model under construction: the named terms, the findings in naming order.
struct Extension {
  NoiseModel det;                   ///< deterministic terms subtracted from the data
  std::vector<Sinusoid> broad;      ///< broadened lines: in the model, not subtracted
  std::optional<OutputLowpassEstimate> lowpass;
  std::vector<double> mid_var;      ///< mid-τ AV of the data without the named terms (mid-τ fits)
  NoiseModel model;                 ///< extended model (time origin: the stretch start)
  std::vector<Finding> findings;    ///< parameters only (the evidence is added by the caller)
};

/// One record as a detector's statistic reads it: the measurement or a simulated record.
struct RecordView {
  const PhaseSeries& series;
  const Decimated& dec;                   ///< decimated angle
  const Decimated& clean;                 ///< the same without its own mean-shape candidate
  const std::vector<double>& octave_var;  ///< overlapping AV at the octave cluster sizes
};

/// A record under test and its base model's ensemble.
struct Trial {
  RecordView data;
  const std::vector<RunStats>& runs;       ///< the base model's ensemble
  const Stretch& stretch;                  ///< the data as a stretch (base model, references)
  const SimulationSettings& settings;      ///< of the base ensemble (alternatives reuse its seeds)
  const std::vector<double>* mid_var = nullptr;  ///< mid-τ AV without candidate and named lines
};

class Detector {
 public:
  virtual ~Detector() = default;
  [[nodiscard]] virtual Effect effect() const = 0;
  /// The verdict on the measurement against its base ensemble.
  [[nodiscard]] virtual DetectorResult test(const Trial& t) const = 0;
  /// Whether the fitting block of a fold (`t`, with its own base ensemble) shows the effect, so
  /// that the effect enters the block's extended model.
  [[nodiscard]] virtual bool shows_in(const Trial& t) const { return test(t).fired; }
  /// Whether the effect is fitted on the mid-τ AV jointly with N, B, K (after the re-fit).
  [[nodiscard]] virtual bool mid_tau() const { return false; }
  /// Whether the effect changes the mean rate (a step or a transient: one change of the mean).
  [[nodiscard]] virtual bool mean_shape() const { return false; }
  /// Estimate the effect on a stretch and add it (terms and finding) to the extension.
  virtual void estimate(const Stretch& s, Extension& x) const = 0;
};

/// A detector whose statistic is a function of one record, computed alike on the measurement and
/// on every record of an ensemble (RunStats::stat); the threshold is the ensemble's Gumbel
/// (1 − α) quantile.
class RecordDetector : public Detector {
 public:
  [[nodiscard]] virtual double statistic(const RecordView& r) const = 0;
  /// Whether shows_in reads the statistic on a block's own ensemble (which then scores it).
  [[nodiscard]] virtual bool block_statistic() const { return true; }
  [[nodiscard]] DetectorResult test(const Trial& t) const override;
  /// The verdict of a statistic against ensemble values (Gumbel (1 − α) quantile).
  [[nodiscard]] DetectorResult calibrate(double statistic, const std::vector<RunStats>& runs, double alpha) const;
};

/// What a detector's statistic is, as the evidence of a finding says.
std::string_view detector_description(Effect e);

/// The detectors of a record, in the order of the report: sinusoid, bias step, warm-up,
/// Gauss–Markov, low-pass, and the high-frequency line. `analysis` is the record's (the low-pass
/// statistic reads its octave EDF); `lattice`: floating samples on a pulse lattice (on_lattice).
/// Pulse counts, whole or as numbers, get neither the line nor the low-pass: the counting
/// read-out's beat of the pulse rate against the sampling makes lines and short-τ structure.
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
