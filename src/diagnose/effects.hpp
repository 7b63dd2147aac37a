#pragma once
/// @file effects.hpp
/// The effects the likelihood of the block means tests (gls.hpp): slow lines, bias steps, warm-up
/// transients and drifts as regressors, Gauss–Markov terms as covariance terms; each family's scan,
/// its p-value bound, and the forward selection that names them (docs/diagnosis.md).
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gls.hpp"
#include "rwcalc/diagnose.hpp"

namespace rwcalc::diag {

/// A deterministic term of the rate: its kind and its nonlinear parameter (a line's frequency, Hz;
/// a step's time, s; a transient's time constant, s).
struct DetTerm {
  Effect effect = Effect::Sinusoid;
  double nl = 0;
};
/// Its regressor columns in z (second differences of the block means): 2 for a line, 1 else.
Eigen::MatrixXd det_columns(const Blocks& b, const DetTerm& t);

/// A model of the block means: deterministic terms and covariance terms, with its profile.
struct GlsModel {
  std::vector<DetTerm> det;
  std::vector<CovTerm> cov;
  Profile fit;
};
Hypothesis hypothesis_of(const Blocks& b, const std::vector<DetTerm>& det, const std::vector<CovTerm>& cov);
/// Profile `m` (det and cov set) from the levels of `from` (new covariance terms start at
/// `new_level`).
void refit(const Blocks& b, GlsModel& m, const GlsModel& from, double new_level);

/// p-value bound of the largest of a χ²_s statistic over a smooth one-parameter family whose
/// unit-variance components trace a curve of length `length` (radians): P(χ²_s > u) plus the
/// expected up-crossings (Davies 1987, Hotelling's tube).
double scan_p(double u, int s, double length);
/// The statistic whose scan_p is `alpha`.
double scan_threshold(double alpha, int s, double length);
/// P(χ²_s > u).
double chi2_sf(double u, int s);

/// A χ² bound `p_chi2(u)` of a statistic whose alternative also moves one noise level towards its
/// boundary (the flicker level giving up power to a slow effect): the law of the sum with an
/// independent ½χ²₀ + ½χ²₁, ½p(u) + ½E p(u − Y), Y ~ χ²₁.
double level_boundary_p(const std::function<double(double)>& p_chi2, double u);
/// The u at which a decreasing p(u) falls to alpha.
double threshold_of(const std::function<double(double)>& p, double alpha);

/// One family's best candidate against the current model.
struct Candidate {
  Effect effect = Effect::Sinusoid;
  double lr = 0;         ///< −2 Δ ln L, levels profiled under both hypotheses
  double p = 1;          ///< bound on the probability of an LR as large under the current model
  double threshold = 0;  ///< the LR whose p is the family's α
  std::string test;      ///< the test and its null law
  GlsModel model;        ///< the current model with the candidate
};

/// The searches. `alpha` is the family's false-alarm level.
Candidate search_slow_line(const Blocks& b, const GlsModel& cur, double alpha, double f_lo, double f_hi, Effect effect);
Candidate search_step(const Blocks& b, const GlsModel& cur, double alpha);
Candidate search_transient(const Blocks& b, const GlsModel& cur, double alpha);
Candidate search_gauss_markov(const Blocks& b, const GlsModel& cur, double alpha);

/// A named term's parameters with standard errors and 95 % profile intervals, under the final
/// model.
struct TermEstimate {
  std::vector<FindingParameter> parameters;
};
/// A parameter with a symmetric 95 % interval, value ± kZ95·σ.
FindingParameter from_sigma(std::string name, Quantity q, double value, double sigma);
/// A parameter with a profile interval [low, high]; its standard uncertainty is the width / (2·kZ95).
FindingParameter from_interval(std::string name, Quantity q, double value, double low, double high);
/// Every deterministic term's, in the order of m.det.
std::vector<TermEstimate> estimate_det(const Blocks& b, const GlsModel& m);
TermEstimate estimate_gm(const Blocks& b, const GlsModel& m, std::size_t cov_index);

}  // namespace rwcalc::diag
