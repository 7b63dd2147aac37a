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

std::vector<RunStats> run_ensemble(const NoiseModel& model, const SimulationSettings& settings, std::size_t runs,
                                   const EnsemblePlan& plan, Progress* progress) {
  std::vector<RunStats> out(runs);
  EnsembleOptions eo;
  eo.path = SimulationPath::Ensemble;
  eo.progress = progress;
  const bool clean = plan.clean_mid || !plan.scored.empty();
  simulate_ensemble(
      model, settings, runs,
      [&](std::size_t r, const PhaseSeries& s) {
        RunStats& st = out[r];
        st.octave_var = octave_avar(s, plan.octave_m);
        st.mean_rate = s.diff(s.points() - 1, 0) / s.duration_s();
        const Decimated d = decimate(s);
        st.mid_var = decimated_avar(d, plan.grid);
        if (!clean) return;
        const Decimated dc = without_own_candidates(d);
        st.mid_var_clean = decimated_avar(dc, plan.grid);
        const RecordView view{s, d, dc, st.octave_var};
        for (const RecordDetector* det : plan.scored)
          st.stat[static_cast<std::size_t>(det->effect())] = det->statistic(view);
      },
      eo);
  return out;
}

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
