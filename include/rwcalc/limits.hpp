#pragma once
/// @file limits.hpp
/// The usable ranges of the scales a record is read and simulated with: far wider than any
/// instrument needs, and narrow enough that τ², squared phase differences and their sums stay
/// well inside a double (beyond them a record would underflow to "noiseless" or overflow).
namespace rwcalc {

inline constexpr double kMinRateHz = 1e-9;  ///< sample rate, Hz
inline constexpr double kMaxRateHz = 1e9;
inline constexpr double kMinScaleArcsec = 1e-9;  ///< pulse weight, ″ per pulse
inline constexpr double kMaxScaleArcsec = 1e9;
/// Largest rate an option may give (Earth rate, bias, noise terms), °/h: keeps rate × duration finite.
inline constexpr double kMaxRateDegPerH = 1e9;
inline constexpr double kMinTemperatureC = -273.15;
inline constexpr double kMaxTemperatureC = 1000.0;
/// The range of the rates a record may hold, in its deviation unit (°/h for a gyro, m/s/h for an
/// accelerometer, 1 for a clock's frequency): any rate sample, or rate between two angle samples,
/// beyond ±kMaxDataRate, or a record whose largest rate is below kMinDataRate, is refused. Within
/// them the Allan variances, the noise fit (whose weights are squared variances) and the bootstrap
/// of the cross-checks stay far inside a double; beyond them the fit overflows or underflows
/// (from about 1e76 and 1e-72).
inline constexpr double kMaxDataRate = 1e50;
inline constexpr double kMinDataRate = 1e-50;

}  // namespace rwcalc
