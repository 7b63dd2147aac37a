// The simulator's inverse real FFT in four steps (src/sim/real_fft.hpp) against the defining sum in
// double, for table shapes with odd, even, square and degenerate sides, and the Nyquist bin's sign.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <random>
#include <vector>

#include "sim/real_fft.hpp"

namespace {

using rwcalc::detail::RealInverseFft;

// x_j = X_0 + (−1)^j X_{L/2} + 2·Re Σ_{0<k<L/2} X_k e^{2πijk/L}, summed in long double.
std::vector<double> defining_sum(const std::vector<std::complex<float>>& bins, std::size_t size) {
  std::vector<long double> cosine(size), sine(size);
  for (std::size_t i = 0; i < size; ++i) {
    const long double a =
        2.0L * std::numbers::pi_v<long double> * static_cast<long double>(i) / static_cast<long double>(size);
    cosine[i] = std::cos(a);
    sine[i] = std::sin(a);
  }
  std::vector<double> x(size);
  for (std::size_t j = 0; j < size; ++j) {
    long double s = bins[0].real() + (j % 2 == 0 ? 1.0L : -1.0L) * bins[size / 2].real();
    for (std::size_t k = 1; k < size / 2; ++k)
      s += 2.0L * (bins[k].real() * cosine[(j * k) % size] - bins[k].imag() * sine[(j * k) % size]);
    x[j] = static_cast<double>(s);
  }
  return x;
}

class RealFftShapes : public ::testing::TestWithParam<std::size_t> {};

TEST_P(RealFftShapes, EqualsTheDefiningSum) {
  const std::size_t size = GetParam();
  std::mt19937_64 gen(size);
  std::normal_distribution<float> normal;
  std::vector<std::complex<float>> bins(size / 2 + 1);
  for (auto& b : bins) b = {normal(gen), normal(gen)};
  RealInverseFft fft(size);
  std::size_t calls = 0;
  fft.set_spectrum([&](std::size_t k) {
    EXPECT_EQ(k, calls++) << "bins are drawn in order";
    return bins[k];
  });
  EXPECT_EQ(calls, size / 2 + 1);
  fft.run();
  const std::vector<double> want = defining_sum(bins, size);
  // Single precision: the error grows like √(L)·log L times float's 6e-8 of a bin.
  const double tolerance = 2e-6 * std::sqrt(static_cast<double>(size)) * std::log2(static_cast<double>(size) + 2);
  for (std::size_t j = 0; j < size; ++j) ASSERT_NEAR(fft.values()[j], want[j], tolerance) << "value " << j;
}

// L = 2M with M = M1·M2: 1×1, 1×3 (prime), 2×4, 3×4, 5×5, 4×4, 6×6, 12×20, 10×18, 48×50.
INSTANTIATE_TEST_SUITE_P(Tables, RealFftShapes, ::testing::Values(2, 6, 16, 24, 50, 32, 72, 480, 360, 4800));

TEST(RealFft, MemoryIsTheBufferAndLittleMore) {
  const std::size_t size = std::size_t{172800000};  // 24 h at 1 kHz, L = 2n
  const std::size_t buffer = sizeof(float) * size;
  EXPECT_GE(RealInverseFft::memory_bytes(size), buffer);
  EXPECT_LE(RealInverseFft::memory_bytes(size), buffer + buffer / 50);
}

}  // namespace
