// The flicker increments' circulant eigenvalues in closed form (src/sim/flicker_circulant.hpp)
// against the FFT of the autocovariance in double, and against long-double sums where the FFT's
// own rounding (about 1e-15 absolute) is too coarse: at the lowest k of long circulants.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "sim/flicker_circulant.hpp"

namespace {

using rwcalc::detail::FlickerCirculant;

double gamma_at(std::size_t h) {
  const auto hd = static_cast<double>(h);
  return 4.0 / (std::numbers::pi * (1.0 - 4.0 * hd * hd));
}

// λ_k by FFT of the circulant's first row, as the simulator computed them before.
std::vector<double> fft_eigenvalues(std::size_t size) {
  const std::size_t half = size / 2;
  std::vector<double> row(size, 0.0);
  for (std::size_t h = 0; h <= half; ++h) {
    row[h] = gamma_at(h);
    if (h > 0 && h < half) row[size - h] = row[h];
  }
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, row);
  std::vector<double> lambda(half + 1);
  for (std::size_t k = 0; k <= half; ++k) lambda[k] = spectrum[k].real();
  return lambda;
}

// λ_k as the circulant's sum in long double, compensated, with hk reduced mod L exactly.
long double direct_eigenvalue(std::size_t size, std::size_t k) {
  const std::size_t half = size / 2;
  long double sum = 0.0L, carry = 0.0L;
  for (std::size_t h = 0; h <= half; ++h) {
    const auto hd = static_cast<long double>(h);
    const long double g = 4.0L / (std::numbers::pi_v<long double> * (1.0L - 4.0L * hd * hd));
    const auto r = static_cast<long double>((h * k) % size);
    const long double weight = h == 0 || h == half ? 1.0L : 2.0L;
    // Beyond h = 2^16 the terms are below 1e-10: a cosine in double is then exact enough, and quicker.
    const long double angle = 2.0L * std::numbers::pi_v<long double> * r / static_cast<long double>(size);
    const long double cosine = h < 65536 ? std::cos(angle) : std::cos(static_cast<double>(angle));
    const long double term = weight * g * cosine;
    const long double y = term - carry;
    const long double t = sum + y;
    carry = (t - sum) - y;
    sum = t;
  }
  return sum;
}

// Sizes: tiny ones (the tail summed term by term), and 2^a·3^b·5^c ones as good_fft_size makes
// them, up to 2^22.
const std::size_t kSizes[] = {2, 6, 10, 64, 510, 514, 4096, 76800, 1492992, 4050000, 4194304};

TEST(FlickerCirculant, EigenvaluesMatchTheFftOfTheAutocovariance) {
  for (const std::size_t size : kSizes) {
    const FlickerCirculant circulant(size);
    const std::vector<double> reference = fft_eigenvalues(size);
    double worst = 0.0;
    for (std::size_t k = 0; k < reference.size(); ++k) {
      const double lambda = circulant.eigenvalue(k);
      ASSERT_GT(lambda, 0.0) << "L = " << size << ", k = " << k;
      // 1e-15: the FFT's own rounding (ε·Σ|γ(h)|·log₂ L), which is 2e-10 of λ_1 at 2^22.
      ASSERT_NEAR(lambda, reference[k], 1e-10 * reference[k] + 1e-15) << "L = " << size << ", k = " << k;
      worst = std::max(worst, std::abs(lambda / reference[k] - 1.0));
    }
    RecordProperty("worst_relative_vs_fft_L" + std::to_string(size), std::to_string(worst));
  }
}

TEST(FlickerCirculant, LowEigenvaluesMatchLongDoubleSumsToOneInATrillion) {
  for (const std::size_t size : kSizes) {
    const FlickerCirculant circulant(size);
    const std::size_t half = size / 2;
    std::vector<std::size_t> ks{0, 1, 2, 3, 7, 100};
    if (size < 100000) ks.insert(ks.end(), {half / 3, half});  // the FFT checks the rest well
    for (const std::size_t k : ks) {
      if (k > half) continue;
      const long double reference = direct_eigenvalue(size, k);
      EXPECT_LT(std::abs(static_cast<double>((circulant.eigenvalue(k) - reference) / reference)), 1e-12)
          << "L = " << size << ", k = " << k;
    }
  }
}

TEST(FlickerCirculant, TheLowestEigenvalueOfSixHoursAtOneKilohertzIsExact) {
  // L = 2·21.6e6: λ_1 = 1.42e-7, 2.4 % below the increments' PSD 2 sin(π/L) (the circulant's tail).
  const std::size_t size = 43200000;
  const long double reference = direct_eigenvalue(size, 1);
  EXPECT_LT(std::abs(static_cast<double>((FlickerCirculant(size).eigenvalue(1) - reference) / reference)), 1e-12);
  EXPECT_LT(reference, 0.98L * 2.0L * std::sin(std::numbers::pi_v<long double> / size));
}

}  // namespace
