#pragma once
/// @file outliers.hpp
/// Isolated outliers in a rate record (loose connectors, bus glitches): detection, and the two
/// ways of dealing with them besides keeping them — removal and replacement by the local median.
///
/// Detection compares each rate sample with the median of its six nearest neighbours (three on
/// each side, the sample itself excluded) and scales the residual by a robust spread of all
/// residuals: 1.4826 × their median absolute value, floored at the data's resolution (the
/// smallest non-zero step between neighbouring samples) so that quantised records — pulse counts,
/// a 16-bit ADC — whose median residual is zero do not turn every quantum into an "outlier".
/// A sample is an outlier when |residual| > threshold × scale. White-noise-dominated data keep no
/// false alarms at the default threshold 8 (a Gaussian exceeds 8σ with probability 1.2e-15);
/// slow drift and bias instability cancel in the neighbour median. Runs of up to two adjacent bad
/// samples are found without false alarms beside them (the median tolerates two bad neighbours
/// of six); longer bursts are found in part.
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

/// Lowest detection threshold accepted, robust z. Below 3 the test flags the tails of ordinary
/// Gaussian noise (beyond 3σ: 0.27 % of the samples, beyond 1σ: 32 %), not isolated glitches.
inline constexpr double kMinOutlierThreshold = 3.0;

/// Largest share of the rate samples that `--outliers remove|replace` may change. Isolated
/// outliers are rare by nature: Gaussian noise exceeds even the lowest threshold (3σ) on 0.27 %
/// of its samples, and glitches of a loose connector are far rarer still. When more than 1 % of
/// the samples are flagged they are the noise's own tail, a burst or a step, not isolated
/// glitches, and removing or replacing them would change the very noise the Allan variance
/// measures; the analysis refuses instead of rewriting the record.
inline constexpr double kMaxOutlierShare = 0.01;

/// The robust scale of a rate record (see the file comment). Needs at least 7 samples (else 0).
OutlierScale outlier_scale(const std::vector<double>& rates);

/// The same scale for the rates of a phase series (the rates Recording::rates() gives), computed
/// stretch by stretch without a copy of the whole record: bit-identical to outlier_scale(rates).
OutlierScale outlier_scale(const PhaseSeries& phase);

/// Isolated outliers of `rates`, sorted by index; `line` is 0. Fewer than 7 samples: none.
std::vector<Outlier> find_outliers(const std::vector<double>& rates,
                                   double threshold = kDefaultOutlierThreshold);

/// Same, with the robust scale already computed by outlier_scale(rates).
std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& scale);

/// Same, on the rates of a phase series, computed stretch by stretch (no copy of the record); the
/// result is identical to find_outliers(rates, threshold, scale) on the rates as a vector.
std::vector<Outlier> find_outliers(const PhaseSeries& phase, double threshold, const OutlierScale& scale);

/// Same, on a recording's rates, with the input line of each outlier filled in.
std::vector<Outlier> find_outliers(const Recording& recording,
                                   double threshold = kDefaultOutlierThreshold);

/// What to do with detected outliers.
enum class OutlierAction {
  Keep,     ///< leave the data as read
  Remove,   ///< drop the samples: the record gets shorter and the samples after each one move one
            ///< period earlier (a splice); harmless for the Allan variance while few are removed
  Replace,  ///< put the median of the four nearest non-outlier neighbours in their place
};

/// The rates with the outliers dropped (in order).
std::vector<double> remove_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers);

/// The rates with each outlier replaced by the median of its four nearest non-outlier neighbours.
std::vector<double> replace_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers);

/// A phase series with the outliers' increments removed or replaced (Keep: a copy). Exact pulse
/// counts stay exact integers: a replacement count is the neighbour median rounded to the nearest
/// integer (halves away from zero).
PhaseSeries apply_outliers(const PhaseSeries& phase, const std::vector<Outlier>& outliers,
                           OutlierAction action);

}  // namespace rwcalc
