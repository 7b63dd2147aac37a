#pragma once
/// @file noise_model.hpp
/// What a simulated gyro senses and how it is read out: the noise terms (noise-models.md §3), the
/// record's length and sampling, their checks, the Allan variance the terms have in theory, and
/// the model's JSON form. Rates are in °/h (= ″/s), angles in arcseconds (″), times in seconds.
///
/// Read-out modes (docs/simulation.md): Counting takes C_k = floor(θ_k/q + u) with one random
/// phase u for the record, so the count error is a deterministic sawtooth whose Allan variance is
/// structured (§2.1). White draws u afresh for every sample, as a mechanical dither does: the count
/// error is white with mean variance q²/6 (σ²(τ) = 3Q²/τ², Q = q/√6) for any non-zero rate.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

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
  /// per-sample rate is filtered (a decimation or dither-stripping filter) and the record is its
  /// integral, a floating angle (PhaseSeries::values); a `lowpass` finding of diagnose names it.
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
/// non-finite values, a record shorter than 2 samples, …).
void validate(const NoiseModel& model, const SimulationSettings& settings);

/// Quantization Q of the read-out (rms white angle error), ″: q/√6 for the white read-out; for
/// counting, q/√12, the nominal level of the (structured, not white) sawtooth.
[[nodiscard]] double readout_q_arcsec(ReadoutMode mode, double scale_arcsec);

/// Theoretical Allan variance (°/h)² at τ = m·τ0 of the random and periodic terms of `model`
/// as simulated: ARW, flicker (exact discrete value, including the small-m overshoot), RRW, ramp,
/// sinusoids, Gauss–Markov, extra white angle noise and the white read-out's quantization.
/// Steps, warm-ups, temperature bias, low-pass and the counting read-out are not included.
[[nodiscard]] double theoretical_avar(const NoiseModel& model, double tau0_s, double scale_arcsec,
                                      std::size_t m);

/// Exact AV of the discrete (Kasdin) flicker with Q_d = B² at cluster size m, (°/h)².
[[nodiscard]] double flicker_avar(double b_deg_per_h, std::size_t m);

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
