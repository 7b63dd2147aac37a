#pragma once
// An inverse real FFT in single precision, in place (internal to the sim layer; FFTW's libfftw3f).
#include <complex>
#include <cstddef>

struct fftwf_plan_s;

namespace rwcalc::detail {

/// The real sequence of even length L from its half spectrum (L/2 + 1 bins), unnormalised:
/// x_j = X_0 + (−1)^j X_{L/2} + 2·Re Σ_{0<k<L/2} X_k e^{2πijk/L}. The spectrum and the sequence share
/// one buffer of L + 2 floats. FFTW plans it without SIMD code, so that every x86-64 processor
/// rounds the same way (simulated pulse records are compared byte for byte across machines).
class RealInverseFft {
 public:
  explicit RealInverseFft(std::size_t size);
  ~RealInverseFft();
  RealInverseFft(const RealInverseFft&) = delete;
  RealInverseFft& operator=(const RealInverseFft&) = delete;

  [[nodiscard]] std::complex<float>* spectrum() noexcept { return reinterpret_cast<std::complex<float>*>(data_); }
  [[nodiscard]] float* values() noexcept { return data_; }
  [[nodiscard]] const float* values() const noexcept { return data_; }

  /// Transforms spectrum() into values(), overwriting it.
  void run();

  /// Bytes a transform of `size` points holds: its buffer and FFTW's plan (twiddle tables, which
  /// measured 0.5 to 1.5 times the buffer for sizes 2^a·3^b·5^c).
  [[nodiscard]] static std::size_t memory_bytes(std::size_t size) noexcept;

 private:
  float* data_ = nullptr;
  fftwf_plan_s* plan_ = nullptr;
};

}  // namespace rwcalc::detail
