#pragma once
#ifndef RWCALC_USES_SIM
#error "rwcalc/simulate.hpp belongs to the sim layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file simulate.hpp
/// Exact discrete-time simulation of gyro pulse records from a NoiseModel (docs/simulation.md).
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
  Exact,  ///< Kasdin filter at τ0 over the whole record; every file `simulate` writes
  /// For ensembles: Kasdin flicker at D·τ0 held over D samples (AV: fast_flicker_avar).
  Ensemble,
};

/// Decimation D of the Ensemble path's flicker for a sample rate: the largest D with
/// rate/D ≥ 10 Hz (1, i.e. no decimation, at rates below 20 Hz).
[[nodiscard]] std::size_t flicker_decimation(double rate_hz);

/// Expected AV (°/h)² at cluster size m of the Ensemble path's flicker with decimation D.
[[nodiscard]] double fast_flicker_avar(double b_deg_per_h, std::size_t m, std::size_t decimation);

/// Simulate one record. counts[0] = 0; counts.size() = samples + 1; with an output-chain low-pass
/// (NoiseModel::output_lowpass_tc_s) values[0] = 0, values.size() = samples + 1 in ″ and no counts.
/// Throws UsageError.
PhaseSeries simulate(const NoiseModel& model, const SimulationSettings& settings);

/// Samples first … first + size − 1 (first ≥ 1) of a streamed record: `counts` (C_k), or with an
/// output-chain low-pass `angles` (θ_k, ″).
struct RecordBlock {
  std::size_t first = 1;
  std::span<const std::int64_t> counts;
  std::span<const double> angles;
};

/// Bound on |C_k| (pulses) of a simulated record: 2^61, so that every count and increment fits
/// in 64 bits. A model whose angle goes beyond it is refused (UsageError naming the sample).
inline constexpr double kMaxSimulatedPulses = 2305843009213693952.0;

/// Repeated simulation of one model at one length (the flicker filter is made once).
class Simulator {
 public:
  /// Throws UsageError (validate). `path` chooses how the flicker term is generated.
  explicit Simulator(NoiseModel model, SimulationSettings settings, SimulationPath path = SimulationPath::Exact);
  ~Simulator();
  Simulator(Simulator&&) noexcept;
  Simulator& operator=(Simulator&&) noexcept;

  /// One realisation with `seed` (settings.seed is ignored); `out` is resized and overwritten.
  /// Throws UsageError when the angle leaves the range of a pulse count (kMaxSimulatedPulses).
  void run(std::uint64_t seed, PhaseSeries& out);

  /// The same realisation as run(seed, …), handed to `sink` block by block in order.
  void stream(std::uint64_t seed, const std::function<void(const RecordBlock&)>& sink);

  [[nodiscard]] const NoiseModel& model() const noexcept;

  /// Peak bytes a simulator of this model and length holds beyond a few MiB: the flicker
  /// (bias-instability) term's single-precision FFT over twice the record, its buffer and plan,
  /// about 21 bytes per sample (17 measured); 0 without that term. simulate compares it with the
  /// memory ceiling before it starts.
  [[nodiscard]] static std::size_t memory_bytes(const NoiseModel& model, const SimulationSettings& settings,
                                                SimulationPath path = SimulationPath::Exact);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Per-sample pulse increments c_k = C_k − C_{k−1}, k = 1..M, of an exact series.
[[nodiscard]] std::vector<std::int64_t> pulse_increments(const PhaseSeries& series);

}  // namespace rwcalc
