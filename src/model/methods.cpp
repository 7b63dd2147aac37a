// The paper's cross-checks as unbiased estimators: direct N from the overlapping angle-increment
// variances, B from the 100-s averages and from the ADEV minimum, the spread of block means.
#include "rwcalc/methods.hpp"
#include "rwcalc/normal_quantile.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numbers>

#include "rwcalc/confidence.hpp"
#include "rwcalc/exact_sums.hpp"
#include "rwcalc/narrow_counts.hpp"
#include "rwcalc/noise_model.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/random.hpp"
#include "rwcalc/sample_variance.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/structure_function.hpp"

namespace rwcalc {

namespace {

constexpr double kFlicker = 2.0 * std::numbers::ln2 / std::numbers::pi;  // AV of B at unit B²
using Vec3 = Eigen::Vector3d;

/// Structure functions of white angle, white rate and flicker rate at unit coefficient, u in s.
Vec3 structure(double u) {
  const std::array<double, 5> d = term_structure_functions(u);
  return {d[0], d[1], d[2]};
}

/// Σe and Σe² of e_k = C_{k+t} − C_k − shift, k in [k0, k1): in 16-bit lanes where the counts'
/// bounds allow (narrow_counts.hpp), else exactly in 64- or 128-bit blocks (exact_sums.hpp).
void add_increment_sums(const std::int64_t* c, const detail::NarrowCounts& narrow, std::size_t t, std::int64_t shift,
                        std::size_t k0, std::size_t k1, ExactSums& sums) {
  for (std::size_t from = k0; from < k1; from += detail::NarrowCounts::kMaxTerms) {
    const std::size_t to = std::min(k1, from + detail::NarrowCounts::kMaxTerms);
    std::int64_t n1 = 0;
    std::uint64_t n2 = 0;
    if (!narrow.increment_sums(from, to - from, t, shift, n1, n2)) break;
    sums.sum += static_cast<u128>(static_cast<i128>(n1));
    sums.squares += n2;
    k0 = to;
  }
  for (std::size_t from = k0; from < k1; from += kExactBlock) {
    const std::int64_t* b = c + from;
    const auto e = [b, t, shift](std::size_t k) {
      return static_cast<std::uint64_t>(b[k + t]) - static_cast<std::uint64_t>(b[k]) -
             static_cast<std::uint64_t>(shift);
    };
    add_exact_sums<SumKinds::ValuesAndSquares>(std::min(kExactBlock, k1 - from), 0, e, sums);
  }
}

/// Σd and Σd² of the increments d_k = x_{k+t} − x_k − shift, k0 ≤ k < k1, of a floating phase, in
/// four lanes (a single running sum is bound by the adder's latency), as x.diff forms them.
void add_floating_increment_sums(const PhaseSeries& x, std::size_t t, double shift, std::size_t k0, std::size_t k1,
                                 double (&s1)[4], double (&s2)[4]) {
  const double* v = x.values.data();
  const double offset = x.offset_phase(static_cast<double>(t));
  std::size_t k = k0;
  for (; k + 4 <= k1; k += 4)
    for (std::size_t j = 0; j < 4; ++j) {
      const double d = (v[k + j + t] - v[k + j] + offset) - shift;
      s1[j] += d;
      s2[j] += d * d;
    }
  for (; k < k1; ++k) {
    const double d = (v[k + t] - v[k] + offset) - shift;
    s1[0] += d;
    s2[0] += d * d;
  }
}

/// The sums of every length's increments over the record, in one sweep of short blocks (the longest
/// interval's window stays in cache), chunks of the record in parallel: add(sums, t, k0, k1) adds
/// the terms k0 ≤ k < k1 of length t. One Sums per chunk and length, for the caller to add in
/// chunk order (the result does not depend on the number of threads).
template <class Sums, class Add>
std::vector<std::vector<Sums>> sweep_increments(std::size_t n, const std::vector<std::size_t>& ts, const Add& add) {
  constexpr std::size_t kBlock = std::size_t{1} << 14, kChunk = kBlock * 32;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<Sums>> part(chunks, std::vector<Sums>(ts.size()));
  parallel_for(chunks, [&](std::size_t ci) {
    for (std::size_t k0 = ci * kChunk; k0 < std::min(n, (ci + 1) * kChunk); k0 += kBlock)
      for (std::size_t i = 0; i < ts.size(); ++i) {
        const std::size_t k1 = std::min({k0 + kBlock, (ci + 1) * kChunk, n - ts[i] + 1});
        if (k1 > k0) add(part[ci][i], i, k0, k1);
      }
  });
  return part;
}

/// Sample variances of the overlapping increments of a floating phase (overlapping_variances), the
/// mean rate taken out first.
std::vector<double> floating_overlapping_variances(const PhaseSeries& x, const std::vector<std::size_t>& ts) {
  const std::size_t n = x.points() - 1;
  struct Lanes {
    double s1[4] = {}, s2[4] = {};
  };
  std::vector<double> shift(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i)
    shift[i] = x.diff(n, 0) * static_cast<double>(ts[i]) / static_cast<double>(n);
  const auto part = sweep_increments<Lanes>(n, ts, [&](Lanes& l, std::size_t i, std::size_t k0, std::size_t k1) {
    add_floating_increment_sums(x, ts[i], shift[i], k0, k1, l.s1, l.s2);
  });
  std::vector<double> out(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i) {
    double s1 = 0, s2 = 0;
    for (const auto& p : part)
      for (std::size_t j = 0; j < 4; ++j) s1 += p[i].s1[j], s2 += p[i].s2[j];
    const auto m = static_cast<double>(n - ts[i] + 1);
    out[i] = (s2 - s1 * s1 / m) / (m - 1.0);
  }
  return out;
}

/// Sample variances of the M = n − t + 1 overlapping increments x_{k+t} − x_k for every t in ts,
/// ″², by sweep_increments. Pulse counts: exact integer sums of the increments less the mean
/// rate's whole counts (the variance does not see the shift, and the small values fit narrow
/// sums). Floating phases: floating_overlapping_variances.
std::vector<double> overlapping_variances(const PhaseSeries& x, const std::vector<std::size_t>& ts) {
  if (!x.exact()) return floating_overlapping_variances(x, ts);
  const std::size_t n = x.points() - 1;
  const detail::NarrowCounts narrow(x.counts.data(), x.points());
  const auto total = static_cast<double>(
      static_cast<std::int64_t>(static_cast<std::uint64_t>(x.count(n)) - static_cast<std::uint64_t>(x.count(0))));
  std::vector<std::int64_t> shift(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const double s = std::round(total * static_cast<double>(ts[i]) / static_cast<double>(n));
    shift[i] = std::abs(s) < 0x1p62 ? static_cast<std::int64_t>(s) : 0;
  }
  const auto part =
      sweep_increments<ExactSums>(n, ts, [&](ExactSums& sums, std::size_t i, std::size_t k0, std::size_t k1) {
        add_increment_sums(x.counts.data(), narrow, ts[i], shift[i], k0, k1, sums);
      });
  const double q2 = x.arcsec_per_count * x.arcsec_per_count;
  std::vector<double> out(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i) {
    i128 s1 = 0, s2 = 0;
    for (const auto& p : part) {
      s1 += static_cast<i128>(p[i].sum);
      s2 += static_cast<i128>(p[i].squares);
    }
    const std::size_t m = n - ts[i] + 1;
    const i128 mss = s2 * static_cast<i128>(m) - s1 * s1;  // M·Σ(d − d̄)², exact
    out[i] = static_cast<double>(mss) / static_cast<double>(m) / (static_cast<double>(m) - 1.0) * q2;
  }
  return out;
}

/// Weighted regression s² = X·β, weights (n/t)/model² (the EDF of s²(t) falls as t/T), iterated
/// from the data's own variances. Unconstrained, so linear and unbiased in s² for fixed weights.
bool regress(const std::vector<DirectPoint>& pts, const std::vector<Vec3>& x, Vec3& beta) {
  const std::size_t k = pts.size();
  std::vector<double> w(k);
  for (std::size_t i = 0; i < k; ++i) w[i] = 1.0 / (pts[i].t_s * pts[i].var_arcsec2 * pts[i].var_arcsec2 + 1e-300);
  for (int it = 0; it < 4; ++it) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Vec3 rhs = Vec3::Zero();
    for (std::size_t i = 0; i < k; ++i) {
      a += w[i] * x[i] * x[i].transpose();
      rhs += w[i] * pts[i].var_arcsec2 * x[i];
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(a);
    if (ldlt.info() != Eigen::Success) return false;
    beta = ldlt.solve(rhs);
    if (!beta.allFinite()) return false;
    for (std::size_t i = 0; i < k; ++i) {
      const double m = x[i].dot(beta);
      const double v = m > 0 ? m : pts[i].var_arcsec2;
      w[i] = 1.0 / (pts[i].t_s * v * v + 1e-300);
    }
  }
  return true;
}

Vec3 as_vec(const IncrementBasis& g) { return {g.q, g.n, g.b}; }

/// Interval lengths (sample steps), log-spaced over [t_min, t_max], multiples of `base`.
std::vector<std::size_t> interval_grid(double t_min, double t_max, int count, double tau0, std::size_t base) {
  std::vector<std::size_t> ts;
  for (int i = 0; i < count; ++i) {
    const double t = t_min * std::pow(t_max / t_min, count > 1 ? double(i) / (count - 1) : 0.0);
    const auto j = static_cast<std::size_t>(std::max(1.0, std::round(t / tau0 / static_cast<double>(base))));
    if (ts.empty() || j * base != ts.back()) ts.push_back(j * base);
  }
  return ts;
}

}  // namespace

IncrementBasis increment_basis(std::size_t t, std::size_t points, double step, bool overlapping) {
  const std::size_t n = points > 0 ? points - 1 : 0;
  const double ts = static_cast<double>(t) * step;
  Vec3 e = Vec3::Zero();
  if (!overlapping) {
    // k blocks; Σ Δ_j = θ(k·t) − θ(0).
    const std::size_t k = t > 0 ? n / t : 0;
    if (k < 2) return {};
    const auto kd = static_cast<double>(k);
    e = (kd * structure(ts) - structure(kd * ts) / kd) / (kd - 1.0);
    return {e[0], e[1], e[2]};
  }
  if (t == 0 || n + 1 < 2 * t) return {};
  const std::size_t m = n - t + 1;
  const auto md = static_cast<double>(m);
  // Σ Δ_k = (last t phases) − (first t phases): Var = −½ Σ a_i a_j D(i − j).
  Vec3 v = Vec3::Zero();
  const auto td = static_cast<double>(t);
  for (std::size_t h = 1; h < t; ++h) {
    const double w = td - static_cast<double>(h);
    v += w * (structure((md + static_cast<double>(h)) * step) + structure((md - static_cast<double>(h)) * step)) -
         2.0 * w * structure(static_cast<double>(h) * step);
  }
  v += td * structure(md * step);
  e = (md * structure(ts) - v / md) / (md - 1.0);
  return {e[0], e[1], e[2]};
}

namespace {

/// Overlapping increment variances at the lengths ts (sample steps) of x.
std::vector<DirectPoint> overlapping_points(const PhaseSeries& x, const std::vector<std::size_t>& ts) {
  const std::vector<double> v = overlapping_variances(x, ts);
  std::vector<DirectPoint> pts(ts.size());
  const std::size_t n = x.points() - 1;
  for (std::size_t i = 0; i < ts.size(); ++i) pts[i] = {static_cast<double>(ts[i]) * x.tau0_s, n - ts[i] + 1, v[i]};
  return pts;
}

/// The paper's line: non-overlapping variances, weighted straight line a + b·t.
bool fit_straight(const std::vector<DirectPoint>& pts, double& a, double& b) {
  double s0 = 0, s1 = 0, s2 = 0, sy = 0, sty = 0;
  std::vector<double> w(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i)
    w[i] = static_cast<double>(pts[i].intervals - 1) / (pts[i].var_arcsec2 * pts[i].var_arcsec2 + 1e-300);
  for (int it = 0; it < 4; ++it) {
    s0 = s1 = s2 = sy = sty = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double t = pts[i].t_s;
      s0 += w[i];
      s1 += w[i] * t;
      s2 += w[i] * t * t;
      sy += w[i] * pts[i].var_arcsec2;
      sty += w[i] * t * pts[i].var_arcsec2;
    }
    const double det = s0 * s2 - s1 * s1;
    if (!(det > 0)) return false;
    b = (s0 * sty - s1 * sy) / det;
    a = (sy - b * s1) / s0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double m = a + b * pts[i].t_s;
      const double v = m > 0 ? m : pts[i].var_arcsec2;
      w[i] = static_cast<double>(pts[i].intervals - 1) / (v * v + 1e-300);
    }
  }
  return std::isfinite(a) && std::isfinite(b);
}

/// Non-overlapping increment variances at lengths ts (the paper's points).
std::vector<DirectPoint> block_points(const PhaseSeries& x, const std::vector<std::size_t>& ts) {
  std::vector<DirectPoint> pts;
  const std::size_t n = x.points() - 1;
  for (std::size_t m : ts) {
    const std::size_t k = n / m;
    if (k < 10) continue;
    std::vector<double> d(k);
    for (std::size_t j = 0; j < k; ++j) d[j] = x.diff((j + 1) * m, j * m);
    pts.push_back({static_cast<double>(m) * x.tau0_s, k, sample_variance(d)});
  }
  return pts;
}

/// A bootstrap standard deviation and the replicates it rests on.
struct BootstrapSd {
  double sd = 0.0;
  /// Semi-deviations below and above the replicates' mean, √(2·Σ(x − x̄)²/(count − 1)) over each
  /// side: equal to sd for a symmetric spread.
  double sd_below = 0.0, sd_above = 0.0;
  std::size_t count = 0;
};

/// The bootstrap's seed, from the record's own overlapping variances: its Monte-Carlo error then varies
/// from record to record (and the interval's t quantile accounts for it) instead of being one fixed
/// draw shared by every record. With one seed for all, the 64 replicates' relative sd of N″² was a
/// single draw 8 % low, and every record's interval was too narrow (92.6 % coverage on pure ARW).
/// The variances enter rounded to 20 bits of mantissa (6 digits): a change in their last digits (a
/// pulse weight read as 0.92 or 0.9200000000009, another processor's arithmetic) then leaves the
/// seed as it is, except once in about 10^6 records, instead of drawing another bootstrap each time.
std::uint64_t bootstrap_seed(const std::vector<DirectPoint>& pts) {
  constexpr int kDroppedBits = 52 - 20;
  std::uint64_t h = 0x5eedu;
  for (const auto& p : pts) {
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(p.var_arcsec2);
    h = derive_seed(h, (bits + (std::uint64_t{1} << (kDroppedBits - 1))) >> kDroppedBits);
  }
  return h;
}

/// Standard deviation of N″² over a parametric bootstrap from the fitted (Q², N″², B²): the rate
/// terms are simulated at the coarse step `base` (the interval grid is a multiple of it) and their
/// overlapping variances computed there; the white-angle part, whose sampling noise at the data's
/// stride is tiny, enters per point as its expectation plus a normal with its exact variance.
BootstrapSd bootstrap_n2_sd(const DirectNResult& r, const std::vector<std::size_t>& ts, std::size_t base, double tau0,
                            std::size_t n, int replicates) {
  const double step = static_cast<double>(base) * tau0;
  const std::size_t nb = n / base;
  const double q2 = std::max(0.0, r.q2_arcsec2), n2 = std::max(0.0, r.n2_arcsec2_per_s);
  const double b2 = std::max(0.0, r.b2_arcsec2_per_s2);
  NoiseModel model;
  model.arw_deg_per_sqrt_h = std::sqrt(n2) / 60.0;
  model.bias_instability_deg_per_h = std::sqrt(b2);
  SimulationSettings settings;
  settings.rate_hz = 1.0 / step;
  settings.duration_s = static_cast<double>(nb) * step;
  // A counting error of 1e-6″ is negligible; a model whose angle would pass 2^40 such pulses (data
  // of huge rates) is counted in pulses of 2^-40 of its extent (6σ of the random walk and the
  // flicker's drift over the record), still negligible and far inside the simulator's range.
  const double extent = 6.0 * (std::sqrt(n2 * settings.duration_s) + std::sqrt(b2) * settings.duration_s);
  settings.scale_arcsec = std::max(1e-6, std::ldexp(extent, -40));
  std::vector<Vec3> xb(ts.size());
  std::vector<std::size_t> coarse(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i) coarse[i] = ts[i] / base;
  std::vector<double> white_sd(ts.size());
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const IncrementBasis gc = increment_basis(ts[i] / base, nb + 1, step);
    xb[i] = {r.basis[i].q, gc.n, gc.b};
    // Var of the white-angle part (its t-dependent half) and of its cross term with the rate part.
    const double md = static_cast<double>(r.points[i].intervals);
    const double rate_part = r.basis[i].n * n2 + r.basis[i].b * b2;
    white_sd[i] = std::sqrt((4.0 * q2 * q2 + 8.0 * q2 * rate_part) / md);
  }
  // One simulator per worker (its flicker filter is made once); each replicate has its own seed,
  // so the result does not depend on the split.
  const std::uint64_t seed = bootstrap_seed(r.points);
  const std::size_t kChunks = std::max(1u, worker_count());
  std::vector<double> n2s(static_cast<std::size_t>(replicates), 0.0);
  std::vector<char> ok(n2s.size(), 0);
  parallel_for(kChunks, [&](std::size_t c) {
    Simulator sim(model, settings);
    PhaseSeries x;
    for (std::size_t rep = c; rep < n2s.size(); rep += kChunks) {
      sim.run(derive_seed(seed, 2 * rep), x);
      Rng rng(derive_seed(seed, 2 * rep + 1));
      std::vector<DirectPoint> pts(ts.size());
      const std::vector<double> rate_part = overlapping_variances(x, coarse);
      for (std::size_t i = 0; i < ts.size(); ++i) {
        const double v = rate_part[i] + r.basis[i].q * q2 + white_sd[i] * rng.normal();
        pts[i] = {r.points[i].t_s, r.points[i].intervals, v};
      }
      Vec3 beta;
      if (regress(pts, xb, beta)) {
        n2s[rep] = beta[1];
        ok[rep] = 1;
      }
    }
  });
  std::vector<double> good;
  for (std::size_t i = 0; i < n2s.size(); ++i)
    if (ok[i]) good.push_back(n2s[i]);
  if (good.size() < 8) return {};
  double mean = 0, below = 0, above = 0;
  for (double v : good) mean += v / static_cast<double>(good.size());
  for (double v : good) (v < mean ? below : above) += 2.0 * (v - mean) * (v - mean);
  const double dof = static_cast<double>(good.size() - 1);
  return {std::sqrt(sample_variance(good)), std::sqrt(below / dof), std::sqrt(above / dof), good.size()};
}

}  // namespace

DirectNResult direct_n(const PhaseSeries& x, const MethodOptions& o, const FitResult* fit) {
  require_valid(o);
  DirectNResult r;
  const std::size_t n = x.points() > 0 ? x.points() - 1 : 0;
  const double t_total = static_cast<double>(n) * x.tau0_s;
  const double t_max = std::min(o.direct_t_max_s, t_total / 50.0);
  const double t_min = std::max(o.direct_t_min_s, x.tau0_s);
  if (n < 20 || !(t_max > t_min)) return r;
  // The bootstrap's coarse step: the shortest interval, whole samples, but no finer than T/16384 so that
  // a replicate stays cheap (a shorter requested t_min is raised to it).
  constexpr std::size_t kMaxCoarse = 16384;
  const auto base = std::max(static_cast<std::size_t>(std::max(1.0, std::floor(t_min / x.tau0_s))),
                             (n + kMaxCoarse - 1) / kMaxCoarse);
  const std::vector<std::size_t> ts = interval_grid(t_min, t_max, o.direct_points, x.tau0_s, base);

  // The paper's straight line through non-overlapping variances.
  auto& sl = r.straight;
  sl.points = block_points(x, ts);
  if (sl.points.size() >= 3 && fit_straight(sl.points, sl.intercept_arcsec2, sl.slope_arcsec2_per_s)) {
    sl.valid = true;
    sl.value = sl.slope_arcsec2_per_s > 0 ? std::sqrt(sl.slope_arcsec2_per_s) / 60.0 : 0.0;
  }

  if (ts.size() < 4) return r;
  r.points = overlapping_points(x, ts);
  // A counter's read-out error is not white angle noise: its known part of each variance is taken off.
  if (fit)
    for (DirectPoint& p : r.points) p.var_arcsec2 -= fit->counter_increment_var(std::llround(p.t_s / x.tau0_s));
  r.basis.resize(ts.size());  // each an O(t) sum: in parallel
  parallel_for(ts.size(), [&](std::size_t i) { r.basis[i] = increment_basis(ts[i], n + 1, x.tau0_s); });
  std::vector<Vec3> xs;
  for (const IncrementBasis& g : r.basis) xs.push_back(as_vec(g));
  Vec3 beta;
  if (!regress(r.points, xs, beta)) return r;
  r.q2_arcsec2 = beta[0];
  r.n2_arcsec2_per_s = beta[1];
  r.b2_arcsec2_per_s2 = beta[2];
  r.replicates = std::max(0, o.bootstrap_replicates);
  const BootstrapSd bs = r.replicates > 0 ? bootstrap_n2_sd(r, ts, base, x.tau0_s, n, r.replicates) : BootstrapSd{};
  const double sd = bs.sd;

  // N″² ± t·sd, t the 97.5 % point of Student's t on the replicates' count − 1 (the sd is itself an
  // estimate: 64 replicates, t = 2.00), mapped through √ (N = √(N″²)/60); the low end may reach 0.
  auto& e = r.N;
  e.valid = sd > 0;
  if (!e.valid) return r;
  const double t95 = boost::math::quantile(boost::math::students_t(static_cast<double>(bs.count - 1)), 0.975);
  // The basic bootstrap's orientation: a right-skewed estimate (N″² traded against B² on short
  // records) puts the truth further below it than above, so the low end takes the upper
  // semi-deviation and the high end the lower one. Symmetric ends (N″² ± t·sd) missed the truth on
  // the high side only: 5 of 64 records at N = 0.00045 °/√h (docs/analysis.md).
  const double lo = beta[1] - t95 * bs.sd_above, hi = beta[1] + t95 * bs.sd_below;
  e.high = hi > 0 ? std::sqrt(hi) / 60.0 : 0.0;
  e.resolved = lo > 0;
  e.low = e.resolved ? std::sqrt(lo) / 60.0 : 0.0;
  e.estimate = beta[1] > 0 ? std::sqrt(beta[1]) / 60.0 : 0.0;
  if (e.resolved) {
    e.value = std::sqrt(beta[1]) / 60.0;
    e.sigma = sd / (2.0 * std::sqrt(beta[1])) / 60.0;
  } else {
    e.value = e.high;
    e.sigma = e.high / (2.0 * kZ95);
  }
  return r;
}

void attach_straight_line_bias(DirectNResult& r, const FitResult& fit, double duration_s, double tau0_s) {
  auto& sl = r.straight;
  const double n2 = fit.c[1];
  if (!sl.valid || !(n2 > 0) || !(tau0_s > 0)) return;
  const auto points = static_cast<std::size_t>(std::llround(duration_s / tau0_s)) + 1;
  std::vector<DirectPoint> expected = sl.points;
  for (auto& p : expected) {
    const auto t = static_cast<std::size_t>(std::llround(p.t_s / tau0_s));
    const IncrementBasis g = increment_basis(t, points, tau0_s, false);
    p.var_arcsec2 =
        g.q * fit.c[0] + g.n * fit.c[1] + g.b * fit.c[2] + fit.counter_increment_var(static_cast<std::int64_t>(t));
  }
  double a = 0, b = 0;
  if (fit_straight(expected, a, b) && b > 0) sl.bias_factor = std::sqrt(b / n2);
}

double AvBEstimate::cdf(double b) const {
  if (!(b > 0)) return 0.0;
  if (!(edf > 0) || !(var > 0)) return b >= B.value ? 1.0 : 0.0;
  // P(σ²_true ≤ s) = P(χ²_ν ≥ ν·σ̂²/s), s = white + (2 ln2/π)·b²: the χ² interval's distribution.
  const double s = white + kFlicker * b * b;
  if (!(s > 0)) return 0.0;  // b² underflows and no white part: no variance can be that small
  const boost::math::chi_squared dist(edf);
  return boost::math::cdf(boost::math::complement(dist, edf * var / s));
}

namespace {

/// Fills B's value and 95 % bounds from σ̂², the removed white part and the EDF.
void finish_av_estimate(AvBEstimate& e) {
  const DevInterval ci = chi2_interval(e.var, e.edf, 0.95);  // deviation bounds
  auto to_b = [&](double s2) { return s2 > e.white ? std::sqrt((s2 - e.white) / kFlicker) : 0.0; };
  auto& m = e.B;
  m.valid = true;
  m.low = to_b(ci.low * ci.low);
  m.high = to_b(ci.high * ci.high);
  m.resolved = m.low > 0;
  m.estimate = to_b(e.var);
  m.value = m.resolved ? m.estimate : m.high;
  m.sigma = (m.high - m.low) / (2.0 * kZ95);
}

/// Model-based EDF of the overlapping AV at one point: 2σ⁴/Var(σ̂²), Var from av_covariance, plus
/// `extra_var` (the uncertainty of a part subtracted from it).
double model_edf(const FitPoint& p, const FitResult& fit, double extra_var) {
  const double mu = fit.model_var(p.tau_s);
  if (p.m <= 0 || p.terms <= 0 || !(mu > 0)) return p.edf;
  const std::vector<FitPoint> one{p};
  const double v = av_covariance(one, fit.covariance_c(), true)(0, 0) + extra_var;
  return v > 0 && std::isfinite(v) ? 2.0 * mu * mu / v : p.edf;
}

}  // namespace

AvBEstimate b_from_averages(const PhaseSeries& x, const FitResult& fit, double block_s) {
  AvBEstimate e;
  const std::size_t n = x.points() > 0 ? x.points() - 1 : 0;
  const double per_block = std::max(1.0, std::round(block_s / x.tau0_s));
  if (!(3.0 * per_block <= static_cast<double>(n))) return e;
  const auto m = static_cast<std::int64_t>(per_block);
  std::int64_t terms = 0;
  e.var = allan_variance(x, m, Estimator::Overlapping, &terms);
  e.tau_s = static_cast<double>(m) * x.tau0_s;
  if (terms <= 0 || !(e.var > 0)) return e;
  // The fitted terms other than B at τ (the white ones; K and R when the fit keeps them), with the
  // variance of that estimate from the fit covariance.
  Eigen::Matrix<double, kTermCount, 1> h;
  for (const Term t : kAllTerms) h[static_cast<int>(t)] = t == Term::B ? 0.0 : term_basis(t, e.tau_s);
  e.white = h.dot(fit.c) + fit.counter_var(e.tau_s);
  const double white_var = std::max(0.0, h.dot(fit.cov_c * h));
  e.edf = model_edf({e.tau_s, e.var, 0.0, m, terms}, fit, white_var);
  if (!(e.edf > 0)) return e;
  finish_av_estimate(e);
  return e;
}

AvBEstimate b_from_minimum(const AllanResult& allan, const SlopeReadout& s, const FitResult& fit) {
  AvBEstimate e;
  if (!s.B) return e;
  const auto it = std::find_if(allan.points.begin(), allan.points.end(),
                               [&](const AllanPoint& p) { return p.tau_s == s.tau_min_s; });
  if (it == allan.points.end()) return e;
  const bool ovl = allan.estimator == Estimator::Overlapping;
  e.tau_s = it->tau_s;
  e.var = it->var;
  e.edf = model_edf({it->tau_s, it->var, it->edf, ovl ? it->m : 0, ovl ? it->n : 0}, fit, 0.0);
  if (!(e.edf > 0)) return e;
  finish_av_estimate(e);
  // σ(τ_min)/0.6643 estimates √(σ²_model(τ_min)/(2 ln2/π)), above B where other terms contribute.
  const double b_fit = std::sqrt(std::max(0.0, fit.c[2]));
  e.bias_factor = b_fit > 0 ? std::sqrt(fit.model_var(e.tau_s) / kFlicker) / b_fit : 0.0;
  return e;
}

BlockSpreadResult block_spread(const PhaseSeries& x, double block_s) {
  BlockSpreadResult r;
  const std::size_t n = x.points() > 0 ? x.points() - 1 : 0;
  // Samples per block, compared as a double before the conversion: a block longer than the
  // record (or NaN) has no whole block, and its count would not fit an integer.
  const double per_block = std::max(1.0, std::round(block_s / x.tau0_s));
  if (!(per_block <= static_cast<double>(n))) {
    r.block_s = std::isfinite(block_s) ? block_s : 0.0;
    return r;
  }
  const auto m = static_cast<std::size_t>(per_block);
  r.block_s = static_cast<double>(m) * x.tau0_s;
  const std::size_t k = n / m;
  r.blocks = k;
  if (k < 3) return r;
  std::vector<double> y(k);
  for (std::size_t j = 0; j < k; ++j) y[j] = x.diff((j + 1) * m, j * m) / r.block_s;
  auto& e = r.spread;
  e.valid = true;
  e.value = std::sqrt(sample_variance(y));
  e.sigma = e.value / std::sqrt(2.0 * static_cast<double>(k - 1));
  e.estimate = e.value;
  const LogNormalInterval i = lognormal_interval95(e.value, e.sigma);
  e.low = i.low;
  e.high = i.high;
  return r;
}

double expected_block_variance(const Eigen::Matrix<double, kTermCount, 1>& c, double tau, std::size_t blocks) {
  if (blocks < 2) return 0;
  // The structure function of the angle, ″² (fit-scale c).
  const std::array<double, 5> ca{c[0], c[1], c[2], c[3], c[4]};
  auto s = [&](double u) { return structure_function(ca, u); };
  const auto mm = static_cast<double>(blocks);
  double sum = 0;
  for (std::size_t l = 1; l < blocks; ++l) {
    const double dl = static_cast<double>(l);
    const double d = (2.0 * s(tau) - s((dl + 1) * tau) - s((dl - 1) * tau) + 2.0 * s(dl * tau)) / (2.0 * tau * tau);
    sum += (mm - dl) * d;
  }
  return 2.0 * sum / (mm * (mm - 1.0));
}

void attach_expectation(BlockSpreadResult& r, const FitResult& fit) {
  if (!r.spread.valid) return;
  const double v = expected_block_variance(fit.c, r.block_s, r.blocks);
  if (!(v > 0)) return;
  r.expected = std::sqrt(v);
  // Linear in c: gradient by unit vectors.
  Eigen::Matrix<double, kTermCount, 1> h;
  for (int i = 0; i < kTermCount; ++i) {
    Eigen::Matrix<double, kTermCount, 1> e = Eigen::Matrix<double, kTermCount, 1>::Zero();
    e[i] = 1.0;
    h[i] = expected_block_variance(e, r.block_s, r.blocks);
  }
  const double var_v = h.dot(fit.cov_c * h);
  r.expected_sigma = var_v > 0 ? std::sqrt(var_v) / (2.0 * r.expected) : 0.0;
}

double discrepancy_sigma(double a, double sa, double b, double sb) {
  const double s = std::sqrt(sa * sa + sb * sb);
  return s > 0 ? (a - b) / s : 0.0;
}

}  // namespace rwcalc
