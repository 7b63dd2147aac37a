// The detectors' shared calibration and the registry of a record's detectors.
#include "diagnose/detector.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "rwcalc/i18n.hpp"

namespace rwcalc {

namespace {

struct EffectNames {
  std::string_view detector, finding, description;
};
constexpr std::array<EffectNames, kEffectCount> kNames{{
    {"sinusoid", "sinusoid", "periodogram peak of the 0.5-s block-mean rates over its local median level"},
    {"sinusoid_hf", "sinusoid",
     "periodogram peak of the raw rate samples over its local median level, whole record and Welch means (detector "
     "sinusoid_hf)"},
    {"bias_step", "bias_step",
     "largest two-window change of the 10-s block-mean rates, in units of its standard error"},
    {"warmup_transient", "warmup_transient",
     "drop of the residual sum of squares of the 10-s block means when an exponential is added"},
    {"gauss_markov", "gauss_markov", "χ² drop of the mid-τ Allan variance when a Gauss–Markov bump is added"},
    {"lowpass", "lowpass",
     "χ² drop of the short-τ Allan variance when white angle and rate noise pass through an output-chain low-pass"},
}};

}  // namespace

std::string_view detector_name(Effect e) { return kNames[static_cast<std::size_t>(e)].detector; }
std::string_view finding_name(Effect e) { return kNames[static_cast<std::size_t>(e)].finding; }

namespace diag {

std::string_view detector_description(Effect e) { return kNames[static_cast<std::size_t>(e)].description; }

DetectorResult RecordDetector::calibrate(double statistic, const std::vector<RunStats>& runs, double alpha) const {
  std::vector<double> ens;
  for (const auto& r : runs)  // NaN: a record the statistic was not computed on
    if (const double v = r.stat[static_cast<std::size_t>(effect())]; !std::isnan(v)) ens.push_back(v);
  DetectorResult d;
  d.effect = effect();
  d.statistic = statistic;
  const GumbelQuantile q = gumbel_quantile(ens, alpha);
  d.threshold = q.value;
  d.threshold_sigma = q.sigma;
  d.ensemble_max = ens.empty() ? 0.0 : *std::max_element(ens.begin(), ens.end());
  d.ensemble_median = quantile(ens, 0.5);
  set_verdict(d, d.threshold + kThresholdUpperZ * q.sigma);
  return d;
}

void set_verdict(DetectorResult& d, double upper) {
  d.threshold_upper = std::max(upper, d.threshold);
  d.fired = d.statistic > d.threshold;
  d.named = d.statistic > d.threshold_upper;
  d.excess = d.fired && !d.named;
  if (d.excess)
    d.note = fmt::format(
        "excess, not named: the statistic is above the threshold but within its Monte-Carlo uncertainty (upper 95 % "
        "limit {:.4g}, threshold {:.4g} ± {:.2g})",
        d.threshold_upper, d.threshold, d.threshold_sigma);
}

DetectorResult RecordDetector::test(const Trial& t) const {
  return calibrate(statistic(t.data), t.runs, t.stretch.opt->alpha);
}

std::vector<std::unique_ptr<Detector>> make_detectors(const AnalysisResult& analysis, const PhaseSeries& x,
                                                      bool lattice) {
  std::string skip;
  if (x.exact())
    skip = tr("whole pulse counts: no filter in the output chain");
  else if (lattice)
    skip =
        tr("the samples are whole multiples of a step coarse against their scatter (pulse counts as numbers): no "
           "filter in the output chain");
  std::vector<std::unique_ptr<Detector>> d;
  d.push_back(sinusoid_detector());
  d.push_back(step_detector());
  d.push_back(warmup_detector());
  d.push_back(gauss_markov_detector());
  d.push_back(lowpass_detector(analysis, x.duration_s(), skip));
  if (skip.empty()) d.push_back(line_detector());
  return d;
}

}  // namespace diag

}  // namespace rwcalc
