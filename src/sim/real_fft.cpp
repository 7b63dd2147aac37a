// FFTW's in-place inverse real transform (real_fft.hpp). FFTW, not Eigen's kissfft, because it
// transforms a real sequence in single precision in place with a plan of about the buffer's size:
// kissfft needs a second, complex buffer and a full complex work space (docs/simulation.md).
#include "real_fft.hpp"

#include <fftw3.h>

#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>

namespace rwcalc::detail {

namespace {

// FFTW's planner is not thread-safe; simulators are made side by side (simulate_ensemble).
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

RealInverseFft::RealInverseFft(std::size_t size) {
  if (size % 2 != 0 || size > static_cast<std::size_t>(std::numeric_limits<std::ptrdiff_t>::max()) / 8)
    throw std::length_error("RealInverseFft: the size must be even and addressable");
  data_ = static_cast<float*>(fftwf_malloc(sizeof(float) * (size + 2)));
  if (data_ == nullptr) throw std::bad_alloc();
  const std::lock_guard lock(planner_mutex());
  // FFTW_ESTIMATE: planning by measurement would time transforms and could choose differently on
  // another machine; FFTW_NO_SIMD: SIMD codelets (SSE2, AVX, AVX-512, chosen by the processor) add in
  // other orders.
  // The 64-bit interface: a record of more than 2^30 samples needs more than an int's 2^31 points.
  fftwf_iodim64 dim{static_cast<std::ptrdiff_t>(size), 1, 1};
  plan_ = fftwf_plan_guru64_dft_c2r(1, &dim, 0, nullptr, reinterpret_cast<fftwf_complex*>(data_), data_,
                                    FFTW_ESTIMATE | FFTW_NO_SIMD);
  if (plan_ == nullptr) {
    fftwf_free(data_);
    throw std::bad_alloc();
  }
}

RealInverseFft::~RealInverseFft() {
  {
    const std::lock_guard lock(planner_mutex());
    fftwf_destroy_plan(plan_);
  }
  fftwf_free(data_);
}

void RealInverseFft::run() { fftwf_execute(plan_); }

std::size_t RealInverseFft::memory_bytes(std::size_t size) noexcept {
  const std::size_t buffer = sizeof(float) * (size + 2);
  return buffer + buffer * 3 / 2;
}

}  // namespace rwcalc::detail
