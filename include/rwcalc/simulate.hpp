#pragma once
/// @file simulate.hpp
/// Exact discrete-time simulation of gyro pulse records from a NoiseModel (noise-models.md §3):
/// each term's angle at t_k = k·τ0 by the exact discretisation of its continuous model, counted
/// in whole pulses of q ″ with θ kept as whole pulses plus a fraction, so that nothing is lost
/// over 10⁷ samples.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "rwcalc/noise_model.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

/// How a Simulator generates the flicker (bias-instability) rate.
enum class SimulationPath {
  /// Kasdin filter at τ0 over the whole record (an FFT of ≥ 2× the record): the reference,
  /// used for every file `rwcalc simulate` writes.
  Exact,
  /// For ensembles: the Kasdin flicker at τd = D·τ0 (D = flicker_decimation(rate), ≈ 0.1 s),
  /// held over each block of D samples. Its expected AV is fast_flicker_avar(): within 0.4 % of
  /// the exact flicker AV for τ ≥ 10·τd, 20 % low at τd. Every other term as on the Exact path.
  Ensemble,
};

/// Decimation D of the Ensemble path's flicker for a sample rate: the largest D with
/// rate/D ≥ 10 Hz (1, i.e. no decimation, at rates below 20 Hz).
[[nodiscard]] std::size_t flicker_decimation(double rate_hz);

/// Expected AV (°/h)² at cluster size m of the Ensemble path's flicker with decimation D: the
/// decimated rate's structure function through the hold and the Allan filter, averaged over the
/// D block phases. Equal to flicker_avar for D = 1, and returns it for m > 256·D (< 1e-4 apart).
[[nodiscard]] double fast_flicker_avar(double b_deg_per_h, std::size_t m, std::size_t decimation);

/// Simulate one record. counts[0] = 0; counts.size() = samples + 1; with an output-chain low-pass
/// (NoiseModel::output_lowpass_tc_s) values[0] = 0, values.size() = samples + 1 in ″ and no counts.
/// Throws UsageError.
PhaseSeries simulate(const NoiseModel& model, const SimulationSettings& settings);

/// A piece of a record handed out as it is generated (Simulator::stream): samples
/// first … first + size − 1 (first ≥ 1; C_0 = 0 is not handed out). An exact record fills
/// `counts` (C_k); one with an output-chain low-pass fills `angles` (θ_k, ″) instead.
struct RecordBlock {
  std::size_t first = 1;
  std::span<const std::int64_t> counts;
  std::span<const double> angles;
};

/// Bound on |C_k| (pulses) of a simulated record: 2^61, so that every count and increment fits
/// in 64 bits. A model whose angle goes beyond it is refused (UsageError naming the sample).
inline constexpr double kMaxSimulatedPulses = 2305843009213693952.0;

/// Repeated simulation of one model at one length: the FFT plan, the flicker filter spectrum and
/// the buffers are made once and reused by every run.
class Simulator {
 public:
  /// Throws UsageError (validate). `path` chooses how the flicker term is generated.
  explicit Simulator(NoiseModel model, SimulationSettings settings,
                     SimulationPath path = SimulationPath::Exact);
  ~Simulator();
  Simulator(Simulator&&) noexcept;
  Simulator& operator=(Simulator&&) noexcept;

  /// One realisation with `seed` (settings.seed is ignored); `out` is resized and overwritten.
  /// Throws UsageError when the angle leaves the range of a pulse count (kMaxSimulatedPulses).
  void run(std::uint64_t seed, PhaseSeries& out);

  /// The same realisation as run(seed, …), handed to `sink` in order, block by block (at most 256
  /// samples each), so that memory does not grow with the record (except the flicker's FFT). With
  /// an output-chain low-pass it is generated twice: the filter starts at the record's mean rate.
  void stream(std::uint64_t seed, const std::function<void(const RecordBlock&)>& sink);

  [[nodiscard]] const NoiseModel& model() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Per-sample pulse increments c_k = C_k − C_{k−1}, k = 1..M, of an exact series.
[[nodiscard]] std::vector<std::int64_t> pulse_increments(const PhaseSeries& series);

}  // namespace rwcalc
