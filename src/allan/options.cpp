// The rules of the estimators' options (validate.hpp).
#include <limits>

#include "rwcalc/allan.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc {

Violation AllanOptions::validate() const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (Violation v = check_in("--confidence", confidence, 0.0, 1.0, "", Ends::Open)) return v;
  if (!noise_id)
    if (Violation v = check_in("AllanOptions::alpha", alpha, -2.0, 2.0)) return v;
  if (grid.kind == TauGrid::Kind::Dense)
    if (Violation v = check_in("--tau dense:P", grid.per_decade, 1.0, 1000.0)) return v;
  if (grid.kind == TauGrid::Kind::Explicit) {
    if (grid.taus_s.empty()) return tr("--tau: the list of tau holds no value");
    for (const double t : grid.taus_s)
      if (Violation v = check_in("--tau", t, 0.0, kInf, "s", Ends::Open)) return v;
  }
  if (grid.max_m < 0) return trf("TauGrid::max_m must be 0 (no cap) or a positive cluster size, got {}", grid.max_m);
  return std::nullopt;
}

}  // namespace rwcalc
