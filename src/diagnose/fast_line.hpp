#pragma once
/// @file fast_line.hpp
/// Lines above the block means' band: the periodogram of the rate samples over its local level, a
/// test with an exact null law per bin and a Bonferroni bound over the bins searched.
#include <cstddef>
#include <string>
#include <vector>

namespace rwcalc::diag {

struct FastLine {
  double statistic = 0;  ///< largest periodogram ordinate over its local level
  double threshold = 0;  ///< the ratio whose bound is α
  double p = 1;          ///< bound on its false-alarm probability
  double f_hz = 0, amp = 0, phase = 0, f_sigma = 0, amp_sigma = 0;
  double level = 0;  ///< the rate's variance per sample at f (the local periodogram level), (°/h)²
  double lr = 0;     ///< −2Δ ln L of the line: its least-squares explained sum of squares over `level`
  std::string test;
};

/// Search rate samples `y` (°/h, step dt s, time origin at the record's start) from `f_min` to
/// `f_max` Hz. Under the null each Hann-windowed ordinate over the mean of `kLevelBins` others
/// (every second true bin, 4 … 258 bins away) is Exp(1)/Gamma(W, 1/W): P(ratio > u) =
/// (1 + u/W)^{−W}, exact for a locally flat spectrum.
FastLine fast_line_search(std::vector<double> y, double dt, double f_min, double f_max, double alpha);

/// The line `l` out of sample: each half of `y` (as searched) predicted by the line fitted to the
/// other half (its frequency refined there), scored by −2 ln L in the line's two dimensions at the
/// local level: the sum over both halves of what the prediction removes, in χ² units.
double fast_line_holdout(const std::vector<double>& y, double dt, const FastLine& l);

inline constexpr int kLevelBins = 256;
/// Longest periodogram segment, samples (longer records average segments).
inline constexpr std::size_t kSegment = std::size_t{1} << 22;

}  // namespace rwcalc::diag
