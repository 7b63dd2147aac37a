#pragma once
/// @file simulate.hpp
/// Exact discrete-time simulation of gyro pulse records (noise-models.md §3).
///
/// The sensed angle is generated at the sample instants t_k = k·τ0 in arcseconds (″), each term
/// by the exact discretisation of its continuous model, then counted in whole pulses of q ″:
/// C_k = floor(θ_k/q + u), with θ kept as an integer number of pulses plus a fraction so that
/// nothing is lost over 10⁷ samples. Rates are in °/h (= ″/s), times in seconds.
///
/// Read-out modes:
///  - Counting: u is one random phase for the whole record. The count error is the
///    deterministic sawtooth −frac(θ_k/q + u); its Allan variance is structured (§2.1).
///  - White (dither-like): u = u_k is drawn afresh, uniform on [0, 1), for every sample: the angle
///    is randomised by up to one pulse before counting, as a mechanical dither does. The count
///    error e_k = C_k − θ_k/q then has zero mean given θ and is uncorrelated between samples, with
///    variance frac(θ_k/q)·(1 − frac(θ_k/q)) pulses²; where the fractional part is spread evenly
///    (any non-zero input rate) that averages q²/6, so σ²(τ) = 3Q²/τ² with Q = q/√6
///    (= q/√12 of the counter's own error plus q/√12 of the dither angle; see docs/simulation.md).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rwcalc/series.hpp"

namespace rwcalc {

/// How whole pulses are counted from the sensed angle.
enum class ReadoutMode {
  Counting,  ///< floor of the cumulative angle/q with one fixed phase: sawtooth errors
  White,     ///< dither-like: a fresh uniform phase per sample, white count errors
};

/// A sinusoidal rate Ω0·cos(2πf·t + φ); its angle is (Ω0/2πf)·sin(2πf·t + φ).
struct Sinusoid {
  double f_hz = 0.0;            ///< frequency, Hz
  double amp_deg_per_h = 0.0;   ///< rate amplitude Ω0, °/h
  double phase_rad = 0.0;       ///< phase φ at t = 0, rad
};

/// First-order Gauss–Markov rate dε/dt = −ε/Tc + w, stationary from the start.
struct GaussMarkov {
  double sigma_deg_per_h = 0.0;  ///< stationary standard deviation σ_GM, °/h (qc = σ·√(2/Tc))
  double tc_s = 0.0;             ///< correlation time Tc, s
};

/// A bias jump of `size` at time `t` (from the start of the record).
struct BiasStep {
  double t_s = 0.0;             ///< time of the step, s
  double size_deg_per_h = 0.0;  ///< signed size, °/h
};

/// A warm-up transient amp·exp(−t/tc) added to the bias.
struct Warmup {
  double amp_deg_per_h = 0.0;  ///< rate offset at t = 0, °/h
  double tc_s = 0.0;           ///< time constant of the decay, s
};

/// Temperature of the gyro during the record, for the temperature-driven bias.
struct TemperatureProfile {
  enum class Kind {
    Ramp,   ///< linear from start_c to end_c over the record
    Cycle,  ///< settings.temperature_c + amp_c·sin(2π·t/period_s)
  };
  Kind kind = Kind::Ramp;
  double start_c = 0.0;   ///< Ramp: temperature at t = 0, °C
  double end_c = 0.0;     ///< Ramp: temperature at the end of the record, °C
  double amp_c = 0.0;     ///< Cycle: amplitude, °C
  double period_s = 0.0;  ///< Cycle: period, s
};

/// Bias coefficient·(T(t) − T_nominal), T_nominal = SimulationSettings::temperature_c.
struct TemperatureBias {
  double coefficient_deg_per_h_per_c = 0.0;  ///< °/h per °C
  TemperatureProfile profile;
};

/// Everything the simulated gyro senses and how it is read out. Zero means "term absent".
struct NoiseModel {
  double arw_deg_per_sqrt_h = 0.0;           ///< N, °/√h (σ² = N²/τ)
  double bias_instability_deg_per_h = 0.0;   ///< B, °/h (flicker floor σ² = 2B²ln2/π)
  double rrw_deg_per_h_per_sqrt_h = 0.0;     ///< K, °/h/√h (σ² = K²τ/3)
  double ramp_deg_per_h2 = 0.0;              ///< R, °/h² (σ² = R²τ²/2)
  double bias_deg_per_h = 0.0;               ///< constant bias, °/h
  double earth_rate_deg_per_h = 0.0;         ///< sensed Earth rate, °/h (see earth_rate_at)
  ReadoutMode readout = ReadoutMode::Counting;
  /// Extra white angle noise added before counting (rms per sample), ″ (σ² = 3σ_θ²/τ²).
  double white_angle_arcsec = 0.0;
  std::vector<Sinusoid> sinusoids;
  std::vector<GaussMarkov> gauss_markov;
  std::vector<BiasStep> bias_steps;
  std::vector<Warmup> warmups;
  /// Time constant of a first-order low-pass of the sensed rate inside the sensor, before the
  /// pulses are counted, s (0: none). Its Allan variance is that of a Gauss–Markov rate.
  double lowpass_tc_s = 0.0;
  /// Time constant of a first-order low-pass in the output chain, s (0: none): the read-out's
  /// per-sample rate (counted pulses·q/τ0) is filtered, as by a decimation or dither-stripping
  /// filter, and the record is the integrated filtered rate, a floating angle with sub-pulse
  /// resolution (PhaseSeries::values, no counts). This is what a `lowpass` finding of diagnose
  /// names (docs/diagnosis.md).
  double output_lowpass_tc_s = 0.0;
  std::optional<TemperatureBias> temperature_bias;
};

/// Length, sampling and read-out of a simulated record.
struct SimulationSettings {
  double duration_s = 7200.0;    ///< record length, s (samples = round(duration·rate))
  double rate_hz = 400.0;        ///< sample rate, Hz
  double scale_arcsec = 0.92;    ///< pulse weight q, ″
  std::uint64_t seed = 1;        ///< seed of every random stream
  std::optional<double> temperature_c;  ///< nominal temperature (metadata; temperature bias), °C
  [[nodiscard]] std::size_t samples() const;
  [[nodiscard]] double tau0_s() const { return 1.0 / rate_hz; }
};

/// Vertical component of Earth's rotation at a latitude: Ω_E·sin(lat), °/h.
[[nodiscard]] double earth_rate_at(double latitude_deg);

/// Throw UsageError if a model or settings value is invalid (negative σ, zero time constant,
/// non-finite values, a record shorter than 2 samples, …). `what` prefixes the message.
void validate(const NoiseModel& model, const SimulationSettings& settings);

/// Effective quantization Q of the read-out (rms white angle error), ″: q/√6 for the white
/// read-out with an evenly spread fractional angle; for counting, q/√12 is the nominal level of
/// the (structured, not white) sawtooth.
[[nodiscard]] double readout_q_arcsec(ReadoutMode mode, double scale_arcsec);

/// Theoretical Allan variance (°/h)² at τ = m·τ0 of the random and periodic terms of `model`
/// as simulated: ARW, flicker (exact discrete value, including the small-m overshoot), RRW, ramp,
/// sinusoids, Gauss–Markov, extra white angle noise and the white read-out's quantization.
/// Steps, warm-ups, temperature bias, low-pass and the counting read-out are not included.
[[nodiscard]] double theoretical_avar(const NoiseModel& model, double tau0_s, double scale_arcsec,
                                      std::size_t m);

/// Exact AV of the discrete (Kasdin) flicker with Q_d = B² at cluster size m, (°/h)².
[[nodiscard]] double flicker_avar(double b_deg_per_h, std::size_t m);

/// How a Simulator generates the flicker (bias-instability) rate.
enum class SimulationPath {
  /// Kasdin filter at τ0 over the whole record (an FFT of ≥ 2× the record): the reference,
  /// used for every file `rwcalc simulate` writes. ~0.3–0.6 s per 2-h 400 Hz record.
  Exact,
  /// For ensembles: the Kasdin flicker is generated at the decimated period τd = D·τ0
  /// (D = flicker_decimation(rate), ≈ 0.1 s) and held constant over each block of D samples,
  /// integrated exactly into the angle. Its expected AV is fast_flicker_avar(): within 0.4 %
  /// of the exact flicker AV for τ ≥ 10·τd, 2 % at 4·τd, 20 % low at τd (docs/performance.md).
  /// Every other term is generated exactly as on the Exact path.
  Ensemble,
};

/// Decimation D of the Ensemble path's flicker for a sample rate: the largest D with
/// rate/D ≥ 10 Hz (1, i.e. no decimation, at rates below 20 Hz).
[[nodiscard]] std::size_t flicker_decimation(double rate_hz);

/// Expected AV (°/h)² at cluster size m of the Ensemble path's flicker with decimation D:
/// the Kasdin structure function D_x(h) = (4B²/π)·Σ_{j≤|h|} 1/(2j−1) of the decimated rate,
/// seen through the hold and the m-sample Allan filter, averaged over the D block phases of
/// the overlapping estimator. Exact for D = 1 (then equal to flicker_avar). Cost O(D·(m/D)²):
/// for m > 256·D it returns flicker_avar(B, m), from which it then differs by < 1e-4.
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

/// Bound on |C_k| (pulses) of a simulated record: 2^61, so that every count and every increment
/// C_k − C_{k−1} fits in 64 bits with room to spare. A model whose angle goes beyond it (e.g. a
/// bias of 1e300 °/h) is refused with a UsageError naming the sample, never written as wrapped counts.
inline constexpr double kMaxSimulatedPulses = 2305843009213693952.0;

/// Fast repeated simulation of one model at one length: FFT plans, the flicker filter
/// spectrum and all buffers are made once and reused by every run.
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

  /// The same realisation as run(seed, …), handed to `sink` block by block (at most 256
  /// samples each, in order) as it is generated, so that memory does not grow with the record
  /// (except the flicker term's FFT, which spans the record). With an output-chain low-pass the
  /// record is generated twice: the filter starts at the record's mean rate, known only at its end.
  void stream(std::uint64_t seed, const std::function<void(const RecordBlock&)>& sink);

  [[nodiscard]] const NoiseModel& model() const noexcept;
  [[nodiscard]] const SimulationSettings& settings() const noexcept;
  [[nodiscard]] SimulationPath path() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class Progress;

/// How simulate_ensemble runs.
struct EnsembleOptions {
  SimulationPath path = SimulationPath::Ensemble;
  unsigned threads = 0;           ///< worker threads; 0: all hardware threads
  Progress* progress = nullptr;   ///< advanced once per finished realisation (may be null)
};

/// Seed of realisation `run` of an ensemble whose base seed is `seed` (independent streams).
[[nodiscard]] std::uint64_t ensemble_seed(std::uint64_t seed, std::size_t run) noexcept;

/// Simulate `runs` realisations of one model, settings.seed being the base seed: realisation r
/// uses ensemble_seed(settings.seed, r), so the result does not depend on the thread count.
/// Each worker thread owns one Simulator and one PhaseSeries, reused for all its runs.
/// `consume(r, series)` is called on the worker threads, concurrently for different r; the
/// series is overwritten after it returns. The first exception (from the simulator or
/// `consume`) stops the remaining runs and is rethrown.
void simulate_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                       const std::function<void(std::size_t run, const PhaseSeries& series)>& consume,
                       const EnsembleOptions& options = {});

/// Per-sample pulse increments c_k = C_k − C_{k−1}, k = 1..M, of an exact series.
[[nodiscard]] std::vector<std::int64_t> pulse_increments(const PhaseSeries& series);

// JSON form of the model (the "extended_model" of diagnose uses the same form):
// {"arw_deg_per_sqrt_h", "bias_instability_deg_per_h", "rrw_deg_per_h_per_sqrt_h",
//  "ramp_deg_per_h2", "bias_deg_per_h", "earth_rate_deg_per_h", "readout": "counting"|"white",
//  "white_angle_arcsec", "lowpass_tc_s", "output_lowpass_tc_s",
//  "sinusoids": [{"frequency_hz", "amplitude_deg_per_h", "phase_rad"}],
//  "gauss_markov": [{"sigma_deg_per_h", "correlation_time_s"}],
//  "bias_steps": [{"time_s", "size_deg_per_h"}],
//  "warmups": [{"amplitude_deg_per_h", "time_constant_s"}],
//  "temperature_bias": {"coefficient_deg_per_h_per_c", "profile": {"kind": "ramp"|"cycle", …}}}
// Missing keys mean zero/absent. from_json also accepts a "terms" array of findings in the
// diagnose form ({"effect": "sinusoid", "frequency_hz", "amplitude_deg_per_h", …}).
void to_json(nlohmann::json& j, const NoiseModel& model);
void from_json(const nlohmann::json& j, NoiseModel& model);
void to_json(nlohmann::json& j, const SimulationSettings& settings);

/// Add one diagnose-style finding ({"effect": "sinusoid"|"gauss_markov"|"bias_step"|
/// "warmup_transient"|"lowpass", parameters…}) to a model. Throws UsageError on an unknown effect.
void add_finding(const nlohmann::json& finding, NoiseModel& model);

/// Build a model from `rwcalc analyze --json` output (fit.*.value, mean_rate_deg_per_h…) or from
/// diagnose JSON (its "extended_model", else "base_model"), and fill in rate, duration and
/// temperature of `settings` from it when present. `name` labels errors (InputError).
NoiseModel model_from_analysis_json(const nlohmann::json& j, const std::string& name,
                                    SimulationSettings& settings);
/// The same from a JSON file (`simulate --from`): every value is checked (numbers finite, rate,
/// duration and pulse weight positive, …); an error names the file, the line and the key path.
NoiseModel model_from_analysis_file(const std::string& path, SimulationSettings& settings);

}  // namespace rwcalc
