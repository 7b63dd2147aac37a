#pragma once
#ifndef RWCALC_USES_ANALYSIS
#error "rwcalc/imu.hpp belongs to the analysis layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file imu.hpp
/// A whole IMU from one recording: every gyro and accelerometer column analysed (in parallel), one
/// table per sensor kind, the JSON `channels` list, and the noise file (Kalibr, OpenVINS, VINS-Fusion, ORB-SLAM3).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/sensor.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

struct ImuOptions {
  ReadOptions read;  ///< rate, time tolerance, identification; column, input mode and unit are set per channel
  std::vector<std::string> gyro_columns, accel_columns;  ///< header names or 1-based indices
  std::optional<RateUnit> gyro_unit, accel_unit;         ///< unset: each column name's suffix
  /// Per-sample increments instead of rates: Δθ in an angle unit, Δv in m/s (InputMode::Increment)
  std::optional<AngleUnit> gyro_increment_unit, accel_increment_unit;
  std::string gyro_output_unit, accel_output_unit;  ///< "" : the kind's usual units (sensor.hpp)
  /// The gyro column (as given in gyro_columns) whose axis is vertical: the Earth rate is subtracted
  /// from it and the class verdict given (AnalysisOptions::earth_rate, verdict_wanted).
  std::string vertical_gyro;
  AnalysisOptions analysis;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

struct ImuChannel {
  std::string column;
  SensorKind kind = SensorKind::Gyro;
  AnalysisResult result;
};

struct ImuResult {
  std::string source;
  std::vector<ImuChannel> channels;  ///< gyro columns first, then accelerometer columns, as given
  UnitSet gyro_units, accel_units;   ///< the units results are shown in
};

/// Reads the file once (gzip or text; "-": standard input) and analyses every column given.
/// Throws UsageError when no column is given or a column's unit is of the other sensor kind.
ImuResult analyze_imu(const std::string& path, const ImuOptions& options);

/// `rwcalc imu --json`: source, rate, the `channels` list (each an analysis object, analysis.hpp
/// to_json) and the noise densities per axis.
nlohmann::json to_json(const ImuResult& r);
/// The readable report: one table per sensor kind, each axis' coefficients with 95 % intervals.
std::string format_imu(const ImuResult& r);
/// One channel's readable report (`analyze` of an accelerometer column).
std::string format_channel(const AnalysisResult& r, const UnitSet& shown);

/// How the noise file combines the axes of one kind.
enum class AxisCombination { Worst, Mean };

/// The program a noise file is written for, each with its own keys and layout.
enum class NoiseFormat { Kalibr, OpenVins, VinsFusion, OrbSlam3 };

/// Parses kalibr, openvins, vins-fusion, orb-slam3; UsageError naming --noise-format otherwise.
NoiseFormat parse_noise_format(std::string_view name);
/// Whether the format's consumer can be given discrete-time values (VINS-Fusion: its acc_n ...
/// are used as per-sample deviations by some users); the others convert continuous values themselves.
bool takes_discrete(NoiseFormat format);

struct NoiseFileOptions {
  NoiseFormat format = NoiseFormat::Kalibr;
  std::string rostopic = "/imu0";
  AxisCombination combine = AxisCombination::Worst;
  /// The keys take every axis; by default only the axes with an accepted fit and a resolved value
  /// (the others named in the comments, with why; when none qualifies, every axis, said in the first lines).
  bool all_axes = false;
  double inflate = 1;     ///< every value written is this many times the measured one (≥ 1), said in the file
  bool discrete = false;  ///< discrete-time values: N·√rate, K/√rate (takes_discrete formats only)

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// The rostopic as the noise file writes it (one YAML double-quoted scalar, encode.hpp); UsageError
/// naming --rostopic when it is not UTF-8, which no YAML file can carry. The command calls it before
/// it writes anything.
std::string rostopic_scalar(const std::string& rostopic);

/// The noise file for the format's consumer: noise densities = N and random walks = K of each kind
/// in SI (Kalibr: imu.yaml; OpenVINS: the imu0 block of kalibr_imu_chain.yaml; VINS-Fusion: acc_n,
/// gyr_n, acc_w, gyr_w, g_norm; ORB-SLAM3: IMU.Noise*, IMU.*Walk, IMU.Frequency; OpenCV's %YAML:1.0
/// header for the three that read it with OpenCV), the qualifying axes (all_axes) combined as asked;
/// each axis' values, and why one is left out, in comments, every outside name in them made a safe
/// comment (yaml_comment).
std::string noise_file(const ImuResult& r, const NoiseFileOptions& options = {});

}  // namespace rwcalc
