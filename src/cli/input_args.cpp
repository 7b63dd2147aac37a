#include <fmt/format.h>

#include "cli/commands.hpp"
#include "cli/numeric_options.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc::cli {

void InputArgs::add_to(CLI::App& app) {
  app.add_option("--input", input,
                 "What the column holds: pulses (per-sample pulse increments), counter (cumulative "
                 "counter, wraps at --counter-bits), angle (cumulative angle/phase in --angle-unit), "
                 "rate (rate samples in --rate-unit)")
      ->capture_default_str()
      ->group("Input");
  app.add_option("--column", column, "Column to read: a header name or a 1-based index")->group("Input");
  app.add_option("--rate", rate_hz, "Sample rate, Hz (default: metadata, time column, or 400)")
      ->check(real_in(kMinRateHz, kMaxRateHz, "Hz"))
      ->group("Input");
  app.add_option("--scale", scale_arcsec, "Pulse weight, arcsec per pulse (default: metadata or 0.92)")
      ->check(real_in(kMinScaleArcsec, kMaxScaleArcsec, "arcsec"))
      ->group("Input");
  app.add_option("--counter-bits", counter_bits, "Width of a wrapping counter, bits (counter input)")
      ->check(whole_in(1, 64))
      ->capture_default_str()
      ->group("Input");
  app.add_option("--angle-unit", angle_unit, "Unit of angle input: arcsec, deg, rad, or s (clock phase)")
      ->capture_default_str()
      ->group("Input");
  app.add_option("--rate-unit", rate_unit,
                 "Unit of rate input: deg/h, deg/s, rad/s, or 1 (dimensionless clock frequency)")
      ->capture_default_str()
      ->group("Input");
  app.add_option("--time-tolerance", time_tolerance,
                 "Allowed deviation of a time-column step from the sample period, fraction of it")
      ->check(real_in(0.0, 0.5, ""))
      ->capture_default_str()
      ->group("Input");
}

ReadOptions InputArgs::options() const {
  ReadOptions o;
  o.mode = parse_input_mode(input);
  o.column = column;
  o.rate_hz = rate_hz;
  o.scale_arcsec = scale_arcsec;
  o.counter_bits = counter_bits;
  o.angle_unit = parse_angle_unit(angle_unit);
  o.rate_unit = parse_rate_unit(rate_unit);
  o.time_tolerance = time_tolerance;
  return o;
}

}  // namespace rwcalc::cli
