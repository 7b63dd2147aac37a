// Allan-variance engine: τ grids, the three estimators, and the per-τ noise id / EDF / bounds,
// computed in parallel across τ.
#include "rwcalc/allan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>

#include "allan/allan_all.hpp"
#include "allan/allan_kernels.hpp"
#include "allan/noise_id.hpp"
#include "core/timing.hpp"
#include "rwcalc/confidence.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/thread.hpp"

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
    throw UsageError(fmt::format("--tau: '{}' in '{}' is not a number of seconds (expected octave, "
                                 "decade, dense[:P], all, or a list such as 1,2,5)",
                                 s, spec));
  return v;
}

// `--tau all` on records of at least kAllFftMinPoints: cluster sizes from kAllExactBelow on take
// their sums from the FFT path (allan_all.hpp); smaller ones, and every other grid, stay exact.
constexpr std::int64_t kAllExactBelow = 1024;
constexpr std::size_t kAllFftMinPoints = std::size_t{1} << 15;

// The sums for one τ with exact data: the pulse weight and τ enter only here.
double finish_counts(detail::u128 sumsq, double q, double tau, double denom) {
  return static_cast<double>(sumsq) * (q * q) / (2.0 * tau * tau * denom);
}

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
        throw UsageError(fmt::format("--tau: '{}': P in dense:P must be an integer from 1 to 1000", spec));
      g.per_decade = v;
    }
    return g;
  }
  g.kind = Kind::Explicit;
  std::string_view rest = s;
  while (true) {
    const auto comma = rest.find(',');
    const double t = parse_number(rest.substr(0, comma), spec);
    if (!(t > 0)) throw UsageError(fmt::format("--tau: τ must be positive, got {} in '{}'", t, spec));
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
  }
  return std::max<std::int64_t>(t, 0);
}

std::vector<std::int64_t> cluster_sizes(const TauGrid& grid, Estimator est, std::size_t points,
                                        double tau0_s) {
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
          throw UsageError(fmt::format("--tau {} s is not a whole number of samples (τ0 = {} s)", t, tau0_s));
        if (m > static_cast<double>(limit))
          throw UsageError(fmt::format("--tau {} s (m = {}) is beyond the longest usable τ of this record, "
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

// Variance of one τ; `prepared` holds the counts in their fast exact form (see PreparedCounts).
double variance_at(const PhaseSeries& x, std::int64_t m, Estimator est, const detail::PreparedCounts* prepared,
                   std::int64_t* terms_out) {
  const std::size_t points = x.points();
  const std::int64_t n = term_count(est, m, points);
  if (terms_out) *terms_out = n;
  if (n < 1) return 0.0;
  const double tau = static_cast<double>(m) * x.tau0_s;
  const double q = x.arcsec_per_count;
  detail::PreparedCounts local;
  if (x.exact() && !prepared) {
    local = detail::prepare_counts(x, est == Estimator::Modified);
    prepared = &local;
  }
  switch (est) {
    case Estimator::Overlapping:
    case Estimator::NonOverlapping: {
      const std::int64_t stride = est == Estimator::Overlapping ? 1 : m;
      if (x.exact())
        return finish_counts(detail::second_diff_sumsq(*prepared, n, m, stride), q, tau, static_cast<double>(n));
      return detail::second_diff_sumsq_values(x.values.data(), n, m, stride) /
             (2.0 * tau * tau * static_cast<double>(n));
    }
    case Estimator::Modified: {
      const double md = static_cast<double>(m);
      const double sumsq = x.exact() ? detail::modified_sumsq(*prepared, n, m) * (q * q)
                                     : detail::modified_sumsq_values(x.values.data(), n, m);
      return sumsq / (2.0 * md * md * tau * tau * static_cast<double>(n));
    }
  }
  return 0.0;
}

}  // namespace

double allan_variance(const PhaseSeries& x, std::int64_t m, Estimator est, std::int64_t* terms) {
  return variance_at(x, m, est, nullptr, terms);
}

AllanResult compute_allan(const PhaseSeries& x, const AllanOptions& options) {
  if (!(options.confidence > 0 && options.confidence < 1))
    throw UsageError(fmt::format("--confidence must lie strictly between 0 and 1, got {}", options.confidence));
  if (!(x.tau0_s > 0) || !std::isfinite(x.tau0_s))
    throw UsageError(fmt::format("sample period must be positive, got {} s", x.tau0_s));
  if (!options.noise_id && (options.alpha < -2 || options.alpha > 2))
    throw UsageError(fmt::format("noise exponent alpha must lie in -2..2, got {}", options.alpha));
  const Estimator est = options.estimator;
  const std::size_t points = x.points();
  if (max_cluster_size(est, points) < 1)
    throw AnalysisError(fmt::format("the record has {} phase point(s); the {} variance needs at least {}",
                                    points, long_name(est), 3));
  const std::vector<std::int64_t> ms = cluster_sizes(options.grid, est, points, x.tau0_s);
  if (ms.empty()) throw AnalysisError("no cluster size of the τ grid fits this record");

  AllanResult result;
  result.estimator = est;
  result.unit = x.deviation_unit();
  result.tau0_s = x.tau0_s;
  result.points_in = points;
  result.confidence = options.confidence;
  result.points.resize(ms.size());

  unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, ms.size()));

  detail::PreparedCounts prepared;
  if (x.exact()) {
    detail::ScopedTimer t("allan: prepare counts");
    prepared = detail::prepare_counts(x, est == Estimator::Modified, threads, options.crew);
  }

  // Every m of a long record: the sums above kAllExactBelow come from FFT autocorrelations
  // (allan_all.hpp), O(N log² N) instead of O(N²); below it the exact kernel as everywhere else.
  std::vector<double> fft_sums;
  if (options.grid.kind == TauGrid::Kind::All && est == Estimator::Overlapping && ms.back() >= kAllExactBelow &&
      points >= kAllFftMinPoints) {
    detail::ScopedTimer t("allan: all-τ FFT sums");
    std::vector<double> phase(points);
    if (x.exact()) {
      const auto c0 = static_cast<std::uint64_t>(x.count(0));
      for (std::size_t k = 0; k < points; ++k)
        phase[k] = static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(x.count(k)) - c0));
    } else {
      phase = x.values;
    }
    fft_sums = detail::all_oavar_sumsq_fft(std::move(phase), ms.back(), threads);
    result.fft_from_m = kAllExactBelow;
  }
  const double q = x.arcsec_per_count;

  // Overlapping sums of every τ of a grid in one sweep over the data per thread (the threads take
  // every threads-th τ), when the counts allow the sweep kernel; exact, so the same bits as per τ.
  std::vector<detail::u128> swept;
  if (x.exact() && est == Estimator::Overlapping && options.grid.kind != TauGrid::Kind::All) {
    detail::ScopedTimer t("allan: swept variance sums");
    swept.resize(ms.size());
    bool ok = false;
    if (options.crew) {
      ok = detail::second_diff_sumsq_sweep_shared(prepared, points, ms.data(), ms.size(), *options.crew, swept.data());
    } else if (threads > 1) {
      std::vector<char> oks(threads, 0);
      {
        std::vector<Thread> pool;
        for (unsigned k = 1; k < threads; ++k)
          pool.emplace_back([&, k] {
            oks[k] = detail::second_diff_sumsq_sweep(prepared, points, ms.data(), ms.size(), k, threads, swept.data());
          });
        oks[0] = detail::second_diff_sumsq_sweep(prepared, points, ms.data(), ms.size(), 0, threads, swept.data());
      }
      ok = std::all_of(oks.begin(), oks.end(), [](char v) { return v != 0; });
    } else {
      ok = detail::second_diff_sumsq_sweep(prepared, points, ms.data(), ms.size(), 0, 1, swept.data());
    }
    if (!ok) swept.clear();
  }

  // The first two lag-1 levels of the noise identification at every small m, in one pass over the
  // int32 view shared by all of them (the per-τ passes each streamed the whole view).
  std::vector<double> lag1_start;
  if (options.noise_id && prepared.view) {
    detail::ScopedTimer t("allan: noise id start pass");
    lag1_start = detail::lag1_start_pass(x, ms.data(), ms.size(), options.noise_id_domain, prepared.view,
                                         prepared.small24, threads, options.crew);
  }

  const bool timing = detail::timing_enabled();
  std::atomic<std::int64_t> ns_sums{0}, ns_noise{0};
  auto work = [&](std::size_t i) {
    AllanPoint& p = result.points[i];
    p.m = ms[i];
    p.tau_s = static_cast<double>(p.m) * x.tau0_s;
    const std::int64_t t0 = timing ? detail::cpu_ns(true) : 0;
    // (analyze's fitted octave points stay exact on the `all` grid too.)
    const bool octave_kept = options.grid.with_octave && (p.m & (p.m - 1)) == 0;
    if (!fft_sums.empty() && p.m >= kAllExactBelow && !octave_kept) {
      p.n = term_count(est, p.m, points);
      const double scale = x.exact() ? q * q : 1.0;
      p.var = p.n > 0 ? fft_sums[static_cast<std::size_t>(p.m)] * scale /
                            (2.0 * p.tau_s * p.tau_s * static_cast<double>(p.n))
                      : 0.0;
    } else if (!swept.empty()) {
      p.n = term_count(est, p.m, points);
      p.var = p.n > 0 ? finish_counts(swept[i], q, p.tau_s, static_cast<double>(p.n)) : 0.0;
    } else {
      p.var = variance_at(x, p.m, est, x.exact() ? &prepared : nullptr, &p.n);
    }
    p.dev = std::sqrt(p.var);
    const std::int64_t t1 = timing ? detail::cpu_ns(true) : 0;
    p.alpha = options.noise_id ? detail::identify_noise(x, p.m, est, options.noise_id_domain,
                                                        prepared.view,
                                                        prepared.small24,
                                                        !lag1_start.empty() && !std::isnan(lag1_start[2 * i])
                                                            ? &lag1_start[2 * i]
                                                            : nullptr)
                               : options.alpha;
    if (timing) {
      const std::int64_t t2 = detail::cpu_ns(true);
      ns_sums += t1 - t0;
      ns_noise += t2 - t1;
    }
  };
  struct Report {
    const bool& on;
    std::atomic<std::int64_t>& sums;
    std::atomic<std::int64_t>& noise;
    std::size_t taus;
    ~Report() {
      if (on)
        std::fprintf(stderr, "timing: allan: %zu variance sums %8.2f ms cpu; noise id %8.2f ms cpu\n", taus,
                     static_cast<double>(sums.load()) * 1e-6, static_cast<double>(noise.load()) * 1e-6);
    }
  } report{timing, ns_sums, ns_noise, ms.size()};
  // EDF and bounds once every α is known: Stable32 does not identify the noise at the longest τ of
  // a run (too few points) but carries the previous τ's α over.
  auto finish = [&](AllanPoint& p) {
    p.edf = edf_for(est, p.alpha, p.m, points);
    const DevInterval ci = chi2_interval(p.var, p.edf, options.confidence);
    p.dev_low = ci.low;
    p.dev_high = ci.high;
  };
  if (threads <= 1) {
    for (std::size_t i = 0; i < ms.size(); ++i) work(i);
    if (options.noise_id && result.points.size() > 1)
      result.points.back().alpha = result.points[result.points.size() - 2].alpha;
    for (AllanPoint& p : result.points) finish(p);
    return result;
  }
  // Indices handed out dynamically, in chunks so that grids of a million τ (`all`) do not contend
  // on the counter; the result does not depend on which thread did what.
  auto parallel = [&](auto&& fn) {
    const std::size_t count = ms.size();
    const std::size_t chunk = std::clamp<std::size_t>(count / (64 * threads), 1, 256);
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    std::atomic<bool> failed{false};
    auto loop = [&] {
      for (std::size_t i0; (i0 = next.fetch_add(chunk)) < count;) {
        if (failed.load()) return;
        try {
          for (std::size_t i = i0; i < std::min(count, i0 + chunk); ++i) fn(i);
        } catch (...) {
          if (!failed.exchange(true)) failure = std::current_exception();
          return;
        }
      }
    };
    std::vector<Thread> pool;
    pool.reserve(threads - 1);
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(loop);
    loop();
    pool.clear();  // joins
    if (failure) std::rethrow_exception(failure);
  };
  // Largest m first would not help: cost per τ is ~N for every m.
  parallel(work);
  if (options.noise_id && result.points.size() > 1)
    result.points.back().alpha = result.points[result.points.size() - 2].alpha;
  parallel([&](std::size_t i) { finish(result.points[i]); });
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
  }
  return "?";
}

std::string_view long_name(Estimator e) {
  switch (e) {
    case Estimator::Overlapping: return "overlapping Allan";
    case Estimator::NonOverlapping: return "non-overlapping Allan";
    case Estimator::Modified: return "modified Allan";
  }
  return "?";
}

Estimator parse_estimator(std::string_view s) {
  if (s == "oadev" || s == "overlapping") return Estimator::Overlapping;
  if (s == "adev" || s == "nonoverlapping" || s == "non-overlapping") return Estimator::NonOverlapping;
  if (s == "mdev" || s == "modified") return Estimator::Modified;
  throw UsageError(fmt::format("unknown estimator '{}' (expected oadev, adev or mdev)", s));
}

}  // namespace rwcalc
