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
#include <memory>
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
/// block by block without a copy of the whole record: bit-identical to outlier_scale(rates).
/// `threads`: 0 = all hardware threads; records of more than 2^20 samples use two when allowed.
OutlierScale outlier_scale(const PhaseSeries& phase, unsigned threads = 0);

/// Isolated outliers of `rates`, sorted by index; `line` is 0. Fewer than 7 samples: none.
std::vector<Outlier> find_outliers(const std::vector<double>& rates,
                                   double threshold = kDefaultOutlierThreshold);

/// Same, with the robust scale already computed by outlier_scale(rates).
std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& scale);

/// Same, on the rates of a phase series, computed block by block (no copy of the record); the
/// result is identical to find_outliers(rates, threshold, scale) on the rates as a vector.
/// `threads`: 0 = all hardware threads; records of more than 2^20 samples use two when allowed.
std::vector<Outlier> find_outliers(const PhaseSeries& phase, double threshold, const OutlierScale& scale,
                                   unsigned threads = 0);

/// outlier_scale(phase, threads) and find_outliers(phase, threshold, scale, threads) in one call,
/// with the same results; on exact counts usually in one pass over the record instead of two.
std::vector<Outlier> scan_outliers(const PhaseSeries& phase, double threshold, OutlierScale& scale,
                                   unsigned threads = 0);

/// scan_outliers shared between threads that join in whenever they are free: any number of
/// threads call help(), each taking stretches of the record until none is left (on exact counts;
/// on other data the first caller runs the whole scan), and once every help() has returned one
/// thread calls finish(), which does what is left. The results are those of scan_outliers.
class SharedOutlierScan {
 public:
  SharedOutlierScan(const PhaseSeries& phase, double threshold);
  ~SharedOutlierScan();
  SharedOutlierScan(const SharedOutlierScan&) = delete;
  SharedOutlierScan& operator=(const SharedOutlierScan&) = delete;
  void help();
  /// `threads` for the last step (records of more than 2^20 samples use two when allowed).
  std::vector<Outlier> finish(OutlierScale& scale, unsigned threads = 1);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

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
