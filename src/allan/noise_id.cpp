// Noise identification as Stable32 does it: the lag-1 autocorrelation of the decimated phase or
// frequency, the B1 ratio where too few points remain, and R(n) for the modified variance.
#include "noise_id.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include "rwcalc/confidence.hpp"
#include "rwcalc/exact_sums.hpp"
#include "rwcalc/sample_variance.hpp"

namespace rwcalc {

namespace {

// Stable32 uses the lag-1 autocorrelation when at least this many points remain at τ.
constexpr std::size_t kMinAcfPoints = 30;
constexpr int kMaxDifferences = 2;  // d_max for Allan-type (two-sample) variances

/// The decimated points whose lag-1 sums decide the noise type: all of them up to kAcfMaxPoints,
/// beyond that kAcfRuns runs of consecutive points spread evenly from the record's start to its
/// end, pairs taken within a run. The decision is a class, not an estimate: r1's standard error is
/// about 1/√points, 0.004 at this size against boundaries 1/3 and 3/5 apart, so more points would
/// change a type only where the record sits on a boundary, while the sums over every point were the
/// costliest part of an octave sweep (docs/performance.md). Runs cover the whole record, so a
/// warm-up or a drift weighs as in the record.
constexpr std::size_t kAcfMaxPoints = std::size_t{1} << 16;
constexpr std::size_t kAcfRuns = 16;

struct AcfRuns {
  std::size_t count = 0;  // decimated points of the series
  std::size_t runs = 1;
  std::size_t width = 0;  // points per run
  explicit AcfRuns(std::size_t points)
      : count(points),
        runs(points > kAcfMaxPoints ? kAcfRuns : 1),
        width(points > kAcfMaxPoints ? kAcfMaxPoints / kAcfRuns : points) {}
  std::size_t start(std::size_t r) const { return spread_run_start(r, runs, count, width); }
};

/// Decimated phase p_k = x_{k·m} − x_0, k = 0 … ⌊(N−1)/m⌋, in arbitrary units (the ACF and the
/// B1 ratio do not depend on scale); offset-free and exact for counts.
std::vector<double> decimated_phase(const PhaseSeries& x, std::int64_t m) {
  const auto um = static_cast<std::size_t>(m);
  const std::size_t count = (x.points() - 1) / um + 1;
  std::vector<double> z(count);
  if (x.exact()) {
    const auto c0 = static_cast<std::uint64_t>(x.count(0));
    for (std::size_t k = 0; k < count; ++k)
      z[k] = static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(x.count(k * um)) - c0));
  } else {
    const double* v = x.values.data();
    for (std::size_t k = 0; k < count; ++k) z[k] = v[k * um] - v[0];
  }
  return z;
}

/// Averaged frequencies ȳ_k ∝ p_{k+1} − p_k (k < ⌊(N−1)/m⌋), same arbitrary units.
std::vector<double> averaged_frequency(const PhaseSeries& x, std::int64_t m) {
  std::vector<double> y = decimated_phase(x, m);
  for (std::size_t i = 0; i + 1 < y.size(); ++i) y[i] = y[i + 1] - y[i];
  y.pop_back();
  return y;
}

/// Value i of the level-th difference of p (level 0: p itself); p(i) gives the decimated phase.
template <class P>
inline double difference(const P& p, int level, std::size_t i) {
  switch (level) {
    case 0: return p(i);
    case 1: return p(i + 1) - p(i);
    case 2: return (p(i + 2) - p(i + 1)) - (p(i + 1) - p(i));
    default: return ((p(i + 3) - p(i + 2)) - (p(i + 2) - p(i + 1))) - ((p(i + 2) - p(i + 1)) - (p(i + 1) - p(i)));
  }
}

/// Lag-1 autocorrelation r1 = Σ(z_i − z̄)(z_{i+1} − z̄) / Σ(z_i − z̄)² (Riley & Greenhall eq. 2) of
/// the Level-th difference z of the decimated phase points p(0) … p(count − 1), over the runs of
/// AcfRuns (pairs within a run), from floating sums, without forming z or p: the mean of a
/// difference follows from its end points, and the sums run in four lanes (whose order fixes the
/// rounding).
template <int Level, class P>
double lag1_floating(const P& p, const AcfRuns& runs) {
  constexpr auto kLevel = static_cast<std::size_t>(Level);
  if (runs.width <= kLevel + 1) return 0.0;
  const std::size_t len = runs.width - kLevel;  // points of z per run
  const double total = static_cast<double>(len * runs.runs);
  double mean = 0;
  if constexpr (Level == 0) {
    double lane[4] = {};
    for (std::size_t r = 0; r < runs.runs; ++r) {
      const std::size_t s = runs.start(r);
      std::size_t i = 0;
      for (; i + 4 <= len; i += 4)
        for (int j = 0; j < 4; ++j) lane[j] += p(s + i + static_cast<std::size_t>(j));
      for (; i < len; ++i) lane[0] += p(s + i);
    }
    mean = (lane[0] + lane[1] + lane[2] + lane[3]) / total;
  } else {
    for (std::size_t r = 0; r < runs.runs; ++r)
      mean += difference(p, Level - 1, runs.start(r) + len) - difference(p, Level - 1, runs.start(r));
    mean /= total;
  }
  double num[4] = {}, den[4] = {};
  for (std::size_t r = 0; r < runs.runs; ++r) {
    const std::size_t s = runs.start(r);
    std::size_t i = 0;
    // Pairs (z_i, z_{i+1}) for i < len − 1; den over all i < len.
    for (; i + 4 < len; i += 4) {
      for (int j = 0; j < 4; ++j) {
        const auto k = s + i + static_cast<std::size_t>(j);
        const double a = difference(p, Level, k) - mean;
        const double b = difference(p, Level, k + 1) - mean;
        den[j] += a * a;
        num[j] += a * b;
      }
    }
    for (; i < len; ++i) {
      const double a = difference(p, Level, s + i) - mean;
      den[0] += a * a;
      if (i + 1 < len) num[0] += a * (difference(p, Level, s + i + 1) - mean);
    }
  }
  const double n_sum = num[0] + num[1] + num[2] + num[3];
  const double d_sum = den[0] + den[1] + den[2] + den[3];
  return d_sum > 0 ? n_sum / d_sum : 0.0;
}

template <class P>
double lag1_floating(const P& p, const AcfRuns& runs, int level) {
  switch (level) {
    case 0: return lag1_floating<0>(p, runs);
    case 1: return lag1_floating<1>(p, runs);
    case 2: return lag1_floating<2>(p, runs);
    default: return lag1_floating<3>(p, runs);
  }
}

// ---- Exact integer lag-1 sums of counts ------------------------------------------------------
//
// The level-L differences z of counts are integers, so Σz, Σz² and Σz_k·z_{k+1} are taken exactly
// and r1 is formed once from them: only its final conversion rounds, whatever the order of the sums.

/// Exact sums over z_0 … z_{len−1} of one difference level.
struct ExactLag1 {
  i128 s1 = 0;   // Σ z_k
  i128 s2 = 0;   // Σ z_k²
  i128 lag = 0;  // Σ z_k·z_{k+1}, k < len − 1
};

/// The sums stay inside 128 bits while every |z| < 2^34 and there are fewer than 2^28 points.
constexpr std::uint64_t kZLimit = std::uint64_t{1} << 34;
constexpr std::size_t kExactMaxPoints = std::size_t{1} << 28;

/// r1 = Σ(z_k − z̄)(z_{k+1} − z̄) / Σ(z_k − z̄)² from the exact sums over R runs of n points in
/// all, pairs within a run, z̄ = S1/n and E the sum of every run's first and last z:
/// n·num = U − R·S1²/n, U = n·Slag − S1² + S1·E;  n·den = n·S2 − S1²
/// (integers but for the fraction of R·S1²/n, which is added last).
double r1_from_exact(const ExactLag1& s, std::size_t len, i128 ends, std::size_t runs) {
  const auto n = static_cast<i128>(len);
  const i128 s1sq = s.s1 * s.s1;
  const i128 den = n * s.s2 - s1sq;
  if (den <= 0) return 0.0;
  const i128 u = n * s.lag - s1sq + s.s1 * ends;
  const i128 rs1sq = static_cast<i128>(runs) * s1sq;
  const i128 q = rs1sq / n;
  const i128 rem = rs1sq % n;
  const long double num =
      static_cast<long double>(u - q) - static_cast<long double>(rem) / static_cast<long double>(len);
  return static_cast<double>(num / static_cast<long double>(den));
}

/// Difference levels whose sums one gather of the decimated phase feeds at most.
constexpr int kLevelsAtOnce = 2;

/// The exact sums of one level over a block: z (n values, and z[n] the next one where `pairs` = n;
/// `pairs` = n − 1 at the record's end). False when some |z| ≥ kZLimit (the 128-bit sums could then
/// overflow).
bool add_block(const std::int64_t* z, std::size_t n, std::size_t pairs, ExactSums& s) {
  const auto v = [z](std::size_t i) { return static_cast<std::uint64_t>(z[i]); };
  if (add_exact_sums<SumKinds::WithLag>(n, pairs, v, s)) return true;
  std::uint64_t range = 0;
  for (std::size_t i = 0; i < n; ++i) range |= static_cast<std::uint64_t>(z[i]) + kZLimit;
  return range < 2 * kZLimit;
}

/// Exact sums of one difference level over the runs read so far.
struct ExactLevel {
  ExactSums s;
  i128 ends = 0;      // Σ over runs of the first and the last z
  std::size_t n = 0;  // z values
  bool exact = true;
};

/// Adds to lev the exact sums of the difference levels lv0 … lv0 + levels − 1 of one run,
/// p(0) … p(count − 1), the run gathered once for all of them. The differences of a block are
/// taken modulo 2^64: exact while |z| < 2^63.
template <class P>
void add_run(const P& p, std::size_t count, std::size_t lv0, std::size_t levels, ExactLevel* lev) {
  std::int64_t g[kExactBlock + 1 + 3 + kLevelsAtOnce], z[kExactBlock + 1 + 3 + kLevelsAtOnce];
  const std::size_t longest = count > lv0 ? count - lv0 : 0;
  for (std::size_t k0 = 0; k0 < longest; k0 += kExactBlock) {
    const std::size_t have = std::min(kExactBlock + 1 + lv0 + levels - 1, count - k0);
    for (std::size_t i = 0; i < have; ++i) g[i] = static_cast<std::int64_t>(p(k0 + i));
    for (std::size_t l = 0; l < levels; ++l) {
      const std::size_t lv = lv0 + l, len = count > lv ? count - lv : 0;
      if (k0 >= len || !lev[l].exact) continue;
      const std::size_t n = std::min(kExactBlock, len - k0), pairs = k0 + n < len ? n : n - 1;
      const std::size_t width = std::min(n + 1, len - k0);  // z values used: with the successor if any
      for (std::size_t i = 0; i < width + lv; ++i) z[i] = g[i];
      for (std::size_t d = 0; d < lv; ++d)
        for (std::size_t i = 0; i < width + lv - d - 1; ++i)
          z[i] = static_cast<std::int64_t>(static_cast<std::uint64_t>(z[i + 1]) - static_cast<std::uint64_t>(z[i]));
      if (width == n) z[n] = 0;  // the run's last block: no successor
      lev[l].exact = add_block(z, n, pairs, lev[l].s);
      if (k0 == 0) lev[l].ends += z[0];
      if (k0 + n == len) lev[l].ends += z[n - 1];
      lev[l].n += n;
    }
  }
}

/// r1 of the difference levels first … first + r1.size() − 1 (at most kLevelsAtOnce) of p(0) …
/// p(count − 1) over the runs of AcfRuns from exact sums; nothing for a level whose sums could
/// leave 128 bits (they run modulo 2^128 and are used only when every |z| < kZLimit).
template <class P>
void lag1_exact(const P& p, const AcfRuns& runs, int first, std::span<std::optional<double>> r1) {
  const auto levels = static_cast<std::size_t>(std::min<std::ptrdiff_t>(std::ssize(r1), kLevelsAtOnce));
  const auto lv0 = static_cast<std::size_t>(first);
  ExactLevel lev[kLevelsAtOnce];
  for (std::size_t r = 0; r < runs.runs; ++r) {
    const std::size_t s = runs.start(r);
    add_run([&p, s](std::size_t k) { return p(s + k); }, runs.width, lv0, levels, lev);
  }
  for (std::size_t l = 0; l < levels; ++l) {
    const std::size_t lv = lv0 + l;
    if (runs.width <= lv + 1) {
      r1[l] = 0.0;
    } else if (runs.width * runs.runs >= kExactMaxPoints || !lev[l].exact) {
      r1[l] = std::nullopt;
    } else {
      const ExactLag1 e{static_cast<i128>(lev[l].s.sum), static_cast<i128>(lev[l].s.squares),
                        static_cast<i128>(lev[l].s.lag)};
      r1[l] = r1_from_exact(e, lev[l].n, lev[l].ends, runs.runs);
    }
  }
}

/// r1 of the levels first … first + r1.size() − 1 (at most kLevelsAtOnce) of the phase decimated by m.
void lag1_autocorrelations(const PhaseSeries& x, std::int64_t m, std::size_t count, int first, std::span<double> r1) {
  const auto um = static_cast<std::size_t>(m);
  const AcfRuns runs(count);
  if (x.exact()) {
    const auto c0 = static_cast<std::uint64_t>(x.count(0));
    auto p = [&x, c0, um](std::size_t k) { return static_cast<std::uint64_t>(x.count(k * um)) - c0; };
    std::optional<double> exact[kLevelsAtOnce];
    const std::size_t levels = std::min<std::size_t>(r1.size(), kLevelsAtOnce);
    lag1_exact(p, runs, first, std::span(exact, levels));
    for (std::size_t l = 0; l < levels; ++l)
      r1[l] = exact[l]
                  ? *exact[l]
                  : lag1_floating([&p](std::size_t k) { return static_cast<double>(static_cast<std::int64_t>(p(k))); },
                                  runs, first + static_cast<int>(l));
    return;
  }
  const double* v = x.values.data();
  for (std::size_t l = 0; l < r1.size(); ++l)
    r1[l] = lag1_floating([v, um](std::size_t k) { return v[k * um] - v[0]; }, runs, first + static_cast<int>(l));
}

/// Lag-1 ACF method on the phase decimated by m, starting at difference level `base` (0: phase
/// data, 1: frequency data): difference until δ = r1/(1 + r1) < 0.25 or d = d_max;
/// p = −round(2δ) − 2d. Returns p, the exponent of the analysed series' own spectrum.
int acf_exponent(const PhaseSeries& x, std::int64_t m, std::size_t count, int base) {
  double r1s[kMaxDifferences + 1] = {};
  for (int d = 0, known = 0;; ++d) {
    if (d == known) {  // this level and the next from one pass: the phase itself seldom ends it
      const int levels = std::min(kLevelsAtOnce, kMaxDifferences + 1 - d);
      lag1_autocorrelations(x, m, count, base + d, std::span(r1s + d, static_cast<std::size_t>(levels)));
      known += levels;
    }
    const double r1 = r1s[d];
    const double delta = r1 / (1.0 + r1);
    if (delta < 0.25 || d >= kMaxDifferences) return -static_cast<int>(std::lround(2.0 * delta)) - 2 * d;
  }
}

/// Expected B1 = (standard variance)/(Allan variance) for N averages and phase exponent μ
/// (Howe, Beard, Greenhall & Riley, PTTI 2000, Table 3). μ = 2 … −2 ↔ α = −3 … +1/+2.
double b1_expected(double n, int mu) {
  switch (mu) {
    case 2: return n * (n + 1.0) / 6.0;
    case 1: return n / 2.0;
    case 0: return n * std::log(n) / (2.0 * (n - 1.0) * std::numbers::ln2);
    case -1: return 1.0;
    case -2: return (n * n - 1.0) / (1.5 * n * (n - 1.0));
    default: return n * (1.0 - std::pow(n, mu)) / (2.0 * (n - 1.0) * (1.0 - std::pow(2.0, mu)));
  }
}

/// μ from a measured B1: the largest μ whose boundary with μ − 1 the ratio exceeds. Boundaries are
/// geometric means of neighbouring expectations, except the arithmetic mean between μ = 2 and 1.
int b1_mu(double measured, double n) {
  for (int mu = 2; mu > -2; --mu) {
    const double hi = b1_expected(n, mu), lo = b1_expected(n, mu - 1);
    const double boundary = mu == 2 ? 0.5 * (hi + lo) : std::sqrt(hi * lo);
    if (measured > boundary) return mu;
  }
  return -2;
}

double nonoverlapping_avar(const std::vector<double>& y) {
  double s = 0;
  for (std::size_t i = 0; i + 1 < y.size(); ++i) s += (y[i + 1] - y[i]) * (y[i + 1] - y[i]);
  return 0.5 * s / static_cast<double>(y.size() - 1);
}

// The expectations are taken for N = the estimator's number of terms at this τ (not the number of
// averages): that is what reproduces every α of Stable32's tables in the B1 region.
int noise_id_b1(const PhaseSeries& x, std::int64_t m, Estimator est) {
  const std::vector<double> y = averaged_frequency(x, m);
  if (y.size() < 2) return 0;
  const double avar = nonoverlapping_avar(y);
  if (!(avar > 0)) return 0;
  const double b1 = sample_variance(y) / avar;
  const int mu = b1_mu(b1, static_cast<double>(term_count(est, m, x.points())));
  if (mu == -2) {
    // μ = −2 covers white and flicker PM; Stable32 reports flicker PM (α = 1) unless R(n) can
    // tell them apart, which it uses for the modified variance only.
    if (est != Estimator::Modified) return 1;
    // R(n) = MVAR/AVAR tells white (1/m) from flicker PM (NIST TN 1337 Table 2, f_h = 1/(2τ0)).
    // y is in phase units per cluster: bring AVAR to deviation units before the ratio.
    const double unit = (x.exact() ? x.arcsec_per_count : 1.0) / (static_cast<double>(m) * x.tau0_s);
    const double mvar = allan_variance(x, m, Estimator::Modified);
    const double rn = mvar / (avar * unit * unit);
    const double md = static_cast<double>(m);
    const double r_flicker = 3.37 / (1.04 + 3.0 * std::log(std::numbers::pi * md));
    const double r_white = 1.0 / md;
    return rn > std::sqrt(r_flicker * r_white) ? 1 : 2;
  }
  return std::clamp(-mu - 1, -2, 2);  // μ = 1, 0, −1 ↔ α = −2, −1, 0 (μ = 2: α = −3, clamped)
}

}  // namespace

namespace detail {

double lag1_autocorrelation(const PhaseSeries& x, std::int64_t m, std::size_t count, int level) {
  double r1 = 0;
  lag1_autocorrelations(x, m, count, level, std::span(&r1, 1));
  return r1;
}

}  // namespace detail

int identify_noise(const PhaseSeries& x, std::int64_t m, Estimator est, NoiseIdDomain domain) {
  if (m < 1 || x.points() < 3 || static_cast<std::size_t>(m) > x.points() - 1) return 0;
  // Points at τ: phase samples for phase data, averaged frequencies (one fewer) for frequency data.
  const std::size_t phase_points = (x.points() - 1) / static_cast<std::size_t>(m) + 1;
  if (domain == NoiseIdDomain::Phase && phase_points >= kMinAcfPoints)
    return std::clamp(acf_exponent(x, m, phase_points, 0) + 2, -2, 2);
  if (domain == NoiseIdDomain::Frequency && phase_points - 1 >= kMinAcfPoints)
    return std::clamp(acf_exponent(x, m, phase_points, 1), -2, 2);
  return noise_id_b1(x, m, est);
}

}  // namespace rwcalc
