// FFTW's short in-place transforms arranged as one long inverse real transform (real_fft.hpp).
// FFTW, not Eigen's kissfft, because it transforms in single precision in place; in four steps
// because FFTW's plan of one transform of 10^8 points held 0.9 times the buffer besides it.
#include "real_fft.hpp"

#include <fftw3.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <numbers>
#include <stdexcept>

namespace rwcalc::detail {

namespace {

// FFTW's planner is not thread-safe; simulators are made side by side (simulate_ensemble).
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

// The divisor of m nearest √m from below: the four steps' rows are then as short as its columns.
std::size_t row_length(std::size_t m) {
  std::size_t best = 1;
  for (std::size_t d = 1; d * d <= m; ++d)
    if (m % d == 0) best = d;
  return best;
}

// Twiddle factors along a row are advanced by one multiplication and recomputed exactly this often,
// so that their rounding does not accumulate.
constexpr std::size_t kReseed = 64;

struct Rotor {
  double re = 1, im = 0;
  static Rotor at(double angle) { return {std::cos(angle), std::sin(angle)}; }
  void advance(const Rotor& by) {
    const double r = re * by.re - im * by.im;
    im = re * by.im + im * by.re;
    re = r;
  }
};

// Z_k = (X_k + X̄_{M−k}) + i·w·(X_k − X̄_{M−k}) with w = e^{iπk/M}, and Z_{M−k} likewise with
// w' = −w̄: the spectrum of the even values (real part) and of the odd values (imaginary part).
void combine(std::complex<float>& xk, std::complex<float>& xmk, const Rotor& w) {
  const double ar = xk.real(), ai = xk.imag(), br = xmk.real(), bi = xmk.imag();
  // k: sum (ar + br, ai − bi), difference (ar − br, ai + bi); M−k: sum (br + ar, bi − ai),
  // difference (br − ar, bi + ai).
  const double dr = ar - br, di = ai + bi;
  const double zk_re = ar + br - (w.re * di + w.im * dr), zk_im = ai - bi + (w.re * dr - w.im * di);
  // w' = (−w.re, w.im), difference' = (−dr, di).
  const double zm_re = br + ar - (-w.re * di - w.im * dr), zm_im = bi - ai + (w.re * dr - w.im * di);
  xmk = {static_cast<float>(zm_re), static_cast<float>(zm_im)};
  xk = {static_cast<float>(zk_re), static_cast<float>(zk_im)};
}

fftwf_plan plan(std::ptrdiff_t n, std::ptrdiff_t stride, std::ptrdiff_t count, std::ptrdiff_t distance,
                std::complex<float>* data) {
  const fftwf_iodim64 dim{n, stride, stride}, loop{count, distance, distance};
  auto* d = reinterpret_cast<fftwf_complex*>(data);
  // FFTW_ESTIMATE: planning by measurement would time transforms and could choose differently on
  // another machine; FFTW_NO_SIMD: SIMD codelets (SSE2, AVX, AVX-512, chosen by the processor) add in
  // other orders. The 64-bit interface: a buffer may pass 2^31 points.
  return fftwf_plan_guru64_dft(1, &dim, 1, &loop, d, d, FFTW_BACKWARD, FFTW_ESTIMATE | FFTW_NO_SIMD);
}

}  // namespace

RealInverseFft::RealInverseFft(std::size_t size) : m_(size / 2) {
  if (size < 2 || size % 2 != 0 || size > static_cast<std::size_t>(std::numeric_limits<std::ptrdiff_t>::max()) / 8)
    throw std::length_error("RealInverseFft: the size must be even, positive and addressable");
  m1_ = row_length(m_);
  m2_ = m_ / m1_;
  staged_.resize(std::min(kStagedRows, m1_) * m2_);
  data_ = static_cast<std::complex<float>*>(fftwf_malloc(sizeof(std::complex<float>) * m_));
  if (data_ == nullptr) throw std::bad_alloc();
  const auto m1 = static_cast<std::ptrdiff_t>(m1_), m2 = static_cast<std::ptrdiff_t>(m2_);
  const std::lock_guard lock(planner_mutex());
  rows_plan_ = plan(m1, 1, m2, m1, data_);
  columns_plan_ = plan(m2, m1, m1, 1, data_);
  if (rows_plan_ == nullptr || columns_plan_ == nullptr) {
    if (rows_plan_ != nullptr) fftwf_destroy_plan(rows_plan_);
    fftwf_free(data_);
    throw std::bad_alloc();
  }
}

RealInverseFft::~RealInverseFft() {
  {
    const std::lock_guard lock(planner_mutex());
    fftwf_destroy_plan(rows_plan_);
    fftwf_destroy_plan(columns_plan_);
  }
  fftwf_free(data_);
}

void RealInverseFft::store_staged(std::size_t first, std::size_t rows) noexcept {
  for (std::size_t k2 = 0; k2 < m2_; ++k2)
    for (std::size_t r = 0; r < rows; ++r) data_[first + r + m1_ * k2] = staged_[r * m2_ + k2];
}

// Bin k = M2·k1 + k2 sits at k1 + M1·k2. Its partner M − k: for k2 = 0, column M1 − k1 of row 0
// (column 0's is the Nyquist bin); otherwise column M1 − 1 − k1 of row M2 − k2.
void RealInverseFft::pair_bins() noexcept {
  const double angle_per_bin = std::numbers::pi / static_cast<double>(m_);
  data_[0] = {data_[0].real() + nyquist_, data_[0].real() - nyquist_};
  for (std::size_t c = 1; 2 * c <= m1_; ++c)
    combine(data_[c], data_[m1_ - c], Rotor::at(angle_per_bin * static_cast<double>(m2_ * c)));
  const Rotor along = Rotor::at(angle_per_bin * static_cast<double>(m2_));
  for (std::size_t k2 = 1; 2 * k2 <= m2_; ++k2) {
    std::complex<float>* row = data_ + m1_ * k2;
    std::complex<float>* partner = data_ + m1_ * (m2_ - k2);
    const std::size_t columns = 2 * k2 == m2_ ? (m1_ + 1) / 2 : m1_;
    Rotor w;
    for (std::size_t c = 0; c < columns; ++c, w.advance(along)) {
      if (c % kReseed == 0) w = Rotor::at(angle_per_bin * static_cast<double>(m2_ * c + k2));
      combine(row[c], partner[m1_ - 1 - c], w);
    }
  }
}

// After the rows' transforms, element j1 of row k2 is multiplied by e^{2πi·j1·k2/M}.
void RealInverseFft::twiddle() noexcept {
  const double angle_per_step = 2 * std::numbers::pi / static_cast<double>(m_);
  for (std::size_t k2 = 1; k2 < m2_; ++k2) {
    std::complex<float>* row = data_ + m1_ * k2;
    const Rotor along = Rotor::at(angle_per_step * static_cast<double>(k2));
    Rotor w;
    for (std::size_t j1 = 0; j1 < m1_; ++j1, w.advance(along)) {
      if (j1 % kReseed == 0) w = Rotor::at(angle_per_step * static_cast<double>((j1 * k2) % m_));
      const double re = row[j1].real(), im = row[j1].imag();
      row[j1] = {static_cast<float>(re * w.re - im * w.im), static_cast<float>(re * w.im + im * w.re)};
    }
  }
}

void RealInverseFft::run() {
  pair_bins();
  fftwf_execute(rows_plan_);
  twiddle();
  fftwf_execute(columns_plan_);
}

std::size_t RealInverseFft::memory_bytes(std::size_t size) noexcept {
  const std::size_t m = size / 2, m1 = row_length(m), m2 = m / m1;
  // FFTW's plans of the short transforms: tables and buffers of a few times their lengths.
  constexpr std::size_t kPlans = std::size_t{1} << 20;
  return sizeof(std::complex<float>) * (m + kStagedRows * m2 + 8 * (m1 + m2)) + kPlans;
}

}  // namespace rwcalc::detail
