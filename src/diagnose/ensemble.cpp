// The simulated ensemble of a model: per-record statistics, band, mid-τ reference, deviance.
#include "diagnose/ensemble.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include "allan/allan_kernels.hpp"
#include "diagnose/detector.hpp"
#include "rwcalc/allan.hpp"
#include "rwcalc/ensemble.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/noise_model.hpp"

namespace rwcalc::diag {

namespace {

/// Overlapping AV of a simulated record at the octave cluster sizes; pulse counts by exact integer
/// sums, every cluster size in one sweep.
std::vector<double> octave_avar(const PhaseSeries& s, const std::vector<std::int64_t>& octave_m) {
  std::vector<double> v(octave_m.size(), 0.0);
  if (!s.exact()) {
    for (std::size_t i = 0; i < octave_m.size(); ++i) v[i] = allan_variance(s, octave_m[i], Estimator::Overlapping);
    return v;
  }
  const std::vector<detail::u128> swept = detail::second_diff_sumsq_sweep(s.counts.data(), s.points(), octave_m);
  const double q = s.arcsec_per_count;
  for (std::size_t i = 0; i < octave_m.size(); ++i) {
    const std::int64_t m = octave_m[i];
    const std::int64_t n = term_count(Estimator::Overlapping, m, s.points());
    if (n < 1) continue;
    const double tau = static_cast<double>(m) * s.tau0_s;
    v[i] = static_cast<double>(swept[i]) * q * q / (2.0 * tau * tau * static_cast<double>(n));
  }
  return v;
}

/// A band point's weight: its EDF with the ensemble's sampling error and a 1000-EDF model floor.
double band_nu(double edf, std::size_t runs) {
  const double K = static_cast<double>(std::max<std::size_t>(runs, 1));
  return 1.0 / (1.0 / edf + 1.0 / (K * edf) + 1.0 / 1000.0);
}

bool band_point_valid(const BandPoint& b) { return b.mean_var > 0 && b.dev > 0 && b.edf > 0; }

}  // namespace

namespace {

/// Full-rate samples of the short pieces that give the octave AV below the decimated step.
constexpr std::size_t kPieceSamples = 4096;

/// The plan's reductions of one simulated record: its octave AV `v` (already set), mean rate,
/// mid-τ AV and scored statistics, from `s` (full rate, or the decimated step itself).
/// Records from plan.stats_from on are reduced to the scored statistics.
void reduce(const PhaseSeries& s, const EnsemblePlan& plan, std::size_t r, RunStats& st) {
  st.mean_rate = s.diff(s.points() - 1, 0) / s.duration_s();
  const bool mid = r < plan.stats_from;
  const Decimated d = decimate(s);
  if (plan.raw_mid && mid) st.mid_var = decimated_avar(d, plan.grid);
  if (!plan.clean_mid && plan.scored.empty()) return;
  // The record's own candidate from its step and warm-up fits, which are also their statistics.
  const StepEstimate step = step_detect(d);
  const WarmupEstimate warm = warmup_detect(d);
  Decimated dc = d;
  subtract_deterministic(dc, own_candidates(step, warm));
  if (plan.clean_mid && mid) st.mid_var_clean = decimated_avar(dc, plan.grid);
  const RecordView view{s, d, dc, st.octave_var, &step, &warm};
  for (const RecordDetector* det : plan.scored) st.stat[static_cast<std::size_t>(det->effect())] = det->statistic(view);
}

/// Every record at full rate: a statistic that reads the raw samples needs it.
std::vector<RunStats> full_rate_ensemble(const NoiseModel& model, const SimulationSettings& settings,
                                         std::size_t runs, const EnsemblePlan& plan, Progress* progress) {
  std::vector<RunStats> out(runs);
  simulate_ensemble(
      model, settings, runs,
      [&](std::size_t r, const PhaseSeries& s) {
        out[r].octave_var = octave_avar(s, plan.octave_m);
        reduce(s, plan, r, out[r]);
      },
      {SimulationPath::Ensemble, progress});
  return out;
}

/// Whether the nulls can be simulated at the decimated step D·τ0: no output-chain low-pass, and
/// every octave cluster size a multiple of D or short enough for the pieces.
bool decimated_nulls(const NoiseModel& model, const EnsemblePlan& plan, std::size_t D) {
  // An output-chain low-pass filters the white angle noise up to a few τf, past the decimated step.
  if (D < 2 || model.output_lowpass_tc_s > 0) return false;
  return std::all_of(plan.octave_m.begin(), plan.octave_m.end(), [D](std::int64_t m) {
    return m % static_cast<std::int64_t>(D) == 0 || m <= static_cast<std::int64_t>(kPieceSamples / 16);
  });
}

/// The octave AV below the decimated step, per record: the mean over the records of short
/// full-rate pieces (exact read-out and all), each record's deviation from it shrunk to the full
/// length (an overlapping AV's variance falls as 1/terms at τ ≪ T).
void short_tau_octaves(const NoiseModel& model, const SimulationSettings& settings, const std::vector<std::int64_t>& m,
                       const std::vector<std::size_t>& at, std::vector<RunStats>& out) {
  if (at.empty()) return;
  SimulationSettings ps = settings;
  ps.duration_s = std::min(settings.duration_s, static_cast<double>(kPieceSamples) / settings.rate_hz);
  ps.seed = ensemble_seed(settings.seed, 0x7069656365ULL);  // streams apart from the records'
  std::vector<std::int64_t> ms;
  for (const std::size_t i : at) ms.push_back(m[i]);
  std::vector<std::vector<double>> piece(out.size());
  std::size_t piece_points = 0;
  simulate_ensemble(
      model, ps, out.size(),
      [&](std::size_t r, const PhaseSeries& s) {
        piece[r] = octave_avar(s, ms);
        if (r == 0) piece_points = s.points();
      },
      {SimulationPath::Exact, nullptr});
  const std::size_t full_points = settings.samples() + 1;
  for (std::size_t k = 0; k < at.size(); ++k) {
    double mean = 0;
    for (const auto& p : piece) mean += p[k];
    mean /= static_cast<double>(out.size());
    const double n_piece = static_cast<double>(term_count(Estimator::Overlapping, ms[k], piece_points));
    const double n_full = static_cast<double>(term_count(Estimator::Overlapping, ms[k], full_points));
    const double shrink = n_piece > 0 && n_full > 0 ? std::sqrt(n_piece / n_full) : 0.0;
    for (std::size_t r = 0; r < out.size(); ++r)
      out[r].octave_var[at[k]] = std::max(mean + (piece[r][k] - mean) * shrink, 1e-3 * mean);
  }
}

std::vector<RunStats> decimated_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                         const EnsemblePlan& plan, std::size_t D, Progress* progress);

}  // namespace

std::vector<RunStats> run_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                   const EnsemblePlan& plan, Progress* progress) {
  const std::size_t D = decimation(settings.rate_hz);
  if (!decimated_nulls(model, plan, D)) return full_rate_ensemble(model, settings, runs, plan, progress);
  // A statistic that reads the raw samples gets its own full-rate records (the band's K at most,
  // other seeds); the records beyond have no value for it (NaN, left out of its calibration).
  EnsemblePlan rest = plan;
  std::vector<const RecordDetector*> raw;
  rest.scored.clear();
  for (const RecordDetector* d : plan.scored) (d->full_rate() ? raw : rest.scored).push_back(d);
  auto out = decimated_ensemble(model, settings, runs, rest, D, progress);
  if (raw.empty()) return out;
  SimulationSettings fs = settings;
  fs.seed = ensemble_seed(settings.seed, 0x726177ULL);
  const EnsemblePlan raw_plan{{}, {}, false, raw, false};
  const auto full = full_rate_ensemble(model, fs, std::min(runs, plan.stats_from), raw_plan, nullptr);
  for (std::size_t r = 0; r < runs; ++r)
    for (const RecordDetector* d : raw)
      out[r].stat[static_cast<std::size_t>(d->effect())] =
          r < full.size() ? full[r].stat[static_cast<std::size_t>(d->effect())] : std::numeric_limits<double>::quiet_NaN();
  return out;
}

namespace {

std::vector<RunStats> decimated_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                         const EnsemblePlan& plan, std::size_t D, Progress* progress) {
  // The detectors read the angle at D·τ0 only. The simulator's discrete model at that step gives
  // exactly that angle (every term is simulated as an exact step, the read-out quantizes the
  // angle at each sample, white angle noise is per sample).
  SimulationSettings cs = settings;
  cs.rate_hz = settings.rate_hz / static_cast<double>(D);
  std::vector<std::int64_t> coarse_m;
  std::vector<std::size_t> coarse_at, short_at;
  for (std::size_t i = 0; i < plan.octave_m.size(); ++i) {
    if (plan.octave_m[i] % static_cast<std::int64_t>(D) == 0) {
      coarse_m.push_back(plan.octave_m[i] / static_cast<std::int64_t>(D));
      coarse_at.push_back(i);
    } else {
      short_at.push_back(i);
    }
  }
  std::vector<RunStats> out(runs);
  simulate_ensemble(
      model, cs, runs,
      [&](std::size_t r, const PhaseSeries& s) {
        RunStats& st = out[r];
        st.octave_var.assign(plan.octave_m.size(), 0.0);
        const std::vector<double> v = octave_avar(s, coarse_m);
        for (std::size_t k = 0; k < coarse_at.size(); ++k) st.octave_var[coarse_at[k]] = v[k];
        reduce(s, plan, r, st);
      },
      {SimulationPath::Exact, progress});
  short_tau_octaves(model, settings, plan.octave_m, short_at, out);
  return out;
}

}  // namespace

std::vector<BandPoint> make_band(const std::vector<AllanPoint>& measured, const std::vector<RunStats>& runs,
                                 double level) {
  std::vector<BandPoint> band;
  for (std::size_t i = 0; i < measured.size(); ++i) {
    std::vector<double> dev;
    double mean = 0;
    for (const auto& r : runs) {
      if (i >= r.octave_var.size() || !(r.octave_var[i] > 0)) continue;
      dev.push_back(std::sqrt(r.octave_var[i]));
      mean += r.octave_var[i];
    }
    if (dev.size() < 3 || !(measured[i].dev > 0)) continue;
    BandPoint b;
    b.tau_s = measured[i].tau_s;
    b.dev = measured[i].dev;
    b.edf = measured[i].edf;
    b.low = quantile(dev, 0.5 - level / 2);
    b.high = quantile(dev, 0.5 + level / 2);
    b.median = quantile(dev, 0.5);
    b.mean_var = mean / static_cast<double>(dev.size());
    band.push_back(b);
  }
  return band;
}

MidTauReference make_reference(const std::vector<std::size_t>& grid, double tau_d, const std::vector<RunStats>& runs,
                               bool clean) {
  const auto var_of = [clean](const RunStats& r) -> const std::vector<double>& {
    return clean ? r.mid_var_clean : r.mid_var;
  };
  MidTauReference ref;
  ref.grid = grid;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    double m = 0, m2 = 0;
    std::size_t k = 0;
    for (const auto& r : runs) {
      if (i >= var_of(r).size() || !(var_of(r)[i] > 0)) continue;
      m += var_of(r)[i];
      m2 += var_of(r)[i] * var_of(r)[i];
      ++k;
    }
    ref.tau.push_back(static_cast<double>(grid[i]) * tau_d);
    const double mean = k < 3 ? 0.0 : m / double(k);  // fewer than 3 runs: no reference
    ref.mean.push_back(mean);
    ref.var.push_back(k < 3 ? 0.0 : std::max((m2 - double(k) * mean * mean) / double(k - 1), 0.0));
  }
  const std::size_t g = grid.size();
  if (runs.size() >= 5) {
    ref.cov.assign(g * g, 0.0);
    for (std::size_t i = 0; i < g; ++i) {
      for (std::size_t j = i; j < g; ++j) {
        double c = 0;
        std::size_t k = 0;
        for (const auto& r : runs) {
          if (i >= var_of(r).size() || j >= var_of(r).size() || !(var_of(r)[i] > 0) || !(var_of(r)[j] > 0)) continue;
          c += (var_of(r)[i] - ref.mean[i]) * (var_of(r)[j] - ref.mean[j]);
          ++k;
        }
        ref.cov[i * g + j] = ref.cov[j * g + i] = k > 2 ? c / double(k - 1) : 0.0;
      }
    }
  }
  return ref;
}

std::array<double, 3> band_refit(const std::vector<BandPoint>& band, std::size_t runs, const std::array<double, 3>& c,
                                 const std::array<bool, 3>& held_free) {
  constexpr std::array<Term, 3> terms{Term::N, Term::B, Term::K};
  struct Point {
    double d, mu, nu;
    std::array<double, 3> g;
  };
  std::vector<Point> pts;
  for (const auto& b : band) {
    if (!band_point_valid(b)) continue;
    Point p{b.dev * b.dev, b.mean_var, band_nu(b.edf, runs), {}};
    for (std::size_t j = 0; j < 3; ++j) p.g[j] = term_basis(terms[j], b.tau_s);
    pts.push_back(p);
  }
  std::array<double, 3> x{0, 0, 0};
  if (pts.size() < 4) return x;
  auto deviance = [&](const std::array<double, 3>& y) {
    double s = 0;
    for (const auto& p : pts) {
      double m = p.mu;
      for (std::size_t j = 0; j < 3; ++j) m += p.g[j] * y[j];
      if (!(m > 0)) return std::numeric_limits<double>::infinity();
      const double r = p.d / m;
      s += p.nu * (r - 1.0 - std::log(r));
    }
    return s;
  };
  const double d0 = deviance(x);
  double dx = d0;
  for (int it = 0; it < 40; ++it) {
    // Fisher scoring: weights ν/m², residuals d − m; a term at its bound c + Δc = 0 stays there
    // while the deviance's slope pushes it down.
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const auto& p : pts) {
      double m = p.mu;
      for (std::size_t j = 0; j < 3; ++j) m += p.g[j] * x[j];
      const double w = p.nu / (m * m);
      const Eigen::Vector3d g(p.g[0], p.g[1], p.g[2]);
      A += w * g * g.transpose();
      rhs += w * (p.d - m) * g;
    }
    std::vector<Eigen::Index> idx;  // the free terms
    for (std::size_t j = 0; j < 3; ++j)
      if (held_free[j] && (c[j] + x[j] > 1e-12 * (c[j] + 1e-30) || rhs(static_cast<Eigen::Index>(j)) > 0))
        idx.push_back(static_cast<Eigen::Index>(j));
    if (idx.empty()) break;
    const auto n = static_cast<Eigen::Index>(idx.size());
    Eigen::MatrixXd a(n, n);
    Eigen::VectorXd b(n), sc(n);
    for (Eigen::Index i = 0; i < n; ++i) sc(i) = A(idx[i], idx[i]) > 0 ? 1.0 / std::sqrt(A(idx[i], idx[i])) : 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      b(i) = rhs(idx[i]) * sc(i);
      for (Eigen::Index k = 0; k < n; ++k) a(i, k) = A(idx[i], idx[k]) * sc(i) * sc(k);
    }
    const Eigen::VectorXd sol = a.completeOrthogonalDecomposition().solve(b);
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < n; ++i) step(idx[i]) = sol(i) * sc(i);
    bool improved = false;
    for (double t = 1.0; t > 1e-4; t *= 0.5) {
      std::array<double, 3> y = x;
      for (std::size_t j = 0; j < 3; ++j) y[j] = std::max(x[j] + t * step(static_cast<Eigen::Index>(j)), -c[j]);
      const double dy = deviance(y);
      if (dy < dx) {
        improved = dx - dy > 1e-10 * (1.0 + dx);
        x = y;
        dx = dy;
        break;
      }
    }
    if (!improved) break;
  }
  if (!(dx < d0)) return {0, 0, 0};
  return x;
}

BandDeviance band_deviance(const std::vector<BandPoint>& band, std::size_t runs) {
  BandDeviance d;
  for (const auto& b : band) {
    if (!band_point_valid(b)) continue;
    const double r = b.dev * b.dev / b.mean_var;
    d.sum += band_nu(b.edf, runs) * (r - 1.0 - std::log(r));
    ++d.points;
  }
  return d;
}

}  // namespace rwcalc::diag

namespace rwcalc {

double band_misfit(const std::vector<BandPoint>& band, std::size_t runs) {
  return diag::band_deviance(band, runs).per_point();
}

double band_coverage(const std::vector<BandPoint>& band) {
  if (band.empty()) return 0.0;
  std::size_t in = 0;
  for (const auto& b : band) in += (b.dev >= b.low && b.dev <= b.high) ? 1 : 0;
  return static_cast<double>(in) / static_cast<double>(band.size());
}

}  // namespace rwcalc
