#pragma once
#ifndef RWCALC_USES_SIM
#error "rwcalc/noise_model.hpp belongs to the sim layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file noise_model.hpp
/// What a simulated gyro senses and how it is read out (docs/simulation.md), its theoretical
/// Allan variance and its JSON form. Rates in °/h (= ″/s), angles in ″, times in s.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "rwcalc/validate.hpp"

namespace rwcalc {

/// How whole pulses are counted from the sensed angle.
enum class ReadoutMode {
  Counting,  ///< floor of the cumulative angle/q with one fixed phase: sawtooth errors
  White,     ///< dither-like: a fresh uniform phase per sample, white count errors
};

/// A sinusoidal rate Ω0·cos(2πf·t + φ); its angle is (Ω0/2πf)·sin(2πf·t + φ).
struct Sinusoid {
  double f_hz = 0.0;           ///< frequency, Hz
  double amp_deg_per_h = 0.0;  ///< rate amplitude Ω0, °/h
  double phase_rad = 0.0;      ///< phase φ at t = 0, rad
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
  double arw_deg_per_sqrt_h = 0.0;          ///< N, °/√h (σ² = N²/τ)
  double bias_instability_deg_per_h = 0.0;  ///< B, °/h (flicker floor σ² = 2B²ln2/π)
  double rrw_deg_per_h_per_sqrt_h = 0.0;    ///< K, °/h/√h (σ² = K²τ/3)
  double ramp_deg_per_h2 = 0.0;             ///< R, °/h² (σ² = R²τ²/2)
  double bias_deg_per_h = 0.0;              ///< constant bias, °/h
  double earth_rate_deg_per_h = 0.0;        ///< sensed Earth rate, °/h (see earth_rate_at)
  ReadoutMode readout = ReadoutMode::Counting;
  /// Extra white angle noise added before counting (rms per sample), ″ (σ² = 3σ_θ²/τ²).
  double white_angle_arcsec = 0.0;
  std::vector<Sinusoid> sinusoids;
  std::vector<GaussMarkov> gauss_markov;
  std::vector<BiasStep> bias_steps;
  std::vector<Warmup> warmups;
  double lowpass_tc_s = 0.0;  ///< low-pass of the sensed rate before counting, s (0: none)
  /// Low-pass of the read-out's rate in the output chain, s (0: none): the record becomes a
  /// floating angle (diagnose's `lowpass` finding).
  double output_lowpass_tc_s = 0.0;
  std::optional<TemperatureBias> temperature_bias;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// Length, sampling and read-out of a simulated record.
struct SimulationSettings {
  double duration_s = 7200.0;           ///< record length, s (samples = round(duration·rate))
  double rate_hz = 400.0;               ///< sample rate, Hz
  double scale_arcsec = 0.92;           ///< pulse weight q, ″
  std::uint64_t seed = 1;               ///< seed of every random stream
  std::optional<double> temperature_c;  ///< nominal temperature (metadata; temperature bias), °C
  [[nodiscard]] std::size_t samples() const;
  [[nodiscard]] double tau0_s() const { return 1.0 / rate_hz; }

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// Vertical component of Earth's rotation at a latitude: Ω_E·sin(lat), °/h.
[[nodiscard]] double earth_rate_at(double latitude_deg);

/// Throws UsageError with the first violation of the model's or the settings' rules (negative σ,
/// zero time constant, non-finite, < 2 samples).
void validate(const NoiseModel& model, const SimulationSettings& settings);

/// Quantization Q of the read-out, ″: q/√6 (white), q/√12 (counting: the sawtooth's level).
[[nodiscard]] double readout_q_arcsec(ReadoutMode mode, double scale_arcsec);

/// Theoretical Allan variance (°/h)² at τ = m·τ0 of the random and periodic terms as simulated
/// (not steps, warm-ups, temperature bias, low-pass or the counting read-out).
[[nodiscard]] double theoretical_avar(const NoiseModel& model, double tau0_s, double scale_arcsec, std::size_t m);

/// Exact AV of the discrete (Kasdin) flicker with Q_d = B² at cluster size m, (°/h)².
[[nodiscard]] double flicker_avar(double b_deg_per_h, std::size_t m);

// JSON form of the model (docs/simulation.md; also diagnose's "extended_model"); missing keys
// mean zero. from_json also accepts a "terms" array of findings in the diagnose form.
void to_json(nlohmann::json& j, const NoiseModel& model);
void from_json(const nlohmann::json& j, NoiseModel& model);
void to_json(nlohmann::json& j, const SimulationSettings& settings);

/// Add one diagnose-style finding ({"effect": "sinusoid"|"gauss_markov"|"bias_step"|
/// "warmup_transient"|"lowpass", parameters…}) to a model. Throws UsageError on an unknown effect.
void add_finding(const nlohmann::json& finding, NoiseModel& model);

/// A model from `analyze --json` or diagnose JSON ("extended_model", else "base_model"); fills
/// rate, duration and temperature of `settings` when present. Errors: InputError naming `name`.
/// The fitted model: terms in it at their estimates; terms the fit left out or could not resolve
/// without an estimate are left out, or with `upper_bounds` put in at their 95 % upper bounds.
/// `notes` (if given) receives one line per term left out or at its bound.
NoiseModel model_from_analysis_json(const nlohmann::json& j, const std::string& name, SimulationSettings& settings,
                                    bool upper_bounds = false, std::vector<std::string>* notes = nullptr);
/// The same from a JSON file (`simulate --from`), every value checked.
NoiseModel model_from_analysis_file(const std::string& path, SimulationSettings& settings, bool upper_bounds = false,
                                    std::vector<std::string>* notes = nullptr);

}  // namespace rwcalc
