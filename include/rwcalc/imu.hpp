#pragma once
/// @file imu.hpp
/// A whole IMU from one recording: every gyro and accelerometer column analysed (in parallel), one
/// table per sensor kind, the JSON `channels` list, and the Kalibr/OpenVINS noise file.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/analysis.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/sensor.hpp"

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

/// The JSON of one channel: column, sensor kind, input, units, mean, Allan deviation and the fit's
/// coefficients in the shown units and in SI, with their meaning for the kind.
nlohmann::json channel_json(const AnalysisResult& r, const UnitSet& shown);
/// `rwcalc imu --json`: source, rate, the `channels` list and the noise densities per axis.
nlohmann::json to_json(const ImuResult& r);
/// The readable report: one table per sensor kind, each axis' coefficients with 95 % intervals.
std::string format_imu(const ImuResult& r);
/// One channel's readable report (`analyze` of an accelerometer column).
std::string format_channel(const AnalysisResult& r, const UnitSet& shown);

/// How the noise file combines the axes of one kind.
enum class AxisCombination { Worst, Mean };

struct KalibrOptions {
  std::string rostopic = "/imu0";
  AxisCombination combine = AxisCombination::Worst;
  /// The keys take every axis; by default only the axes with an accepted fit and a resolved value
  /// (the others named in the comments, with why; when none qualifies, every axis, said in the first lines).
  bool all_axes = false;
};

/// The rostopic as the noise file writes it (one YAML double-quoted scalar, encode.hpp); UsageError
/// naming --rostopic when it is not UTF-8, which no YAML file can carry. The command calls it before
/// it writes anything.
std::string rostopic_scalar(const std::string& rostopic);

/// Kalibr's imu.yaml (OpenVINS reads the same keys): noise densities = N and random walks = K of
/// each kind in SI, the qualifying axes (KalibrOptions::all_axes) combined as asked; each axis' values,
/// and why one is left out, in comments, every outside name in them made a safe comment (yaml_comment).
std::string kalibr_yaml(const ImuResult& r, const KalibrOptions& options = {});

}  // namespace rwcalc
