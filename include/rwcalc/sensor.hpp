#pragma once
#ifndef RWCALC_USES_MODEL
#error "rwcalc/sensor.hpp belongs to the model layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file sensor.hpp
/// The kind of sensor a channel holds (gyro or accelerometer) and the units its results are shown
/// in. The numerics have one path: the phase series is an angle in ″ or a velocity in 1/3600 m/s
/// (units.hpp), so the fit's coefficients come out in the gyro's IEEE 952 units or in their
/// accelerometer twins (° → m/s); only the names and the units shown change with the kind.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "rwcalc/fit.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

enum class SensorKind { Gyro, Accelerometer };

/// "gyro", "accelerometer".
std::string_view to_string(SensorKind k);
/// The sensor of a phase series; nullopt for clock data.
std::optional<SensorKind> sensor_kind(PhaseKind k);
/// What a term is for the kind: "angle random walk" (gyro N), "velocity random walk" (accelerometer N), …
/// English, as JSON carries it; localized_meaning gives it in the current language (i18n.hpp).
std::string_view term_meaning(SensorKind k, Term t);
[[nodiscard]] std::string localized_meaning(SensorKind k, Term t);

/// One shown unit: its label for people ("°/√h", in English: localized_label gives it in the current
/// language, "°/√ч"), its ASCII name for JSON ("deg/sqrt(h)") and the factor that takes a
/// fit-scale value (fit.hpp) into it.
struct ShownUnit {
  std::string label;
  std::string ascii;
  double factor = 1;
};

[[nodiscard]] std::string localized_label(const ShownUnit& u);

/// The units a channel's results are shown in: the Allan deviation and the mean (a rate or an
/// acceleration) and each of the five terms.
struct UnitSet {
  SensorKind kind = SensorKind::Gyro;
  ShownUnit deviation;
  std::array<ShownUnit, kTermCount> term;
  [[nodiscard]] const ShownUnit& operator[](Term t) const { return term[static_cast<std::size_t>(t)]; }
};

/// The units of `--output-unit` (gyro: deg/h, deg/s, rad/s; accelerometer: m/s^2, g, mg, ug; "" the
/// kind's usual units: °/h with N in °/√h, K in °/h/√h, R in °/h², Q in ″ for a gyro; µg with N in
/// m/s/√h, K in m/s/h/√h, R in m/s/h², Q in m/s for an accelerometer). For a rate unit U other
/// than °/h: B and σ in U, N in U/√Hz, K in U/√s, R in U/s, Q in U·s (the angle or velocity).
/// Throws UsageError for a unit of the other kind or an unknown one.
UnitSet output_units(SensorKind kind, std::string_view output_unit = "");
/// SI: rad/s, rad/s/√Hz, rad/s²/√Hz … for a gyro; m/s², m/s²/√Hz, m/s³/√Hz … for an accelerometer
/// (Kalibr's and OpenVINS's units for N and K).
UnitSet si_units(SensorKind kind);

}  // namespace rwcalc
