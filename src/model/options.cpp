// The rules of the fit's, the cross-checks' and the verdict's options (validate.hpp).
#include <algorithm>
#include <limits>

#include "rwcalc/fit.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/methods.hpp"
#include "rwcalc/verdict.hpp"

namespace rwcalc {

namespace {

constexpr double kNoLimit = std::numeric_limits<double>::infinity();

}  // namespace

Violation FitOptions::validate() const {
  if (Violation v = check_in("--fit-range TMIN", tau_min_s, 0.0, kNoLimit, "s", Ends::OpenHigh)) return v;
  // tau_max_s may be infinite (no upper end), never NaN.
  if (!(tau_max_s > tau_min_s))
    return trf("--fit-range: TMAX ({:g} s) must be above TMIN ({:g} s)", tau_max_s, tau_min_s);
  if (std::none_of(enabled.begin(), enabled.end(), [](bool e) { return e; }))
    return tr("--terms: give at least one of Q, N, B, K, R");
  return first_of({
      check_in("--min-edf", min_edf, 0.0, kNoLimit, "", Ends::OpenHigh),
      check_in("FitOptions::edf_cap", edf_cap, 0.0, kNoLimit, "", Ends::OpenHigh),
      check_in("FitOptions::confidence", confidence, 0.0, 1.0, "", Ends::Open),
      check_in("FitOptions::dispersion", dispersion, 0.0, kNoLimit, "", Ends::Open),
      check_in("FitOptions::edf_inflation", edf_inflation, 0.0, kNoLimit, "", Ends::OpenHigh),
      check_in("FitOptions::max_iterations", max_iterations, 1.0, 1e6),
      counter ? check_in("--scale", counter->q_arcsec, 0.0, kNoLimit, "arcsec", Ends::Open) : std::nullopt,
      counter ? check_in("CounterReadout::tau0_s", counter->tau0_s, 0.0, kNoLimit, "s", Ends::Open) : std::nullopt,
  });
}

Violation MethodOptions::validate() const {
  if (Violation v = check_in("--direct-range TMIN", direct_t_min_s, 0.0, kNoLimit, "s", Ends::Open)) return v;
  if (!(direct_t_max_s > direct_t_min_s && direct_t_max_s < kNoLimit))
    return trf("--direct-range: TMAX ({:g} s) must be finite and above TMIN ({:g} s)", direct_t_max_s, direct_t_min_s);
  return first_of({
      // Fewer than four lengths cannot carry the regression of Q², N² and B² with a degree of freedom.
      check_in("MethodOptions::direct_points", direct_points, 4.0, 1000.0),
      check_in("MethodOptions::bootstrap_replicates", bootstrap_replicates, 0.0, 1e6),  // 0: no interval
      check_in("--block", block_s, 0.0, 1e9, "s", Ends::OpenLow),
  });
}

Violation VerdictOptions::validate() const {
  if (table.classes.empty()) return tr("--limits: the class table lists no class");
  return first_of({
      check_in("--tolerance", tolerance_pct, 0.0, 1000.0, "%"),
      check_in("VerdictOptions::decisive", decisive, 0.0, 1.0, "", Ends::OpenLow),
  });
}

}  // namespace rwcalc
