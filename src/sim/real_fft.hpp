#pragma once
// An inverse real FFT in single precision, in place, with no work space of the transform's size
// (internal to the sim layer; FFTW's libfftw3f).
#include <algorithm>
#include <complex>
#include <cstddef>
#include <vector>

struct fftwf_plan_s;

namespace rwcalc::detail {

/// The real sequence of even length L from its half spectrum (L/2 + 1 bins), unnormalised:
/// x_j = X_0 + (−1)^j X_{L/2} + 2·Re Σ_{0<k<L/2} X_k e^{2πijk/L}. The spectrum and the sequence share
/// one buffer of L floats. The transform is one complex transform of M = L/2 points (the even and
/// odd values as real and imaginary parts), done in four steps over an M1 × M2 table (M = M1·M2,
/// both near √M): FFTW transforms short rows and columns in place, where its plan of one long
/// transform held a work space and tables of 0.5 to 1.5 times the buffer. FFTW plans without SIMD
/// code, so that every x86-64 processor rounds the same way (simulated pulse records are compared
/// byte for byte across machines).
class RealInverseFft {
 public:
  explicit RealInverseFft(std::size_t size);
  ~RealInverseFft();
  RealInverseFft(const RealInverseFft&) = delete;
  RealInverseFft& operator=(const RealInverseFft&) = delete;

  /// Sets bin k = 0 … L/2 to draw(k), called once per bin in that order (a random stream's order).
  /// The imaginary parts of bins 0 and L/2 are not used.
  template <class Draw>
  void set_spectrum(Draw&& draw) {
    std::size_t k = 0;
    for (std::size_t first = 0; first < m1_; first += kStagedRows) {
      const std::size_t rows = std::min(kStagedRows, m1_ - first);
      for (std::size_t i = 0; i < rows * m2_; ++i) staged_[i] = draw(k++);
      store_staged(first, rows);
    }
    nyquist_ = draw(k).real();
  }

  /// Transforms the spectrum into values(), overwriting it.
  void run();

  [[nodiscard]] float* values() noexcept { return reinterpret_cast<float*>(data_); }
  [[nodiscard]] const float* values() const noexcept { return reinterpret_cast<const float*>(data_); }

  /// Bytes a transform of `size` points holds: its buffer, the staged rows and FFTW's two short
  /// plans.
  [[nodiscard]] static std::size_t memory_bytes(std::size_t size) noexcept;

 private:
  // Bins are drawn in order k = M2·k1 + k2 but kept at k1 + M1·k2 (the first step's rows); a few
  // rows are staged so that each cache line of the buffer is written whole.
  static constexpr std::size_t kStagedRows = 8;
  void store_staged(std::size_t first, std::size_t rows) noexcept;
  void pair_bins() noexcept;
  void twiddle() noexcept;

  std::size_t m_ = 0, m1_ = 0, m2_ = 0;
  std::complex<float>* data_ = nullptr;
  float nyquist_ = 0;
  std::vector<std::complex<float>> staged_;
  fftwf_plan_s* rows_plan_ = nullptr;
  fftwf_plan_s* columns_plan_ = nullptr;
};

}  // namespace rwcalc::detail
