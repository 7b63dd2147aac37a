// Allan-variance engine: τ grids, the three estimators, and the per-τ noise id / EDF / bounds,
// computed in parallel across τ.
#include "rwcalc/allan.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

#include "allan_all.hpp"
#include "allan_kernels.hpp"
#include "rwcalc/confidence.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/progress.hpp"

namespace rwcalc {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

double parse_number(std::string_view s, std::string_view spec) {
  s = trim(s);
  double v = 0;
  const auto* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (s.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
    throw UsageError(
        trf("--tau: '{}' in '{}' is not a number of seconds (expected octave, "
            "decade, dense[:P], all, or a list such as 1,2,5)",
            s, spec));
  return v;
}

// `--tau all` on records of at least kAllFftMinPoints: cluster sizes from kAllExactBelow on take
// their sums from the FFT path (allan_all.hpp); smaller ones, and every other grid, stay exact.
constexpr std::int64_t kAllExactBelow = 1024;
constexpr std::size_t kAllFftMinPoints = std::size_t{1} << 15;

}  // namespace

TauGrid TauGrid::parse(std::string_view spec) {
  const std::string_view s = trim(spec);
  TauGrid g;
  if (s == "octave") return g;
  if (s == "decade") {
    g.kind = Kind::Decade;
    return g;
  }
  if (s == "all") {
    g.kind = Kind::All;
    return g;
  }
  if (s == "dense" || s.starts_with("dense:")) {
    g.kind = Kind::Dense;
    if (s.size() > 5) {
      const std::string_view p = s.substr(6);
      int v = 0;
      const auto [ptr, ec] = std::from_chars(p.data(), p.data() + p.size(), v);
      if (p.empty() || ec != std::errc() || ptr != p.data() + p.size() || v < 1 || v > 1000)
        throw UsageError(trf("--tau: '{}': P in dense:P must be an integer from 1 to 1000", spec));
      g.per_decade = v;
    }
    return g;
  }
  g.kind = Kind::Explicit;
  std::string_view rest = s;
  while (true) {
    const auto comma = rest.find(',');
    const double t = parse_number(rest.substr(0, comma), spec);
    if (!(t > 0)) throw UsageError(trf("--tau: τ must be positive, got {} in '{}'", t, spec));
    g.taus_s.push_back(t);
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  return g;
}

std::int64_t max_cluster_size(Estimator est, std::size_t points) {
  const auto n = static_cast<std::int64_t>(points);
  switch (est) {
    case Estimator::Overlapping:
    case Estimator::NonOverlapping: return n >= 3 ? (n - 1) / 2 : 0;  // N − 2m ≥ 1
    case Estimator::Modified: return n >= 3 ? n / 3 : 0;              // N − 3m + 1 ≥ 1
    case Estimator::OverlappingHadamard:
    case Estimator::NonOverlappingHadamard: return n >= 4 ? (n - 1) / 3 : 0;  // N − 3m ≥ 1
  }
  return 0;
}

std::int64_t term_count(Estimator est, std::int64_t m, std::size_t points) {
  const auto n = static_cast<std::int64_t>(points);
  if (m < 1) return 0;
  std::int64_t t = 0;
  switch (est) {
    case Estimator::Overlapping: t = n - 2 * m; break;
    case Estimator::NonOverlapping: t = n >= 1 ? (n - 1) / m - 1 : 0; break;
    case Estimator::Modified: t = n - 3 * m + 1; break;
    case Estimator::OverlappingHadamard: t = n - 3 * m; break;
    case Estimator::NonOverlappingHadamard: t = n >= 1 ? (n - 1) / m - 2 : 0; break;
  }
  return std::max<std::int64_t>(t, 0);
}

std::vector<std::int64_t> cluster_sizes(const TauGrid& grid, Estimator est, std::size_t points, double tau0_s) {
  std::int64_t limit = max_cluster_size(est, points);
  if (grid.max_m > 0) limit = std::min(limit, grid.max_m);
  std::vector<std::int64_t> ms;
  switch (grid.kind) {
    case TauGrid::Kind::Octave:
      for (std::int64_t m = 1; m <= limit; m *= 2) ms.push_back(m);
      break;
    case TauGrid::Kind::Decade:
      for (std::int64_t p = 1; p <= limit; p *= 10)
        for (std::int64_t f : {1, 2, 4})
          if (f * p <= limit) ms.push_back(f * p);
      break;
    case TauGrid::Kind::Dense:
      for (int j = 0;; ++j) {
        const double v = std::round(std::pow(10.0, static_cast<double>(j) / grid.per_decade));
        if (v > static_cast<double>(limit)) break;
        const auto m = static_cast<std::int64_t>(v);
        if (ms.empty() || ms.back() != m) ms.push_back(m);
      }
      break;
    case TauGrid::Kind::All:
      ms.reserve(static_cast<std::size_t>(std::max<std::int64_t>(limit, 0)));
      for (std::int64_t m = 1; m <= limit; ++m) ms.push_back(m);
      break;
    case TauGrid::Kind::Explicit:
      for (double t : grid.taus_s) {
        const double r = t / tau0_s;
        const double m = std::round(r);
        if (m < 1 || std::fabs(r - m) > 1e-9 * std::max(1.0, m))
          throw UsageError(trf("--tau {} s is not a whole number of samples (τ0 = {} s)", t, tau0_s));
        if (m > static_cast<double>(limit))
          throw UsageError(
              trf("--tau {} s (m = {}) is beyond the longest usable τ of this record, "
                  "{} s (m = {})",
                  t, m, static_cast<double>(limit) * tau0_s, limit));
        ms.push_back(static_cast<std::int64_t>(m));
      }
      std::sort(ms.begin(), ms.end());
      ms.erase(std::unique(ms.begin(), ms.end()), ms.end());
      break;
  }
  if (grid.with_octave && grid.kind != TauGrid::Kind::Octave) {
    const std::int64_t top = max_cluster_size(est, points);
    for (std::int64_t m = 1; m <= top; m *= 2) ms.push_back(m);
    std::sort(ms.begin(), ms.end());
    ms.erase(std::unique(ms.begin(), ms.end()), ms.end());
  }
  return ms;
}

namespace {

/// The counts of an exact record and, for the modified variance, their modular prefix sums.
struct CountData {
  const std::int64_t* c = nullptr;
  std::vector<std::uint64_t> prefix;

  CountData(const PhaseSeries& x, Estimator est) {
    if (!x.exact()) return;
    c = x.counts.data();
    if (est == Estimator::Modified) prefix = detail::count_prefix_sums(c, x.points());
  }
};

/// σ² from a sum of n squared second differences; `scale` brings the sum to phase units squared
/// (q² for counts: the pulse weight enters only here).
double avar_from_sum(double sumsq, double scale, double tau, std::int64_t n) {
  return sumsq * scale / (2.0 * tau * tau * static_cast<double>(n));
}

double sum_scale(const PhaseSeries& x) { return x.exact() ? x.arcsec_per_count * x.arcsec_per_count : 1.0; }

// Variance of one τ.
double variance_at(const PhaseSeries& x, const CountData& data, std::int64_t m, Estimator est,
                   std::int64_t* terms_out) {
  const std::int64_t n = term_count(est, m, x.points());
  if (terms_out) *terms_out = n;
  if (n < 1) return 0.0;
  const double tau = static_cast<double>(m) * x.tau0_s;
  if (est == Estimator::Modified) {
    const double md = static_cast<double>(m);
    const double sumsq = x.exact() ? detail::modified_sumsq(data.prefix.data(), n, m) * sum_scale(x)
                                   : detail::modified_sumsq(x.values.data(), n, m);
    return sumsq / (2.0 * md * md * tau * tau * static_cast<double>(n));
  }
  const bool overlapping = est == Estimator::Overlapping || est == Estimator::OverlappingHadamard;
  const std::int64_t stride = overlapping ? 1 : m;
  if (is_hadamard(est)) {  // HVAR = Σ (third difference)² / (6 τ² n)
    const double sumsq = x.exact() ? static_cast<double>(detail::third_diff_sumsq(data.c, n, m, stride))
                                   : detail::third_diff_sumsq(x.values.data(), n, m, stride);
    return sumsq * sum_scale(x) / (6.0 * tau * tau * static_cast<double>(n));
  }
  if (x.exact() && overlapping) {  // a pass over the whole record: the sweep's stretches run in parallel
    const std::int64_t one[] = {m};
    return avar_from_sum(static_cast<double>(detail::second_diff_sumsq_sweep(data.c, x.points(), one)[0]), sum_scale(x),
                         tau, n);
  }
  const double sumsq = x.exact() ? static_cast<double>(detail::second_diff_sumsq(data.c, n, m, stride))
                                 : detail::second_diff_sumsq(x.values.data(), n, m, stride);
  return avar_from_sum(sumsq, sum_scale(x), tau, n);
}

/// Overlapping sums of every m ≥ kAllExactBelow through FFT autocorrelations (allan_all.hpp),
/// O(N log² N) instead of O(N²), for the `all` grid of a long record; empty otherwise.
std::vector<double> all_grid_fft_sums(const PhaseSeries& x, const CountData& data, const TauGrid& grid, Estimator est,
                                      std::int64_t max_m) {
  const std::size_t points = x.points();
  if (grid.kind != TauGrid::Kind::All || est != Estimator::Overlapping || max_m < kAllExactBelow ||
      points < kAllFftMinPoints)
    return {};
  std::vector<double> phase(points);
  if (x.exact()) {
    const auto c0 = static_cast<std::uint64_t>(data.c[0]);
    for (std::size_t k = 0; k < points; ++k)
      phase[k] = static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(data.c[k]) - c0));
  } else {
    phase = x.values;
  }
  return detail::all_oavar_sumsq_fft(std::move(phase), max_m);
}

/// The overlapping sums of every m of ms in one blocked sweep: exact over counts, in lanes over
/// floating phase (allan_kernels.hpp).
std::vector<double> overlapping_sweep(const PhaseSeries& x, const CountData& data,
                                      const std::vector<std::int64_t>& ms) {
  if (!x.exact()) return detail::second_diff_sumsq_sweep(x.values.data(), x.points(), ms);
  const std::vector<u128> exact = detail::second_diff_sumsq_sweep(data.c, x.points(), ms);
  return {exact.begin(), exact.end()};
}

/// σ² of every τ of ms: from the FFT sums where `all` takes them (analyze's fitted octave points
/// stay exact), from one blocked sweep for the other overlapping sums, else per τ.
std::vector<double> grid_variances(const PhaseSeries& x, const CountData& data, const std::vector<std::int64_t>& ms,
                                   const TauGrid& grid, Estimator est, std::int64_t& fft_from_m) {
  const std::vector<double> fft_sums = all_grid_fft_sums(x, data, grid, est, ms.back());
  if (!fft_sums.empty()) fft_from_m = kAllExactBelow;
  auto from_fft = [&](std::int64_t m) {
    const bool octave_kept = grid.with_octave && (m & (m - 1)) == 0;
    return !fft_sums.empty() && m >= kAllExactBelow && !octave_kept;
  };
  std::vector<std::int64_t> swept_ms;
  if (est == Estimator::Overlapping)
    for (std::int64_t m : ms)
      if (!from_fft(m)) swept_ms.push_back(m);
  const std::vector<double> swept = overlapping_sweep(x, data, swept_ms);
  std::vector<double> var(ms.size(), 0.0);
  std::size_t next_swept = 0;
  std::vector<std::size_t> per_tau;  // the τ left to compute one by one
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::int64_t m = ms[i], n = term_count(est, m, x.points());
    const double tau = static_cast<double>(m) * x.tau0_s;
    if (from_fft(m))
      var[i] = n > 0 ? avar_from_sum(fft_sums[static_cast<std::size_t>(m)], sum_scale(x), tau, n) : 0.0;
    else if (!swept_ms.empty())
      var[i] = n > 0 ? avar_from_sum(swept[next_swept++], sum_scale(x), tau, n) : 0.0;
    else
      per_tau.push_back(i);
  }
  parallel_for(per_tau.size(),
               [&](std::size_t j) { var[per_tau[j]] = variance_at(x, data, ms[per_tau[j]], est, nullptr); });
  return var;
}

void check_options(const PhaseSeries& x, const AllanOptions& options) {
  require_valid(options);
  if (!(x.tau0_s > 0) || !std::isfinite(x.tau0_s))
    throw UsageError(trf("sample period must be positive, got {} s", x.tau0_s));
  if (max_cluster_size(options.estimator, x.points()) < 1)
    throw AnalysisError(trf("the record has {} phase point(s); the {} needs at least {}", x.points(),
                            variance_name(options.estimator), 3));
}

}  // namespace

double allan_variance(const PhaseSeries& x, std::int64_t m, Estimator est, std::int64_t* terms) {
  return variance_at(x, CountData(x, est), m, est, terms);
}

AllanResult compute_allan(const PhaseSeries& x, const AllanOptions& options) {
  check_options(x, options);
  const Estimator est = options.estimator;
  const std::size_t points = x.points();
  const std::vector<std::int64_t> ms = cluster_sizes(options.grid, est, points, x.tau0_s);
  if (ms.empty()) throw AnalysisError(tr("no cluster size of the τ grid fits this record"));

  AllanResult result;
  result.estimator = est;
  result.unit = x.deviation_unit();
  result.tau0_s = x.tau0_s;
  result.points_in = points;
  result.confidence = options.confidence;
  result.points.resize(ms.size());
  // Two steps per τ: the noise identification, then the EDF and the bounds.
  Progress progress(tr("computing the deviation at each τ"), 2 * ms.size(), options.progress,
                    Progress::Measure::Percent);
  const std::vector<double> var = grid_variances(x, CountData(x, est), ms, options.grid, est, result.fft_from_m);
  parallel_for(ms.size(), [&](std::size_t i) {
    AllanPoint& p = result.points[i];
    p.m = ms[i];
    p.tau_s = static_cast<double>(p.m) * x.tau0_s;
    p.n = term_count(est, p.m, points);
    p.var = var[i];
    p.dev = std::sqrt(p.var);
    p.alpha = options.noise_id ? identify_noise(x, p.m, est, options.noise_id_domain) : options.alpha;
    progress.advance();
  });
  // EDF and bounds once every α is known: Stable32 does not identify the noise at the longest τ of
  // a run (too few points) but carries the previous τ's α over.
  if (options.noise_id && result.points.size() > 1)
    result.points.back().alpha = result.points[result.points.size() - 2].alpha;
  parallel_for(ms.size(), [&](std::size_t i) {
    AllanPoint& p = result.points[i];
    p.edf = edf_for(est, p.alpha, p.m, points);
    const DevInterval ci = chi2_interval(p.var, p.edf, options.confidence);
    p.dev_low = ci.low;
    p.dev_high = ci.high;
    progress.advance();
  });
  return result;
}

nlohmann::json to_json(const AllanResult& r) {
  nlohmann::json pts = nlohmann::json::array();
  for (const AllanPoint& p : r.points)
    pts.push_back({{"af", p.m},
                   {"tau_s", p.tau_s},
                   {"n", p.n},
                   {"alpha", p.alpha},
                   {"edf", p.edf},
                   {"dev", p.dev},
                   {"dev_low", p.dev_low},
                   {"dev_high", p.dev_high}});
  nlohmann::json j = {{"unit", r.unit},
                      {"estimator", std::string(to_string(r.estimator))},
                      {"confidence", r.confidence},
                      {"tau0_s", r.tau0_s},
                      {"phase_points", r.points_in},
                      {"points", std::move(pts)}};
  if (r.fft_from_m > 0) j["fft_from_af"] = r.fft_from_m;  // sums from this m on: FFT path, not exact
  return j;
}

std::string_view to_string(Estimator e) {
  switch (e) {
    case Estimator::Overlapping: return "oadev";
    case Estimator::NonOverlapping: return "adev";
    case Estimator::Modified: return "mdev";
    case Estimator::OverlappingHadamard: return "ohdev";
    case Estimator::NonOverlappingHadamard: return "hdev";
  }
  return "?";
}

std::string deviation_name(Estimator e) {
  switch (e) {
    case Estimator::Overlapping: return tr("overlapping Allan deviation");
    case Estimator::NonOverlapping: return tr("non-overlapping Allan deviation");
    case Estimator::Modified: return tr("modified Allan deviation");
    case Estimator::OverlappingHadamard: return tr("overlapping Hadamard deviation");
    case Estimator::NonOverlappingHadamard: return tr("Hadamard deviation");
  }
  return "?";
}

std::string variance_name(Estimator e) {
  switch (e) {
    case Estimator::Overlapping: return tr("overlapping Allan variance");
    case Estimator::NonOverlapping: return tr("non-overlapping Allan variance");
    case Estimator::Modified: return tr("modified Allan variance");
    case Estimator::OverlappingHadamard: return tr("overlapping Hadamard variance");
    case Estimator::NonOverlappingHadamard: return tr("Hadamard variance");
  }
  return "?";
}

Estimator parse_estimator(std::string_view s) {
  if (s == "oadev" || s == "overlapping") return Estimator::Overlapping;
  if (s == "adev" || s == "nonoverlapping" || s == "non-overlapping") return Estimator::NonOverlapping;
  if (s == "mdev" || s == "modified") return Estimator::Modified;
  if (s == "ohdev") return Estimator::OverlappingHadamard;
  if (s == "hdev") return Estimator::NonOverlappingHadamard;
  throw UsageError(trf("unknown estimator '{}' (expected oadev, adev, mdev, ohdev or hdev)", s));
}

}  // namespace rwcalc
