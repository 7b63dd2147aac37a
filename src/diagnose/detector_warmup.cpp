// The warm-up detector: the RSS drop of the 10-s block rates when an exponential transient joins
// level and trend; and a record's own mean-shape candidate.
#include <cmath>
#include <limits>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

WarmupEstimate warmup_detect(const Decimated& d, double tc_hint) {
  WarmupEstimate e;
  const std::size_t pb = per_block_for(d, 10.0);
  const std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 40) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double T = tb * static_cast<double>(n);
  const double sig = std::max(diff_sigma(y), 1e-12);
  const double rss0 = ls_rss(y, {});
  auto column = [&](double tc) {
    std::vector<double> c(n);
    const double f = tc / tb * -std::expm1(-tb / tc);  // block mean of exp(−t/tc) over [0, tb]
    for (std::size_t i = 0; i < n; ++i) c[i] = std::exp(-static_cast<double>(i) * tb / tc) * f;
    return c;
  };
  auto rss_at = [&](double tc) { return ls_rss(y, {column(tc)}); };
  // Up to τ = T/3: a longer exponential is nearly the trend over the record, and searched up to T
  // it took part of a Gauss–Markov wander in every record's own candidate (docs/diagnosis.md).
  const double lt_lo = std::log(2.0 * tb), lt_hi = std::log(T / 3.0);
  const int G = 40;
  double best = std::numeric_limits<double>::infinity(), lbest = lt_lo;
  for (int g = 0; g <= G; ++g) {
    const double lt = lt_lo + (lt_hi - lt_lo) * g / G;
    const double r = rss_at(std::exp(lt));
    if (r < best) {
      best = r;
      lbest = lt;
    }
  }
  const double step = (lt_hi - lt_lo) / G;
  lbest = golden_min([&](double lt) { return rss_at(std::exp(lt)); }, lbest - step, lbest + step, 25);
  if (tc_hint > 0) lbest = std::log(tc_hint);
  Eigen::VectorXd coef;
  Eigen::MatrixXd inv;
  e.tc = std::exp(lbest);
  e.rss = ls_rss(y, {column(e.tc)}, &coef, &inv);
  e.amp = coef(2);
  e.amp_sigma = sig * std::sqrt(inv(2, 2));
  // ls_rss's trend column runs over (i − (n − 1)/2)/n: its coefficient is the change over T.
  e.ramp = coef(1) / T * 3600.0;
  e.ramp_sigma = sig * std::sqrt(inv(1, 1)) / T * 3600.0;
  // F-type statistic: the residual variance, not the white level, normalises the drop, so that
  // wander the base fit took up into K or R does not hide the transient.
  e.statistic = std::max(0.0, (rss0 - e.rss) / (e.rss / static_cast<double>(n - 4)));
  // Time-constant range: Δ RSS/σ̂² ≤ 1 on a fine profile around the optimum.
  double tl = e.tc, th = e.tc;
  for (int g = -40; g <= 40; ++g) {
    const double lt = lbest + g * 0.025;
    if (lt < lt_lo - 1 || lt > lt_hi + 1) continue;
    if ((rss_at(std::exp(lt)) - e.rss) / (sig * sig) <= 1.0) {
      tl = std::min(tl, std::exp(lt));
      th = std::max(th, std::exp(lt));
    }
  }
  e.tc_sigma = std::max(0.5 * (th - tl), 0.0);
  return e;
}

NoiseModel own_candidates(const Decimated& d) { return own_candidates(step_detect(d), warmup_detect(d)); }

NoiseModel own_candidates(const StepEstimate& st, const WarmupEstimate& w) {
  NoiseModel c;
  if (st.rss <= w.rss)
    c.bias_steps.push_back({st.t_s, st.size});
  else
    c.warmups.push_back({w.amp, w.tc});
  return c;
}

Decimated without_own_candidates(const Decimated& d) {
  Decimated c = d;
  subtract_deterministic(c, own_candidates(d));
  return c;
}

namespace {

class WarmupDetector final : public RecordDetector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::Warmup; }
  [[nodiscard]] bool mean_shape() const override { return true; }
  [[nodiscard]] double statistic(const RecordView& r) const override {
    return r.warmup ? r.warmup->statistic : warmup_detect(r.dec).statistic;
  }
  void estimate(const Stretch& s, Extension& x) const override {
    const auto est = warmup_detect(s.dec, s.warmup_tc_s);
    x.det.warmups.push_back({est.amp, est.tc});
    x.ramp = est.ramp;
    x.ramp_sigma = est.ramp_sigma;
    x.findings.push_back(
        {Effect::Warmup,
         {{"amplitude_deg_per_h", est.amp}, {"time_constant_s", est.tc}, {"ramp_deg_per_h2", est.ramp}},
         {{"amplitude_deg_per_h", est.amp_sigma}, {"time_constant_s", est.tc_sigma}, {"ramp_deg_per_h2", est.ramp_sigma}},
         {}});
  }
};

}  // namespace

std::unique_ptr<RecordDetector> warmup_detector() { return std::make_unique<WarmupDetector>(); }

}  // namespace rwcalc::diag
