#pragma once
// How many records a population test (label slow) runs, and how far its checks widen when it runs
// fewer than its acceptance population.
//
// Each population test has two sizes: `ci`, the default, sized so that the whole suite stays within
// CI's time budget, and `acceptance`, the population behind the figures docs/calibration.md quotes,
// run by `RWCALC_ACCEPTANCE=1 ctest --preset release -L slow`. A test's own variable (e.g.
// RWCALC_TERM_RECORDS=500) overrides both. At the acceptance size a band is checked as stated; at a
// smaller one a share may leave it by 2.5 binomial standard errors of that size, so the default run
// still fails on a gross loss of coverage or calibration while the acceptance run holds the figure.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace rwcalc::test {

inline bool acceptance_populations() {
  const char* e = std::getenv("RWCALC_ACCEPTANCE");
  return e && *e && std::strcmp(e, "0") != 0;
}

/// The record count: `env`'s value when set (at least `floor`), else `acceptance` under
/// RWCALC_ACCEPTANCE, else `ci`.
inline int population(const char* env, int ci, int acceptance, int floor = 8) {
  if (const char* e = env ? std::getenv(env) : nullptr; e && *e) return std::max(floor, std::atoi(e));
  return acceptance_populations() ? acceptance : ci;
}

/// How far a share whose expected value is `p` may leave its band at `count` records: none at the
/// acceptance size or above, else 2.5 binomial standard errors.
inline double share_allowance(double p, int count, int acceptance) {
  if (count >= acceptance || count <= 0) return 0.0;
  return 2.5 * std::sqrt(p * (1.0 - p) / count);
}

/// The same for a mean whose per-record standard deviation is `sd`.
inline double mean_allowance(double sd, int count, int acceptance) {
  if (count >= acceptance || count <= 0) return 0.0;
  return 2.5 * sd / std::sqrt(static_cast<double>(count));
}

}  // namespace rwcalc::test
