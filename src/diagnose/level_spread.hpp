#pragma once
/// @file level_spread.hpp
/// How well a record pins its noise levels, and what that leaves of an interval's confidence: the
/// levels' covariance from the curvature of the restricted likelihood, and the effective degrees of
/// freedom (Satterthwaite) of a variance that depends on them. A slow line's frequency or a step's
/// size is uncertain through the flicker and random-walk levels, which the few lowest frequencies of
/// a record pin; taken as known, they made the intervals of a line and a step named together too
/// narrow where the levels came out low (docs/diagnosis.md).
#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "gls.hpp"

namespace rwcalc::diag {

/// The covariance of a hypothesis' levels as estimated from the record: the inverse of their
/// information (Whittle's, from the terms' spectra over the blocks' band). A level on its bound of 0
/// keeps the spread its information gives; a known level (a counter's) has a zero row.
struct LevelSpread {
  std::vector<double> level;
  Eigen::MatrixXd cov;
};
LevelSpread level_spread(const Blocks& b, const Hypothesis& h, const std::vector<double>& level);

/// The effective degrees of freedom of a variance v(levels): 2v²/Var v̂, Var v̂ by the delta method
/// over the levels' spread; infinity when v does not move with them (or is not positive).
double effective_dof(const LevelSpread& s, const std::function<double(const std::vector<double>&)>& variance);

/// The rise of −2 ln L that bounds a 95 % profile interval whose variance has `dof` degrees of
/// freedom: Student's t²(0.975, dof), χ²₁'s 3.84 as dof grows.
double profile_cutoff(double dof);

/// The rise of −2 ln L that bounds a 95 % profile interval with the levels known (χ²₁).
inline constexpr double kChi2Cut95 = 3.841458820694124;

}  // namespace rwcalc::diag
