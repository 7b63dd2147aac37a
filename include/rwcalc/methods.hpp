#pragma once
/// @file methods.hpp
/// The seed paper's cross-checks of the AV results, with uncertainties (docs/analysis.md): N by
/// the direct method (angle variance against interval) and the spread of 100-s mean rates.
#include <cstddef>
#include <vector>

#include "rwcalc/fit.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

struct MethodOptions {
  double direct_t_min_s = 1.0;    ///< shortest interval of the direct method
  double direct_t_max_s = 100.0;  ///< longest (also at most T/50)
  int direct_points = 12;         ///< interval lengths, log-spaced
  int direct_segments = 8;        ///< segments for the standard error
  double block_s = 100.0;         ///< block of the averaging method
};

struct MethodEstimate {
  bool valid = false;  ///< false: the record is too short for the method
  double value = 0;    ///< °/√h or °/h
  double sigma = 0;    ///< standard error
  double low = 0;      ///< 95 % bounds (≥ 0)
  double high = 0;
  bool resolved = true;  ///< false: value is an upper bound
};

/// Interval t, number of intervals, variance of the angle (″²).
struct DirectPoint {
  double t_s = 0;
  std::size_t intervals = 0;
  double var_arcsec2 = 0;
};

struct DirectNResult {
  MethodEstimate N;
  double intercept_arcsec2 = 0;    ///< a (2Q² for white angle noise)
  double slope_arcsec2_per_s = 0;  ///< b = (60·N)²
  std::vector<DirectPoint> points;
  int segments_used = 0;
};

/// Direct N of a phase series in ″. Invalid (not thrown) when fewer than three lengths fit.
DirectNResult direct_n(const PhaseSeries& x, const MethodOptions& options = {});

struct BlockSpreadResult {
  MethodEstimate spread;  ///< std of the block mean rates, °/h
  double block_s = 0;     ///< the block used (whole samples)
  std::size_t blocks = 0;
  double expected = 0;        ///< expectation under a fitted model (0: not computed)
  double expected_sigma = 0;  ///< its standard error from the fit covariance
};

/// Spread of block-mean rates. Invalid when fewer than 3 blocks fit.
BlockSpreadResult block_spread(const PhaseSeries& x, double block_s = 100.0);

/// Expected sample variance, (°/h)², of `blocks` consecutive block means of length block_s under
/// the five-term model with fit-scale coefficients c (fit.hpp): exact for the asymptotic model.
double expected_block_variance(const Eigen::Matrix<double, kTermCount, 1>& c, double block_s, std::size_t blocks);

/// Fills `expected` and `expected_sigma` from a fit.
void attach_expectation(BlockSpreadResult& r, const FitResult& fit);

/// (a − b)/√(σa² + σb²); 0 when both sigmas vanish.
double discrepancy_sigma(double a, double sa, double b, double sb);

}  // namespace rwcalc
