#pragma once
/// @file units.hpp
/// Unit conventions and exact conversion factors.
///
/// Gyro data are carried as an angle in arcseconds (″) sampled every τ0 seconds, so an Allan
/// deviation comes out in ″/s, which is exactly °/h. Noise coefficients are in IEEE 952 units:
///   Q ″ (σ² = 3Q²/τ²), N °/√h (σ² = N²/τ), B °/h (σ² = (2 ln2/π)·B²), K °/h/√h (σ² = K²τ/3),
///   R °/h² (σ² = R²τ²/2).
#include <numbers>

namespace rwcalc::units {

inline constexpr double arcsec_per_deg = 3600.0;
inline constexpr double seconds_per_hour = 3600.0;
inline constexpr double arcsec_per_rad = 180.0 * 3600.0 / std::numbers::pi;
inline constexpr double deg_per_h_per_arcsec_per_s = 1.0;
/// Standard gravity, m/s² (the g of accelerometer units).
inline constexpr double standard_gravity = 9.80665;
/// Accelerometer records are carried as a velocity in units of 1/3600 m/s: the m/s takes the place
/// of the degree and that unit the place of the arcsecond, so every gyro formula above holds as
/// written, deviations come out in m/s/h and N, B, K, R in m/s/√h, m/s/h, m/s/h/√h, m/s/h².
inline constexpr double velocity_units_per_mps = 3600.0;
/// Earth's sidereal rotation rate, °/h (7.2921150e-5 rad/s).
inline constexpr double earth_rate_deg_per_h = 7.2921150e-5 * arcsec_per_rad;
/// Default GL-2D sampling: 400 Hz, 0.92″ per pulse; Moscow latitude.
inline constexpr double gl2d_rate_hz = 400.0;
inline constexpr double gl2d_arcsec_per_pulse = 0.92;
inline constexpr double moscow_latitude_deg = 55.75;
/// N in °/√h from a white-rate AV level σ²·τ in (°/h)²·s: N = sqrt(σ²τ)/60.
inline constexpr double sqrt_s_per_sqrt_h = 60.0;

/// Unit labels as reports and figures show them: one place, so that another sensor's units can
/// replace them.
namespace label {
inline constexpr const char* rate = "°/h";    ///< rate, Allan deviation, B
inline constexpr const char* arw = "°/√h";    ///< N
inline constexpr const char* rrw = "°/h/√h";  ///< K
inline constexpr const char* ramp = "°/h²";   ///< R
inline constexpr const char* angle = "″";     ///< angle, Q
inline constexpr const char* angle2 = "″²";   ///< angle variance
inline constexpr const char* celsius = "°C";
}  // namespace label

}  // namespace rwcalc::units
