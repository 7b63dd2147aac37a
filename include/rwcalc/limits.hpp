#pragma once
/// @file limits.hpp
/// The usable ranges of the scales a record is read and simulated with. Outside them the
/// computations lose the record rather than fail loudly: a sample period of 1e300 s or a pulse
/// weight of 1e-300″ squares to zero (underflow) in the Allan variance, so the record would look
/// noiseless; their reciprocals overflow. The ranges are far wider than any instrument needs
/// (a clock sampled once a day runs at 1.2e-5 Hz, a fast gyro read-out at 1e5 Hz) and narrow
/// enough that τ², the squares of phase differences and their sums stay well inside a double.
namespace rwcalc {

inline constexpr double kMinRateHz = 1e-9;        ///< sample rate, Hz (a period of 30 years)
inline constexpr double kMaxRateHz = 1e9;         ///< sample rate, Hz
inline constexpr double kMinScaleArcsec = 1e-9;   ///< pulse weight, ″ per pulse
inline constexpr double kMaxScaleArcsec = 1e9;    ///< pulse weight, ″ per pulse
/// Largest rate magnitude an option may give (Earth rate, bias, noise terms), °/h: 1e9 °/h is
/// 7·10^8 turns per second, beyond any sensor, and keeps rate × duration finite.
inline constexpr double kMaxRateDegPerH = 1e9;
/// Temperatures, °C: from absolute zero to well above any test chamber.
inline constexpr double kMinTemperatureC = -273.15;
inline constexpr double kMaxTemperatureC = 1000.0;
/// Smallest magnitude of floating data (phase steps, arcsec or s) that the Allan variance can
/// carry: its squares, divided by τ² up to (1e9 s·2^40)², must stay above the smallest normal
/// double (2.2e-308), with room for the sums.
inline constexpr double kMinDataStep = 1e-100;

}  // namespace rwcalc
