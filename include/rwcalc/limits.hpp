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
/// Smallest floating data step the Allan variance carries: its square over τ² (up to
/// (1e9 s·2^40)²) stays above the smallest normal double.
inline constexpr double kMinDataStep = 1e-100;

}  // namespace rwcalc
