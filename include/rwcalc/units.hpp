#pragma once
/// @file units.hpp
/// Unit conventions and exact conversion factors used throughout rwcalc.
///
/// Gyro data are carried as an angle in arcseconds (″) sampled every τ0 seconds, so that an Allan
/// deviation comes out in ″/s, which is exactly °/h (1″ = 1/3600°, 1 s = 1/3600 h).
/// Noise coefficients are reported in the IEEE 952 units:
///   Q  ″ (rms white angle error; σ² = 3Q²/τ²)
///   N  °/√h   (σ² = N²/τ)          60·N [°/h·√s] = σ at τ = 1 s
///   B  °/h    (σ² = (2 ln2/π)·B²)
///   K  °/h/√h (σ² = K²τ/3)
///   R  °/h²   (σ² = R²τ²/2)
#include <numbers>

namespace rwcalc::units {

inline constexpr double arcsec_per_deg = 3600.0;
inline constexpr double seconds_per_hour = 3600.0;
inline constexpr double arcsec_per_rad = 180.0 * 3600.0 / std::numbers::pi;
/// °/h per ″/s (exactly one).
inline constexpr double deg_per_h_per_arcsec_per_s = 1.0;
/// Earth's sidereal rotation rate, °/h (7.2921150e-5 rad/s).
inline constexpr double earth_rate_deg_per_h = 7.2921150e-5 * arcsec_per_rad;
/// Default GL-2D sampling: 400 Hz, 0.92″ per pulse; Moscow latitude.
inline constexpr double gl2d_rate_hz = 400.0;
inline constexpr double gl2d_arcsec_per_pulse = 0.92;
inline constexpr double moscow_latitude_deg = 55.75;

/// N in °/√h from a white-rate AV level σ²·τ given in (°/h)²·s: N = sqrt(σ²τ)/60.
inline constexpr double sqrt_s_per_sqrt_h = 60.0;

}  // namespace rwcalc::units
