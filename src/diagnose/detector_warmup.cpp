// The warm-up detector: the RSS drop of the 10-s block rates when an exponential transient joins
// level and trend; and a record's own mean-shape candidate.
#include <cmath>
#include <limits>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

namespace {

/// Block means of e^{−t/τ} over the n blocks of tb from t = 0.
std::vector<double> exp_column(std::size_t n, double tb, double tc) {
  std::vector<double> c(n);
  const double f = tc / tb * -std::expm1(-tb / tc);  // block mean of exp(−t/tc) over [0, tb]
  for (std::size_t i = 0; i < n; ++i) c[i] = std::exp(-static_cast<double>(i) * tb / tc) * f;
  return c;
}

/// The log τ of least RSS on [lo, hi]: a grid of G + 1 points, then golden section around the best.
template <class F>
double best_log_tc(const F& rss_at, double lo, double hi, int G) {
  double best = std::numeric_limits<double>::infinity(), lbest = lo;
  for (int g = 0; g <= G; ++g) {
    const double lt = lo + (hi - lo) * g / G;
    if (const double r = rss_at(std::exp(lt)); r < best) {
      best = r;
      lbest = lt;
    }
  }
  const double step = (hi - lo) / G;
  return golden_min([&](double lt) { return rss_at(std::exp(lt)); }, lbest - step, lbest + step, 25);
}

/// Standard errors of the fit level + c1·(t/T − ½) + A·e^{−t/τ} at its optimum from the Jacobian
/// of all its parameters (ln τ too unless τ was given: beside a free τ, A and r are far looser
/// than at a fixed τ), and the mid-record slope c1/T − (A/τ)e^{−T/2τ} and curvature
/// (A/τ²)e^{−T/2τ} with theirs (delta method). `s` is the noise of one block mean.
void drift_uncertainty(std::size_t n, double tb, double s, bool tc_free, const Eigen::VectorXd& coef,
                       WarmupEstimate& e) {
  const double T = tb * static_cast<double>(n), A = coef(2), tc = e.tc, h = 1e-4;
  const auto p = static_cast<Eigen::Index>(tc_free ? 4 : 3);
  Eigen::MatrixXd J(static_cast<Eigen::Index>(n), p);
  const auto c = exp_column(n, tb, tc), cp = exp_column(n, tb, tc * std::exp(h)),
             cm = exp_column(n, tb, tc * std::exp(-h));
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    J(r, 0) = 1.0;
    J(r, 1) = (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) / static_cast<double>(n);
    J(r, 2) = c[i];
    if (tc_free) J(r, 3) = A * (cp[i] - cm[i]) / (2 * h);  // ∂/∂ln τ
  }
  const Eigen::MatrixXd C = s * s * (J.transpose() * J).inverse();
  e.amp_sigma = std::sqrt(C(2, 2));
  e.ramp_sigma = std::sqrt(C(1, 1)) / T * 3600.0;
  e.tc_sigma = tc_free ? tc * std::sqrt(C(3, 3)) : 0.0;
  // Mid-record slope and curvature, per second, and their gradients in (level, c1, A, ln τ).
  const double E = std::exp(-T / 2 / tc), x = T / 2 / tc;
  e.slope_mid = (coef(1) / T - A / tc * E) * 3600.0;
  e.curvature_mid = A * E / (tc * tc) * 3600.0 * 3600.0;
  Eigen::VectorXd gs = Eigen::VectorXd::Zero(p), gk = Eigen::VectorXd::Zero(p);
  gs(1) = 1.0 / T;
  gs(2) = -E / tc;
  gk(2) = E / (tc * tc);
  if (tc_free) {
    gs(3) = A * E / tc * (1.0 - x);
    gk(3) = A * E / (tc * tc) * (x - 2.0);
  }
  e.slope_mid_sigma = std::sqrt(gs.dot(C * gs)) * 3600.0;
  e.curvature_mid_sigma = std::sqrt(gk.dot(C * gk)) * 3600.0 * 3600.0;
}

/// The white scatter `sig` of a 10-s block mean enlarged so that its Allan variance at T/4 also
/// carries the base's flicker floor (2 ln 2/π)·B²: the drift's parameters are set by the record's
/// slowest scales, where the flicker matters most.
double block_noise(double sig, double tb, double T, const DriftNoise& m) {
  const double floor2 = 2 * std::log(2.0) / kPi * m.b_deg_per_h * m.b_deg_per_h;
  return sig * std::sqrt(1.0 + floor2 * (T / 4) / (sig * sig * tb));
}

}  // namespace

WarmupEstimate warmup_detect(const Decimated& d, double tc_hint, const DriftNoise* noise) {
  WarmupEstimate e;
  const std::size_t pb = per_block_for(d, 10.0);
  const std::vector<double> y = block_rates(d, pb);
  const std::size_t n = y.size();
  if (n < 40) return e;
  const double tb = static_cast<double>(pb) * d.tau_d;
  const double T = tb * static_cast<double>(n);
  const double rss0 = ls_rss(y, {});
  auto rss_at = [&](double tc) { return ls_rss(y, {exp_column(n, tb, tc)}); };
  // The statistic searches τ up to T/3: a longer exponential is nearly the trend over the record,
  // and searched up to T it took part of a Gauss–Markov wander in every record's own candidate
  // (docs/diagnosis.md). The estimate searches up to 2T: a drift of τ ≈ T/2 clipped at T/3 came
  // out with A and r far off; beyond 2T the exponential is a parabola over the record.
  const double lt_lo = std::log(2.0 * tb), lt_hi = std::log(noise ? 2.0 * T : T / 3.0);
  double lbest = tc_hint > 0 ? std::log(tc_hint) : best_log_tc(rss_at, lt_lo, lt_hi, noise ? 60 : 40);
  Eigen::VectorXd coef;
  e.tc = std::exp(lbest);
  e.rss = ls_rss(y, {exp_column(n, tb, e.tc)}, &coef);
  e.amp = coef(2);
  // ls_rss's trend column runs over (i − (n − 1)/2)/n: its coefficient is the change over T.
  e.ramp = coef(1) / T * 3600.0;
  // F-type statistic: the residual variance, not the white level, normalises the drop, so that
  // wander the base fit took up into K or R does not hide the transient.
  e.statistic = std::max(0.0, (rss0 - e.rss) / (e.rss / static_cast<double>(n - 4)));
  if (!noise) return e;
  const double s = block_noise(std::max(diff_sigma(y), 1e-12), tb, T, *noise);
  drift_uncertainty(n, tb, s, tc_hint <= 0, coef, e);
  // A time constant the record does not bound (σ_τ/τ beyond the limit, or at the search's end):
  // A, τ and r trade along a ridge; only the mid-record slope and curvature are determined.
  e.separable = tc_hint > 0 || (e.tc_sigma <= kDriftSeparableSigma * e.tc && lbest < lt_hi - 0.05);
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
    const DriftNoise noise{s.base.bias_instability_deg_per_h};
    const auto est = warmup_detect(s.dec, s.warmup_tc_s, &noise);
    x.det.warmups.push_back({est.amp, est.tc});
    x.ramp = est.ramp;
    x.ramp_sigma = est.ramp_sigma;
    nlohmann::json p{{"slope_mid_deg_per_h2", est.slope_mid}, {"curvature_mid_deg_per_h3", est.curvature_mid}};
    nlohmann::json u{{"slope_mid_deg_per_h2", est.slope_mid_sigma},
                     {"curvature_mid_deg_per_h3", est.curvature_mid_sigma}};
    if (est.separable) {
      p.update({{"amplitude_deg_per_h", est.amp}, {"time_constant_s", est.tc}, {"ramp_deg_per_h2", est.ramp}});
      u.update({{"amplitude_deg_per_h", est.amp_sigma},
                {"time_constant_s", est.tc_sigma},
                {"ramp_deg_per_h2", est.ramp_sigma}});
    }
    // Not separable: a pair (A, τ) and a ramp from a ridge of equal fits would be printed as if
    // determined; only the slope and curvature are, and the finding says so.
    p["separable"] = est.separable;
    x.findings.push_back({Effect::Warmup, p, u, {}});
  }
};

}  // namespace

std::unique_ptr<RecordDetector> warmup_detector() { return std::make_unique<WarmupDetector>(); }

}  // namespace rwcalc::diag
