// Sensor kinds and the units their results are shown in (sensor.hpp).
#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/sensor.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

namespace {

struct RateChoice {
  SensorKind kind;
  std::string_view name;   ///< as --output-unit takes it
  std::string_view label;  ///< for people
  double factor;           ///< from the fit's deviation unit (°/h or m/s/h)
};

constexpr double kGyroSi = std::numbers::pi / 180.0 / units::seconds_per_hour;  // °/h → rad/s
constexpr double kAccelSi = 1.0 / units::seconds_per_hour;                      // m/s/h → m/s²
constexpr double kMicroG = kAccelSi / units::standard_gravity * 1e6;            // m/s/h → µg

constexpr RateChoice kRates[] = {{SensorKind::Gyro, "deg/s", "°/s", 1.0 / units::seconds_per_hour},
                                 {SensorKind::Gyro, "rad/s", "rad/s", kGyroSi},
                                 {SensorKind::Accelerometer, "m/s^2", "m/s²", kAccelSi},
                                 {SensorKind::Accelerometer, "g", "g", kMicroG * 1e-6},
                                 {SensorKind::Accelerometer, "mg", "mg", kMicroG * 1e-3},
                                 {SensorKind::Accelerometer, "ug", "µg", kMicroG}};

/// Every label the unit sets below compose (rate_based, usual_units, si_units), for the catalogue:
/// labels are kept in English and translated where shown (localized_label); a test checks that
/// each label of every unit set has its entry.
[[maybe_unused]] constexpr const char* kComposedLabels[] = {
    N_("°/s"),      N_("°/s/√Hz"), N_("°/s/√s"),     N_("°/s/s"),  N_("°"),        N_("rad/s"),   N_("rad/s/√Hz"),
    N_("rad/s/√s"), N_("rad/s/s"), N_("rad"),        N_("m/s²"),   N_("m/s²/√Hz"), N_("m/s²/√s"), N_("m/s²/s"),
    N_("m/s"),      N_("g"),       N_("g/√Hz"),      N_("g/√s"),   N_("g/s"),      N_("mg"),      N_("mg/√Hz"),
    N_("mg/√s"),    N_("mg/s"),    N_("µg"),         N_("µg/√Hz"), N_("µg/√s"),    N_("µg/s"),    N_("m/s/√h"),
    N_("m/s/h/√h"), N_("m/s/h²"),  N_("rad/s²/√Hz"), N_("rad/s²"), N_("m/s³/√Hz"), N_("m/s³")};

// B and σ in U, N in U/√Hz, K in U/√s, R in U/s: the factors follow from 1 h = 3600 s.
UnitSet rate_based(SensorKind kind, std::string_view ascii, std::string_view label, double f) {
  UnitSet u;
  u.kind = kind;
  u.deviation = {std::string(label), std::string(ascii), f};
  auto at = [&u](Term t) -> ShownUnit& { return u.term[static_cast<std::size_t>(t)]; };
  at(Term::N) = {fmt::format("{}/√Hz", label), fmt::format("{}/sqrt(Hz)", ascii),
                 f * std::sqrt(units::seconds_per_hour)};
  at(Term::B) = u.deviation;
  at(Term::K) = {fmt::format("{}/√s", label), fmt::format("{}/sqrt(s)", ascii), f / std::sqrt(units::seconds_per_hour)};
  at(Term::R) = {fmt::format("{}/s", label), fmt::format("{}/s", ascii), f / units::seconds_per_hour};
  // Q is an angle (gyro) or a velocity (accelerometer): ″ = (°/h)·s, 1/3600 m/s = (m/s/h)·s.
  if (kind == SensorKind::Accelerometer)
    at(Term::Q) = {"m/s", "m/s", 1.0 / units::velocity_units_per_mps};
  else if (ascii == "rad/s")
    at(Term::Q) = {"rad", "rad", 1.0 / units::arcsec_per_rad};
  else
    at(Term::Q) = {"°", "deg", 1.0 / units::arcsec_per_deg};
  return u;
}

UnitSet usual_units(SensorKind kind) {
  if (kind == SensorKind::Gyro) {
    UnitSet u;
    u.deviation = {units::label::rate, "deg/h", 1};
    u.term = {ShownUnit{units::label::angle, "arcsec", 1}, ShownUnit{units::label::arw, "deg/sqrt(h)", 1},
              ShownUnit{units::label::rate, "deg/h", 1}, ShownUnit{units::label::rrw, "deg/h/sqrt(h)", 1},
              ShownUnit{units::label::ramp, "deg/h^2", 1}};
    return u;
  }
  UnitSet u;
  u.kind = kind;
  u.deviation = {"µg", "ug", kMicroG};
  u.term = {ShownUnit{"m/s", "m/s", 1.0 / units::velocity_units_per_mps}, ShownUnit{"m/s/√h", "m/s/sqrt(h)", 1},
            u.deviation, ShownUnit{"m/s/h/√h", "m/s/h/sqrt(h)", 1}, ShownUnit{"m/s/h²", "m/s/h^2", 1}};
  return u;
}

}  // namespace

std::string_view to_string(SensorKind k) { return k == SensorKind::Gyro ? "gyro" : "accelerometer"; }

std::optional<SensorKind> sensor_kind(PhaseKind k) {
  switch (k) {
    case PhaseKind::Gyro: return SensorKind::Gyro;
    case PhaseKind::Accelerometer: return SensorKind::Accelerometer;
    case PhaseKind::Clock: break;
  }
  return std::nullopt;
}

std::string_view term_meaning(SensorKind k, Term t) {
  static constexpr std::array<std::string_view, kTermCount> kGyro{N_("angle quantisation"), N_("angle random walk"),
                                                                  N_("bias instability"), N_("rate random walk"),
                                                                  N_("rate ramp")};
  static constexpr std::array<std::string_view, kTermCount> kAccel{N_("velocity quantisation"),
                                                                   N_("velocity random walk"), N_("bias instability"),
                                                                   N_("acceleration random walk"),
                                                                   N_("acceleration ramp")};
  return (k == SensorKind::Gyro ? kGyro : kAccel)[static_cast<std::size_t>(t)];
}

std::string localized_meaning(SensorKind k, Term t) { return tr(std::string(term_meaning(k, t))); }

std::string localized_label(const ShownUnit& u) { return tr(u.label); }

UnitSet output_units(SensorKind kind, std::string_view output_unit) {
  if (output_unit.empty()) return usual_units(kind);
  if (kind == SensorKind::Gyro && output_unit == "deg/h") return usual_units(kind);
  if (output_unit == "µg") output_unit = "ug";
  if (output_unit == "m/s2") output_unit = "m/s^2";
  for (const RateChoice& r : kRates)
    if (r.name == output_unit) {
      if (r.kind != kind)
        throw UsageError(trf("output unit '{}' is an {} unit; the {} channels take {}", output_unit, to_string(r.kind),
                             to_string(kind),
                             kind == SensorKind::Gyro ? "deg/h, deg/s or rad/s" : "m/s^2, g, mg or ug"));
      return rate_based(kind, r.name, r.label, r.factor);
    }
  throw UsageError(
      trf("unknown output unit '{}': expected deg/h, deg/s, rad/s (gyro) or m/s^2, g, mg, ug "
          "(accelerometer)",
          output_unit));
}

UnitSet si_units(SensorKind kind) {
  const bool gyro = kind == SensorKind::Gyro;
  UnitSet u = gyro ? rate_based(kind, "rad/s", "rad/s", kGyroSi) : rate_based(kind, "m/s^2", "m/s²", kAccelSi);
  // The same factors under the names Kalibr and OpenVINS use.
  auto& k = u.term[static_cast<std::size_t>(Term::K)];
  k.label = gyro ? "rad/s²/√Hz" : "m/s³/√Hz";
  k.ascii = gyro ? "rad/s^2/sqrt(Hz)" : "m/s^3/sqrt(Hz)";
  auto& r = u.term[static_cast<std::size_t>(Term::R)];
  r.label = gyro ? "rad/s²" : "m/s³";
  r.ascii = gyro ? "rad/s^2" : "m/s^3";
  return u;
}

}  // namespace rwcalc
