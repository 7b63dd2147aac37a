#pragma once
// Spectral lines in a rate record (a vibration, a resonance, an interference) that the five-term
// model lacks: found in the Welch spectrum of the rate, and their Allan variance, which the fit
// takes off the octave points (docs/analysis.md, "Spectral lines").
#include <vector>

#include "rwcalc/series.hpp"

namespace rwcalc {

/// One line: the bins of the Welch spectrum that stand out of the local level, with their excess.
struct SpectralLineFound {
  double f_hz = 0;             ///< frequency of the highest bin
  double power = 0;            ///< Σ (S − level)·Δf over the line's bins, (phase unit/s)²
  double peak_ratio = 0;       ///< S / level at the highest bin
  std::vector<double> f;       ///< the line's bins, Hz
  std::vector<double> excess;  ///< (S − level)·Δf at each, (phase unit/s)²
};

/// The lines of the rate x'(t): bins whose one-sided Welch PSD (Hann windows of the largest power of
/// two up to 2^16 samples that leaves at least 15 half-overlapping windows; 64 without overlap,
/// spread evenly over the record, where it holds 64 whole windows or more) exceeds 10 times the
/// local level (the median over the octave below to the octave above), with the window's main
/// lobe (2 bins each side). None for records shorter than 15 windows of 256 samples.
std::vector<SpectralLineFound> find_spectral_lines(const PhaseSeries& x);

/// The lines' Allan variance at τ: Σ excess·2 sin⁴(πfτ)/(πfτ)² (the AV of a stationary process of
/// one-sided PSD S is ∫ 2 S(f) sin⁴(πfτ)/(πfτ)² df).
double spectral_lines_avar(const std::vector<SpectralLineFound>& lines, double tau_s);

}  // namespace rwcalc
