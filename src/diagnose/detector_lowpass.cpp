// The output-chain low-pass detector: the χ² drop of the short-τ octave AV when white angle and
// rate noise (and a floor) pass through a first-order filter. Pulse counts cannot have.
#include <boost/math/distributions/chi_squared.hpp>

#include <array>
#include <cmath>
#include <limits>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

namespace {

/// Non-negative weighted least squares of y on up to three columns (all subsets; small p).
struct NnFit {
  double chi2 = std::numeric_limits<double>::infinity();
  std::array<double, 3> c{0, 0, 0};
};

NnFit nn_fit3(const std::vector<double>& y, const std::vector<double>& w,
              const std::array<std::vector<double>, 3>& cols) {
  NnFit best;
  for (int mask = 1; mask < 8; ++mask) {
    std::vector<std::vector<double>> cs;
    std::vector<int> idx;
    for (int c = 0; c < 3; ++c)
      if (mask & (1 << c)) {
        cs.push_back(cols[static_cast<std::size_t>(c)]);
        idx.push_back(c);
      }
    const WlsOut o = wls(y, w, cs);
    bool ok = true;
    for (Eigen::Index k = 0; k < o.coef.size(); ++k) ok = ok && o.coef(k) >= 0 && std::isfinite(o.coef(k));
    if (!ok || !(o.chi2 < best.chi2)) continue;
    best.chi2 = o.chi2;
    best.c = {0, 0, 0};
    for (std::size_t k = 0; k < idx.size(); ++k)
      best.c[static_cast<std::size_t>(idx[k])] = o.coef(static_cast<Eigen::Index>(k));
  }
  if (!std::isfinite(best.chi2)) {
    best.chi2 = 0;
    for (std::size_t i = 0; i < y.size(); ++i) best.chi2 += w[i] * y[i] * y[i];
  }
  return best;
}

class LowpassDetector final : public RecordDetector {
 public:
  LowpassDetector(const AnalysisResult& a, double duration_s, std::string skip)
      : tau0_(a.allan.tau0_s), duration_(duration_s), skip_(std::move(skip)) {
    for (const auto& p : a.allan.points) {
      m_.push_back(p.m);
      edf_.push_back(p.edf);
    }
  }
  [[nodiscard]] Effect effect() const override { return Effect::Lowpass; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    return skip_.empty() ? fit(r.octave_var).statistic : 0.0;
  }
  /// The base records have no filter and often a statistic of 0: the threshold is at least the
  /// χ²(1) (1 − α) quantile, scaled by the best fit's χ² per degree of freedom.
  [[nodiscard]] DetectorResult test(const Trial& t) const override {
    DetectorResult d;
    d.effect = Effect::Lowpass;
    if (!skip_.empty()) {
      d.note = skip_;
      return d;
    }
    const double alpha = t.stretch.opt->alpha;
    const auto lp = fit(t.data.octave_var);
    d = calibrate(lp.statistic, t.runs, alpha);
    const double dof = std::max(1.0, lp.points - 4.0);
    const double floor =
        boost::math::quantile(boost::math::chi_squared(1.0), 1.0 - alpha) * std::max(1.0, lp.chi2 / dof);
    if (d.threshold < floor) {
      d.threshold = floor;
      d.note.clear();
      set_verdict(d, floor);
    }
    return d;
  }
  [[nodiscard]] bool block_statistic() const override { return false; }
  [[nodiscard]] bool shows_in(const Trial&) const override { return true; }
  /// The filter and the white angle noise before it from the short-τ octave AV; N, B, K stay.
  void estimate(const Stretch& s, Extension& x) const override {
    std::vector<double> v;
    for (const auto& p : s.analysis->allan.points) v.push_back(p.var);
    const auto est = LowpassDetector(*s.analysis, s.rec->phase.duration_s(), "").fit(v);
    x.findings.push_back(
        {Effect::Lowpass, {{"time_constant_s", est.tf}}, {{"time_constant_s", 0.5 * (est.tf_high - est.tf_low)}}, {}});
    x.lowpass = est;
  }

 private:
  [[nodiscard]] OutputLowpassEstimate fit(const std::vector<double>& octave_var) const {
    return output_lowpass_detect(m_, octave_var, edf_, tau0_, duration_);
  }
  double tau0_, duration_;
  std::string skip_;
  std::vector<std::int64_t> m_;
  std::vector<double> edf_;
};

}  // namespace

OutputLowpassEstimate output_lowpass_detect(const std::vector<std::int64_t>& m, const std::vector<double>& v,
                                            const std::vector<double>& edf, double tau0, double duration) {
  OutputLowpassEstimate e;
  const double tau_cut = std::min(20.0, duration / 100.0);
  std::vector<std::size_t> mm;
  std::vector<double> y, w;
  for (std::size_t i = 0; i < m.size() && i < v.size() && i < edf.size(); ++i) {
    const double tau = static_cast<double>(m[i]) * tau0;
    if (tau > tau_cut || !(v[i] > 0) || !(edf[i] > 0)) continue;
    mm.push_back(static_cast<std::size_t>(m[i]));
    y.push_back(v[i]);
    w.push_back(edf[i] / (2.0 * v[i] * v[i]));
  }
  e.points = static_cast<double>(y.size());
  if (y.size() < 5) return e;
  // Columns scaled to unit maximum for the conditioning of the normal equations.
  auto fit_at = [&](double tf, std::array<double, 2>* scale) {
    std::array<std::vector<double>, 3> cols;
    for (auto& c : cols) c.resize(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) {
      cols[0][i] = output_lowpass_angle_avar(mm[i], tau0, tf);
      cols[1][i] = output_lowpass_rate_avar(mm[i], tau0, tf);
      cols[2][i] = 1.0;
    }
    std::array<double, 3> sc{1, 1, 1};
    for (std::size_t c = 0; c < 2; ++c) {
      sc[c] = *std::max_element(cols[c].begin(), cols[c].end());
      for (double& x : cols[c]) x /= sc[c];
    }
    NnFit f = nn_fit3(y, w, cols);
    if (scale) *scale = {f.c[0] / sc[0], f.c[1] / sc[1]};
    return f.chi2;
  };
  const double chi0 = fit_at(0.0, nullptr);
  const double lo = std::log(tau0 / 4.0), hi = std::log(std::max(tau_cut / 4.0, tau0));
  const int G = 80;
  std::vector<std::pair<double, double>> prof;
  double best = chi0;
  // χ² at tf; the best so far (tf and the white scales of its fit) kept in e.
  const auto consider = [&](double tf) {
    std::array<double, 2> sc{0, 0};
    const double c = fit_at(tf, &sc);
    if (c < best) {
      best = c;
      e.tf = tf;
      e.white_angle2 = sc[0];
      e.white_rate = sc[1];
    }
    return c;
  };
  for (int g = 0; g <= G; ++g) {
    const double tf = std::exp(lo + (hi - lo) * g / G);
    prof.emplace_back(tf, consider(tf));
  }
  e.statistic = std::max(0.0, chi0 - best);
  if (!(e.tf > 0)) return e;
  // Golden-section refinement of tf in log between the grid neighbours.
  {
    double a = std::log(e.tf) - (hi - lo) / G, b = std::log(e.tf) + (hi - lo) / G;
    const double gr = (std::sqrt(5.0) - 1.0) / 2.0;
    double c1 = b - gr * (b - a), c2 = a + gr * (b - a);
    double f1 = fit_at(std::exp(c1), nullptr), f2 = fit_at(std::exp(c2), nullptr);
    for (int it = 0; it < 30; ++it) {
      if (f1 < f2) {
        b = c2;
        c2 = c1;
        f2 = f1;
        c1 = b - gr * (b - a);
        f1 = fit_at(std::exp(c1), nullptr);
      } else {
        a = c1;
        c1 = c2;
        f1 = f2;
        c2 = a + gr * (b - a);
        f2 = fit_at(std::exp(c2), nullptr);
      }
    }
    consider(std::exp(0.5 * (a + b)));
    e.statistic = std::max(0.0, chi0 - best);
  }
  e.chi2 = best;
  // Δχ² range, widened by the misfit per degree of freedom.
  const double dof = std::max(1.0, e.points - 4.0);
  const double delta = std::max(1.0, best / dof);
  e.tf_low = e.tf_high = e.tf;
  // Curvature of χ² in ln tf at the optimum (steps of 2 %), else the grid profile.
  const double h = 0.02;
  const double fp = fit_at(e.tf * std::exp(h), nullptr), fm = fit_at(e.tf * std::exp(-h), nullptr);
  const double curv = (fp - 2.0 * best + fm) / (h * h);
  if (curv > 0) {
    const double su = std::sqrt(2.0 * delta / curv);
    e.tf_low = e.tf * std::exp(-su);
    e.tf_high = e.tf * std::exp(su);
  } else {
    for (const auto& [tf, c] : prof)
      if (c - best <= delta) {
        e.tf_low = std::min(e.tf_low, tf);
        e.tf_high = std::max(e.tf_high, tf);
      }
  }
  return e;
}

std::unique_ptr<RecordDetector> lowpass_detector(const AnalysisResult& analysis, double duration_s, std::string skip) {
  return std::make_unique<LowpassDetector>(analysis, duration_s, std::move(skip));
}

}  // namespace rwcalc::diag
