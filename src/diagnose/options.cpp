// The rules of the diagnosis's options (validate.hpp).
#include "rwcalc/diagnose.hpp"

namespace rwcalc {

Violation DiagnoseOptions::validate() const {
  return first_of({
      analysis.validate(),
      check_in("--runs", static_cast<double>(runs), 10.0, 100000.0),
      check_in("DiagnoseOptions::band_level", band_level, 0.0, 1.0, "", Ends::Open),
      check_in("--false-alarm", alpha, 1e-6, 0.2),
  });
}

}  // namespace rwcalc
