#pragma once
#ifndef RWCALC_USES_ALLAN
#error "rwcalc/fft.hpp belongs to the allan layer, which this layer may not use (docs/architecture.md)"
#endif
// Power spectra of real sequences (internal): |X_k|² of the zero-padded DFT, for the periodograms
// of the line search. Small transforms go to Eigen's kissfft as they are; a long one (the whole
// record's, 2^23 points for a 2-h record at 400 Hz) is taken in four steps over sub-transforms that
// stay in cache (docs/performance.md, "The line search's long transform in four steps").
#include <cstddef>
#include <memory>

namespace rwcalc::detail {

/// |X_k|², k = 0 … nfft/2, of X_k = Σ_t x_t e^{−2πi kt/nfft}, x zero-padded to `nfft`.
class RealPowerSpectrum {
 public:
  /// nfft: a power of two, at least 4.
  explicit RealPowerSpectrum(std::size_t nfft);
  ~RealPowerSpectrum();
  RealPowerSpectrum(const RealPowerSpectrum&) = delete;
  RealPowerSpectrum& operator=(const RealPowerSpectrum&) = delete;

  /// Adds |X_k|² to P[k] for k = 0 … nfft/2 (P holds nfft/2 + 1 values); x holds n ≤ nfft samples.
  void add(const double* x, std::size_t n, double* P);

  /// Transforms from this many points on are taken in four steps (below, by kissfft directly).
  static constexpr std::size_t kFourStepFrom = std::size_t{1} << 17;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rwcalc::detail
