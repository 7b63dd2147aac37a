#pragma once
/// @file methods.hpp
/// The seed paper's cross-checks of the AV results, with uncertainties:
///  - N by the direct method (paper's Fig. 2): the angle accumulated over non-overlapping
///    intervals of length t, its mean (Earth rate + bias) removed, the variance of these angles
///    against t, and the slope of a weighted linear regression s²(t) = a + N²·t. The intercept
///    absorbs white angle noise (quantization: a = 2Q²); flicker and RRW bend the line upwards,
///    so with a B floor inside the t range the direct N is biased high (docs/analysis.md).
///  - the spread of 100-s mean rates (sample standard deviation of the block means). It measures
///    the whole noise at 100 s, not B alone: for white rate it is N/√(100 s), for flicker it grows
///    with ln(T/100 s). Its expectation under the fitted AV model is computed exactly (so the
///    comparison is like with like) and reported beside it.
/// Uncertainties: for the direct N, from the spread of the estimate over contiguous segments of
/// the record (Student t); for the 100-s spread, χ² with (blocks − 1) degrees of freedom.
#include <cstddef>
#include <vector>

#include "rwcalc/fit.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

struct MethodOptions {
  double direct_t_min_s = 1.0;    ///< shortest interval of the direct method, s
  double direct_t_max_s = 100.0;  ///< longest interval, s (also limited to T/50)
  int direct_points = 12;         ///< interval lengths, log-spaced
  int direct_segments = 8;        ///< contiguous segments for the direct method's standard error
  double block_s = 100.0;         ///< block length of the averaging method, s
};

/// A cross-check estimate with its uncertainty.
struct MethodEstimate {
  bool valid = false;   ///< false when the record is too short for the method
  double value = 0;     ///< in the unit of the method (°/√h or °/h)
  double sigma = 0;     ///< standard error
  double low = 0;       ///< 95 % bounds (log-normal on the value; ≥ 0)
  double high = 0;
  bool resolved = true; ///< false: value is an upper bound (the estimate came out ≤ 0)
};

/// One point of the direct method: interval t, number of intervals, variance of the angle, ″².
struct DirectPoint {
  double t_s = 0;
  std::size_t intervals = 0;
  double var_arcsec2 = 0;
};

struct DirectNResult {
  MethodEstimate N;              ///< °/√h
  double intercept_arcsec2 = 0;  ///< a of s²(t) = a + b·t (2Q² for white angle noise)
  double slope_arcsec2_per_s = 0; ///< b of s²(t) = a + b·t, ″²/s (= (60·N)² with N in °/√h)
  std::vector<DirectPoint> points;
  int segments_used = 0;
};

/// Direct N of a gyro phase series (phase in ″). Invalid (not thrown) when fewer than three
/// interval lengths fit into the record.
DirectNResult direct_n(const PhaseSeries& x, const MethodOptions& options = {});

struct BlockSpreadResult {
  MethodEstimate spread;          ///< std of the block mean rates, °/h
  double block_s = 0;             ///< the block actually used (whole samples), s
  std::size_t blocks = 0;
  double expected = 0;            ///< its expectation under a fitted model, °/h (0 if not computed)
  double expected_sigma = 0;      ///< standard error of that expectation from the fit covariance
};

/// Spread of block-mean rates. Invalid when fewer than 3 blocks fit in the record.
BlockSpreadResult block_spread(const PhaseSeries& x, double block_s = 100.0);

/// Expected sample variance, (°/h)², of `blocks` consecutive block means of length block_s (s)
/// under the five-term model with fit-scale squared coefficients c (see fit.hpp), from the
/// generalized structure function of the angle (exact for the asymptotic model).
double expected_block_variance(const Eigen::Matrix<double, kTermCount, 1>& c, double block_s, std::size_t blocks);

/// Fill `expected`/`expected_sigma` of a block-spread result from a fit.
void attach_expectation(BlockSpreadResult& r, const FitResult& fit);

/// (a − b)/√(σa² + σb²), 0 when both sigmas vanish.
double discrepancy_sigma(double a, double sa, double b, double sb);

}  // namespace rwcalc
