#pragma once
#ifndef RWCALC_USES_IO
#error "rwcalc/outliers.hpp belongs to the io layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file outliers.hpp
/// Isolated outliers in a rate record (loose connectors, bus glitches): detection, removal and
/// replacement by the local median. A sample is an outlier when its residual from the median of
/// its six nearest neighbours exceeds threshold × max(1.4826·MAD of the residuals, resolution);
/// the resolution floor keeps quantised records from flagging every quantum (docs/analysis.md).
#include <cstddef>
#include <vector>

#include "rwcalc/reader.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

struct Outlier {
  std::size_t index = 0;  ///< rate sample index (0-based), as in Recording::rates()
  std::size_t line = 0;   ///< 1-based input line, 0 when not known
  double value = 0.0;     ///< the rate sample, deviation units (°/h for gyro data)
  double robust_z = 0.0;  ///< residual from the neighbour median over the robust scale (signed)
};

/// Robust spread used by find_outliers, in the units of `rates` (exposed for reporting).
struct OutlierScale {
  double scale = 0.0;       ///< max(1.4826·MAD of the residuals, resolution)
  double mad_sigma = 0.0;   ///< 1.4826·MAD of the neighbour-median residuals
  double resolution = 0.0;  ///< smallest non-zero |y_i − y_{i−1}| seen (quantum of quantised data)
};

/// Detection threshold used when none is given (robust z).
inline constexpr double kDefaultOutlierThreshold = 8.0;

/// Lowest threshold accepted: below 3 the test flags the tails of Gaussian noise, not glitches.
inline constexpr double kMinOutlierThreshold = 3.0;

/// Largest share of the samples `--outliers remove|replace` may change: more flagged samples are
/// the noise's own tail, a burst or a step, and rewriting them would change the noise measured.
inline constexpr double kMaxOutlierShare = 0.01;

/// The robust scale of a rate record (see the file comment). Needs at least 7 samples (else 0).
OutlierScale outlier_scale(const std::vector<double>& rates);

/// The same, stretch by stretch over a phase series' rates (bit-identical, no copy).
OutlierScale outlier_scale(const PhaseSeries& phase);

/// Isolated outliers of `rates`, sorted by index; `line` is 0. Fewer than 7 samples: none.
std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold = kDefaultOutlierThreshold);

/// Same, with the robust scale already computed by outlier_scale(rates).
std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& scale);

/// Same, stretch by stretch over a phase series' rates (identical result, no copy).
std::vector<Outlier> find_outliers(const PhaseSeries& phase, double threshold, const OutlierScale& scale);

/// Same, on a recording's rates, with the input line of each outlier filled in.
std::vector<Outlier> find_outliers(const Recording& recording, double threshold = kDefaultOutlierThreshold);

/// What to do with detected outliers.
enum class OutlierAction {
  Keep,     ///< leave the data as read
  Remove,   ///< drop the samples (a splice: the later samples move one period earlier)
  Replace,  ///< put the median of the four nearest non-outlier neighbours in their place
};

/// The rates with the outliers dropped (in order).
std::vector<double> remove_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers);

/// The rates with each outlier replaced by the median of its four nearest non-outlier neighbours.
std::vector<double> replace_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers);

/// A phase series with the outliers' increments removed or replaced (Keep: a copy). Exact pulse
/// counts stay exact integers: a replacement count is the neighbour median rounded to the nearest
/// integer (halves away from zero).
PhaseSeries apply_outliers(const PhaseSeries& phase, const std::vector<Outlier>& outliers, OutlierAction action);

}  // namespace rwcalc
