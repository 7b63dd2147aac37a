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
  std::string test;
};

/// Search rate samples `y` (°/h, step dt s, time origin at the record's start) from `f_min` to
/// `f_max` Hz. Under the null each Hann-windowed ordinate over the mean of `kLevelBins` others
/// (every second true bin, 4 … 258 bins away) is Exp(1)/Gamma(W, 1/W): P(ratio > u) =
/// (1 + u/W)^{−W}, exact for a locally flat spectrum.
FastLine fast_line_search(std::vector<double> y, double dt, double f_min, double f_max, double alpha);

inline constexpr int kLevelBins = 256;
/// Longest periodogram segment, samples (longer records average segments).
inline constexpr std::size_t kSegment = std::size_t{1} << 22;

}  // namespace rwcalc::diag
