#pragma once
// Eigenvalues of the circulant embedding of the flicker rate's increments (internal to the sim
// layer): the exact simulation draws its flicker from them (simulate.cpp, docs/simulation.md).
#include <cstddef>

namespace rwcalc::detail {

/// The circulant of even length L whose first row is the autocovariance of the increments of a
/// Kasdin flicker rate of unit B, γ(h) = 4/(π(1 − 4h²)) for |h| ≤ L/2, and its eigenvalues
/// λ_k = Σ_h γ(h)·cos(2πhk/L), each computed on its own in closed form to about 1e-13 of itself
/// (tests/test_flicker_circulant.cpp), so that no L-point array and no FFT is needed for them.
class FlickerCirculant {
 public:
  explicit FlickerCirculant(std::size_t size);  ///< size L: even, ≥ 2

  /// λ_k for 0 ≤ k ≤ L/2 (λ_{L−k} = λ_k); all are positive.
  [[nodiscard]] double eigenvalue(std::size_t k) const;

 private:
  std::size_t size_;
  std::size_t half_;    // H = L/2
  std::size_t direct_;  // J: terms of the tail beyond H summed one by one before its asymptotic form
};

}  // namespace rwcalc::detail
