// The rules of the reader's options (validate.hpp).
#include "rwcalc/limits.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

Violation ReadOptions::validate() const {
  return first_of({
      rate_hz ? check_in("--rate", *rate_hz, kMinRateHz, kMaxRateHz, "Hz") : std::nullopt,
      scale_arcsec ? check_in("--scale", *scale_arcsec, kMinScaleArcsec, kMaxScaleArcsec, "arcsec") : std::nullopt,
      check_in("--counter-bits", counter_bits, 1.0, 64.0),
      check_in("--time-tolerance", time_tolerance, 0.0, 0.5),
  });
}

}  // namespace rwcalc
