// The bias-step detector: the largest likelihood ratio of one change of the mean of the 10-s
// block rates, the time refined on 1-s blocks, the size from the mean rates on each side.
#include <cmath>
#include <limits>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

StepEstimate step_detect(const Decimated& d) {
  StepEstimate e;
  const std::size_t pb = per_block_for(d, 10.0);
  const std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 40) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double sig = std::max(diff_sigma(y), 1e-12);
  std::vector<double> cs(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) cs[i + 1] = cs[i] + y[i];
  // Likelihood ratio of one change of the mean at block k (white noise σ̂): n/(k(n−k))·(S_k − k·ȳ)²/σ̂².
  double best = 0;
  std::size_t ibest = n / 2;
  const double ybar = cs[n] / static_cast<double>(n);
  for (std::size_t k = 3; k + 3 <= n; ++k) {
    const double dk = static_cast<double>(k), dn = static_cast<double>(n);
    const double u = cs[k] - dk * ybar;
    const double lr = dn / (dk * (dn - dk)) * u * u / (sig * sig);
    if (lr > best) {
      best = lr;
      ibest = k;
    }
  }
  const std::size_t wbest = std::min<std::size_t>({ibest, n - ibest, 180});
  e.statistic = best;
  // Refine the time on 1-s block means: the split minimising the two-level RSS in the window.
  const std::size_t pb1 = per_block_for(d, 1.0);
  const std::vector<double> y1 = block_rates(d, pb1);
  const double t1 = static_cast<double>(pb1) * d.tau_d;
  const std::size_t n1 = y1.size();
  std::vector<double> c1(n1 + 1, 0.0), c2(n1 + 1, 0.0);
  for (std::size_t i = 0; i < n1; ++i) {
    c1[i + 1] = c1[i] + y1[i];
    c2[i + 1] = c2[i] + y1[i] * y1[i];
  }
  const auto center = static_cast<std::size_t>(static_cast<double>(ibest) * tb / t1);
  const std::size_t W = std::max<std::size_t>(10, static_cast<std::size_t>(static_cast<double>(wbest) * tb / t1));
  const std::size_t search = static_cast<std::size_t>(2.0 * tb / t1) + 2;
  double rss_best = std::numeric_limits<double>::infinity();
  std::size_t split = center;
  auto seg_rss = [&](std::size_t a, std::size_t b) {
    const double s = c1[b] - c1[a], s2 = c2[b] - c2[a];
    return s2 - s * s / double(b - a);
  };
  std::vector<std::pair<std::size_t, double>> profile;
  for (std::size_t s = center > search ? center - search : 1; s <= std::min(n1 - 1, center + search); ++s) {
    const std::size_t a = s > W ? s - W : 0, b = std::min(n1, s + W);
    if (s - a < 2 || b - s < 2) continue;
    const double r = seg_rss(a, s) + seg_rss(s, b);
    profile.emplace_back(s, r);
    if (r < rss_best) {
      rss_best = r;
      split = s;
    }
  }
  const double ts = static_cast<double>(split) * t1;
  e.t_s = ts;
  // Size: the difference of the means over up to 30 min on each side.
  const auto Ws = static_cast<std::size_t>(std::min<double>(1800.0 / t1, static_cast<double>(n1)));
  const std::size_t a = split > Ws ? split - Ws : 0, b = std::min(n1, split + Ws);
  const double m1 = (c1[split] - c1[a]) / double(split - a), m2 = (c1[b] - c1[split]) / double(b - split);
  e.size = m2 - m1;
  const double sig1 = diff_sigma(y1);
  e.size_sigma = sig * std::sqrt(tb / (double(split - a) * t1) + tb / (double(b - split) * t1));
  // Time uncertainty: the range of splits whose RSS is within σ₁² (Δχ² = 1) of the best.
  double lo = ts, hi = ts;
  for (const auto& [s, r] : profile)
    if (r - rss_best <= sig1 * sig1) {
      lo = std::min(lo, static_cast<double>(s) * t1);
      hi = std::max(hi, static_cast<double>(s) * t1);
    }
  e.t_sigma = std::max(0.5 * (hi - lo), t1);
  // RSS of level + trend + step on the 10-s block means (for the comparison with a warm-up).
  std::vector<double> stepcol(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t0 = static_cast<double>(i) * tb, t2 = t0 + tb;
    stepcol[i] = std::clamp((t2 - ts) / tb, 0.0, 1.0);
  }
  e.rss = ls_rss(y, {stepcol});
  return e;
}

namespace {

/// A bias step at a known time: its size from the mean rates over up to 30 min each side.
StepEstimate step_at(const Decimated& d, double ts) {
  StepEstimate e;
  e.t_s = ts;
  const double T = d.duration();
  const double wa = std::min(1800.0, ts), wb = std::min(1800.0, T - ts);
  if (!(wa > d.tau_d) || !(wb > d.tau_d)) return e;
  auto theta_at = [&](double t) {  // linear interpolation of the decimated angle
    const double u = std::clamp(t / d.tau_d, 0.0, static_cast<double>(d.theta.size() - 1));
    const auto i = std::min(static_cast<std::size_t>(u), d.theta.size() - 2);
    const double f = u - static_cast<double>(i);
    return d.theta[i] + f * (d.theta[i + 1] - d.theta[i]);
  };
  const double th = theta_at(ts);
  e.size = (theta_at(ts + wb) - th) / wb - (th - theta_at(ts - wa)) / wa;
  const double sig1 = diff_sigma(block_rates(d, per_block_for(d, 1.0)));
  e.size_sigma = sig1 * std::sqrt(1.0 / wa + 1.0 / wb);
  return e;
}

class StepDetector final : public RecordDetector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::BiasStep; }
  [[nodiscard]] bool mean_shape() const override { return true; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    return r.step ? r.step->statistic : step_detect(r.dec).statistic;
  }
  /// A block shows a step whose time, known from the whole record, lies inside it with data on
  /// both sides: its size is estimable there even where the block's own time search fails.
  [[nodiscard]] bool block_statistic() const override { return false; }
  [[nodiscard]] bool shows_in(const Trial& t) const override { return t.stretch.step_time_s >= 0; }
  void estimate(const Stretch& s, Extension& x) const override {
    const auto est = s.step_time_s >= 0 ? step_at(s.dec, s.step_time_s) : step_detect(s.dec);
    x.det.bias_steps.push_back({est.t_s, est.size});
    x.findings.push_back({Effect::BiasStep,
                          {{"time_s", est.t_s}, {"size_deg_per_h", est.size}},
                          {{"time_s", est.t_sigma}, {"size_deg_per_h", est.size_sigma}},
                          {}});
  }
};

}  // namespace

std::unique_ptr<RecordDetector> step_detector() { return std::make_unique<StepDetector>(); }

}  // namespace rwcalc::diag
