// The rules of the analysis's and the IMU's options (validate.hpp).
#include <algorithm>

#include "rwcalc/analysis.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/imu.hpp"
#include "rwcalc/limits.hpp"

namespace rwcalc {

Violation AnalysisOptions::validate() const {
  if (Violation v = first_of({allan.validate(), fit.validate(), methods.validate(), verdict.validate()})) return v;
  // The cross-checks subtract the fitted N and B, and the verdict classes both.
  if (!fit.enabled[static_cast<std::size_t>(Term::N)] || !fit.enabled[static_cast<std::size_t>(Term::B)])
    return tr("--terms must include N and B (the verdict needs both)");
  return first_of({
      check_in("--latitude", latitude_deg, -90.0, 90.0, "deg"),
      earth_rate_deg_per_h ? check_in("--earth-rate", *earth_rate_deg_per_h, -kMaxRateDegPerH, kMaxRateDegPerH, "deg/h")
                           : std::nullopt,
      temperature_c ? check_in("--temperature", *temperature_c, kMinTemperatureC, kMaxTemperatureC, "deg C")
                    : std::nullopt,
      check_in("--outlier-threshold", outlier_threshold, kMinOutlierThreshold, 1e6, "robust sigma"),
  });
}

Violation ImuOptions::validate() const {
  if (Violation v = first_of({read.validate(), analysis.validate()})) return v;
  if (!vertical_gyro.empty() &&
      std::find(gyro_columns.begin(), gyro_columns.end(), vertical_gyro) == gyro_columns.end())
    return trf("--vertical-gyro {}: not one of the --gyro columns", vertical_gyro);
  if (gyro_unit && (is_accelerometer_unit(*gyro_unit) || *gyro_unit == RateUnit::Unitless))
    return trf(
        "--gyro-unit {} is not a gyro unit: expected deg/h, deg/s, rad/s (rates) or arcsec, deg, rad (increments)",
        to_string(*gyro_unit));
  if (accel_unit && !is_accelerometer_unit(*accel_unit))
    return trf("--accel-unit {} is not an accelerometer unit: expected m/s^2, g, mg, ug (rates) or m/s (increments)",
               to_string(*accel_unit));
  return std::nullopt;
}

Violation NoiseFileOptions::validate() const {
  if (Violation v = check_in("--inflate", inflate, 1.0, 1e6)) return v;
  if (discrete && !takes_discrete(format))
    return tr(
        "--discrete: this --noise-format takes continuous-time values only (its reader converts them); "
        "--discrete is for vins-fusion");
  return std::nullopt;
}

}  // namespace rwcalc
