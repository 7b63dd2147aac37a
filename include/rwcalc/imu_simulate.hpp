#pragma once
#ifndef RWCALC_USES_SIM
#error "rwcalc/imu_simulate.hpp belongs to the sim layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file imu_simulate.hpp
/// A simulated six-axis IMU record (`rwcalc simulate --layout imu`; docs/simulation.md, "IMU
/// layout"): three gyros and three accelerometers, each axis an exact simulator record of its own
/// white noise N, bias instability B, random walk K and constant bias, read out as a MEMS IMU's
/// digital output is, in whole output steps (LSB) per sample.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "rwcalc/noise_model.hpp"
#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

/// One axis' noise: gyro N °/√h, B °/h, K °/h/√h; accelerometer N m/s/√h, B µg, K m/s/h/√h
/// (the units `rwcalc imu` shows them in).
struct AxisNoise {
  double n = 0, b = 0, k = 0;
};

/// The unit the accelerometer columns are written in (and their names' suffix, _mps2 or _g).
enum class AccelColumnUnit { MetrePerSecond2, G };

struct ImuLayout {
  std::array<AxisNoise, 3> gyro{}, accel{};
  std::array<double, 3> gyro_bias_dps{};  ///< constant gyro biases, °/s
  std::array<double, 3> accel_bias_g{};   ///< constant accelerometer outputs (gravity included), g
  double gyro_lsb_dps = 0.05;             ///< the gyro output step, °/s
  double accel_lsb_mg = 3.33;             ///< the accelerometer output step, mg
  AccelColumnUnit accel_unit = AccelColumnUnit::MetrePerSecond2;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// Levels like the ADIS16405's (docs/imu.md, runs 1–4; its output steps 0.05 °/s and 3.33 mg),
/// the biases of its run 1, gravity on −Z.
[[nodiscard]] ImuLayout adis16405_like_layout();

/// The six column names: gyro_x_dps, gyro_y_dps, gyro_z_dps, then acc_x_mps2 … (or acc_x_g …).
[[nodiscard]] std::array<std::string, 6> imu_columns(const ImuLayout& layout);

/// Axis i (0–2 gyro x–z, 3–5 accelerometer x–z) as the simulator's model, in its units (°/h; an
/// accelerometer's velocity in 1/3600 m/s reads as an angle in ″, units.hpp), with a white read-out.
[[nodiscard]] NoiseModel imu_axis_model(const ImuLayout& layout, std::size_t axis);

/// Axis i's settings: `settings` with the pulse weight of one output step per sample (″, or
/// 1/3600 m/s) and the seed of the axis' own stream.
[[nodiscard]] SimulationSettings imu_axis_settings(const ImuLayout& layout, std::size_t axis,
                                                   const SimulationSettings& settings);

/// Peak bytes a simulation holds: the six axes' counts (8 bytes per sample each) and one axis'
/// flicker FFT (Simulator::memory_bytes).
[[nodiscard]] std::size_t imu_memory_bytes(const ImuLayout& layout, const SimulationSettings& settings);

/// The metadata lines of the record: rate, seed, samples, and every axis' terms with their units.
[[nodiscard]] Metadata imu_metadata(const ImuLayout& layout, const SimulationSettings& settings);

/// Simulates the six axes (each from its own stream of settings.seed) and writes the record:
/// `metadata` as `# key: value` lines, the header, one row per sample of the six outputs (whole
/// steps) in °/s and m/s² or g. Throws UsageError for an invalid layout (validate), OutputError.
void write_imu_record(const ImuLayout& layout, const SimulationSettings& settings, const Metadata& metadata,
                      const std::string& path, bool force, std::FILE* progress = nullptr);

}  // namespace rwcalc
