// The Gauss–Markov detector. The base fit takes a bump into a large flicker floor, which realises
// such bumps by itself, so the bump fit on the mid-τ AV only proposes the alternative M1 (base
// plus bump), simulated with the same seeds; the statistic is the drop of the mid-τ Gamma deviance
// from the base ensemble to M1's, which must beat every base record's drop and a likelihood ratio
// of 100 (docs/diagnosis.md, "Naming a Gauss–Markov term").
#include <boost/math/distributions/chi_squared.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "diagnose/models.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::diag {

namespace {

constexpr double kGmMinPeakRatio = 0.6;  ///< bump AV at its peak / base AV there, to name the term
constexpr double kGmMinExcess = 2.0;     ///< ensemble SDs the bump must raise the mid-τ AV by
/// The deviance drop (2 ln of the likelihood ratio) M1 must reach at least.
const double kGmMinLogLr = 2.0 * std::log(100.0);
/// Parameters of M1 fitted to the data beyond the base: the bump's σ² and Tc, and the N², B², K²
/// corrections beside it.
constexpr double kGmFittedParameters = 5.0;

/// The floor of the data's deviance drop. M1 is fitted to the data and the base records are
/// scored against that M1 without a fit of their own, so their drops do not carry the fit's gain:
/// under the base the data's drop is about χ² with M1's fitted parameters as degrees of freedom
/// (Wilks), whose (1 − α) quantile is the floor (15.1 at α = 1 %), and never below 2 ln 100.
double min_log_lr(double alpha) {
  return std::max(kGmMinLogLr, boost::math::quantile(boost::math::chi_squared(kGmFittedParameters), 1.0 - alpha));
}

/// A model plus a fitted bump, its B² and K² corrections and the white rate noise left beside it.
NoiseModel with_bump(const NoiseModel& base, const ShapeEstimate& est) {
  NoiseModel m = base;
  correct(m.bias_instability_deg_per_h, Term::B, est.dc[2]);
  correct(m.rrw_deg_per_h_per_sqrt_h, Term::K, est.dc[3]);
  m.arw_deg_per_sqrt_h = coefficient_from_c(Term::N, est.white_rest);
  m.gauss_markov.push_back({std::sqrt(std::max(est.scale, 0.0)), std::max(est.time, 1e-3)});
  return m;
}

/// Why a bump fit cannot be a Gauss–Markov term (empty: it can): a fit that only trades the white
/// noise for a bump is a deficit; a bump far below the local AV re-arranges flicker or white noise.
std::string implausible(const ShapeEstimate& gm) {
  if (!(gm.scale > 0)) return tr("no bump improves the fit of the mid-τ Allan variance");
  if (gm.excess < kGmMinExcess && gm.white_rest < 2.0 * gm.white_rest_sigma)
    return trf(
        "the fitted shape raises the mid-τ Allan variance by at most {:.2g} ensemble standard "
        "deviations and leaves no white rate noise ({:.3g} ± {:.2g} (°/h)²·s): a deficit, not a "
        "Gauss–Markov bump",
        gm.excess, gm.white_rest, gm.white_rest_sigma);
  if (gm.peak_ratio < kGmMinPeakRatio)
    return trf(
        "the bump's Allan variance at its peak is {:.2g} of the base model's there (at least {:g} "
        "needed): not told apart from the flicker and white noise",
        gm.peak_ratio, kGmMinPeakRatio);
  return {};
}

class GaussMarkovDetector final : public Detector {
 public:
  [[nodiscard]] Effect effect() const override { return Effect::GaussMarkov; }
  [[nodiscard]] bool mid_tau() const override { return true; }

  [[nodiscard]] DetectorResult test(const Trial& t) const override {
    const Stretch& s = t.stretch;
    const std::vector<double>& v = *t.mid_var;
    const auto gm = shape_detect(v, s.ref, c_of(s.base));
    DetectorResult d;
    d.effect = Effect::GaussMarkov;
    d.threshold = min_log_lr(s.opt->alpha);
    d.note = implausible(gm);
    if (!d.note.empty()) return d;
    const std::size_t runs = t.runs.size();
    const auto m1_runs = run_ensemble(with_bump(s.base, gm), t.settings, runs,
                                      {s.octave_m, s.ref.grid, true, {}, false}, s.opt->progress);
    const auto m1_ref = make_reference(s.ref.grid, s.dec.tau_d, m1_runs, true);
    d.statistic = mid_deviance(v, s.clean_ref) - mid_deviance(v, m1_ref);
    std::vector<double> e_gm;
    for (const auto& br : t.runs) {
      const auto loo = leave_one_out(s.clean_ref, br.mid_var_clean, runs);
      e_gm.push_back(mid_deviance(br.mid_var_clean, loo) - mid_deviance(br.mid_var_clean, m1_ref));
    }
    d.ensemble_max = *std::max_element(e_gm.begin(), e_gm.end());
    d.ensemble_median = quantile(e_gm, 0.5);
    d.threshold = std::max(min_log_lr(s.opt->alpha), d.ensemble_max);
    set_verdict(d, d.threshold);
    return d;
  }

  /// A block shows the term when its bump fit with the whole record's correlation time passes the
  /// naming conditions (a block's own likelihood-ratio test has too little power).
  [[nodiscard]] bool shows_in(const Trial& t) const override {
    const Stretch& s = t.stretch;
    return implausible(shape_detect(decimated_avar(t.data.clean, s.ref.grid), s.ref, c_of(s.base), s.gm_tc_s)).empty();
  }

  void estimate(const Stretch& s, Extension& x) const override {
    const ShapeEstimate est = shape_detect(x.mid_var, s.ref, c_of(s.base), s.gm_tc_s);
    x.model = with_bump(x.model, est);
    const double sigma = x.model.gauss_markov.back().sigma_deg_per_h;
    x.findings.push_back({Effect::GaussMarkov,
                          {{"sigma_deg_per_h", sigma}, {"correlation_time_s", est.time}},
                          {{"sigma_deg_per_h", sigma > 0 ? est.scale_sigma / (2 * sigma) : 0.0},
                           {"correlation_time_s", 0.5 * (est.time_high - est.time_low)}},
                          {}});
  }
};

}  // namespace

std::unique_ptr<Detector> gauss_markov_detector() { return std::make_unique<GaussMarkovDetector>(); }

}  // namespace rwcalc::diag
