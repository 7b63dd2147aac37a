// Power spectra of real sequences (src/fft.cpp): the four-step transform of long sequences against
// kissfft's direct transform and against the DFT summed in long double at chosen bins; small
// transforms are kissfft's own.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <stdexcept>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "rwcalc/fft.hpp"

namespace {

using rwcalc::detail::RealPowerSpectrum;

std::vector<double> noisy_lines(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  std::vector<double> x(n);
  for (std::size_t t = 0; t < n; ++t)
    x[t] =
        z(g) + 40.0 * std::cos(0.0123 * static_cast<double>(t) + 0.4) + 3.0 * std::sin(2.71 * static_cast<double>(t));
  return x;
}

std::vector<double> kiss_power(const std::vector<double>& x, std::size_t nfft) {
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> buf(nfft, 0.0);
  std::copy(x.begin(), x.end(), buf.begin());
  std::vector<std::complex<double>> spec;
  fft.fwd(spec, buf);
  std::vector<double> p(nfft / 2 + 1);
  for (std::size_t k = 0; k < p.size(); ++k) p[k] = std::norm(spec[k]);
  return p;
}

long double direct_power(const std::vector<double>& x, std::size_t nfft, std::size_t k) {
  long double re = 0, im = 0;
  for (std::size_t t = 0; t < x.size(); ++t) {
    const long double ph = -2.0L * std::numbers::pi_v<long double> * static_cast<long double>((t * k) % nfft) /
                           static_cast<long double>(nfft);
    re += x[t] * std::cos(ph);
    im += x[t] * std::sin(ph);
  }
  return re * re + im * im;
}

TEST(RealPowerSpectrum, FourStepsAgreeWithKissfftAndTheDirectSum) {
  // 2^18 and 2^19 points (square and oblong splits), the data filling 0.7 of the transform; a tone
  // far above the noise, one near it, and the noise floor must all agree.
  for (const std::size_t nfft : {std::size_t{1} << 18, std::size_t{1} << 19}) {
    ASSERT_GE(nfft, RealPowerSpectrum::kFourStepFrom);
    const auto x = noisy_lines(nfft * 7 / 10, nfft);
    RealPowerSpectrum s(nfft);
    std::vector<double> p(nfft / 2 + 1, 0.0);
    s.add(x.data(), x.size(), p.data());
    const auto ref = kiss_power(x, nfft);
    double top = 0;
    for (const double v : ref) top = std::max(top, v);
    for (std::size_t k = 0; k < p.size(); ++k) ASSERT_NEAR(p[k], ref[k], 1e-11 * top) << "bin " << k << " of " << nfft;
    for (const std::size_t k :
         {std::size_t{0}, std::size_t{1}, std::size_t{513}, nfft / 4 + 3, nfft / 2 - 1, nfft / 2}) {
      const long double d = direct_power(x, nfft, k);
      EXPECT_NEAR(p[k], static_cast<double>(d), 1e-10 * top) << "bin " << k;
    }
    // add() accumulates: a second sequence's power is added bin by bin.
    const auto y = noisy_lines(nfft / 3, nfft + 1);
    s.add(y.data(), y.size(), p.data());
    const auto ref_y = kiss_power(y, nfft);
    for (std::size_t k = 0; k < p.size(); k += 97) ASSERT_NEAR(p[k], ref[k] + ref_y[k], 1e-11 * top) << k;
  }
}

TEST(RealPowerSpectrum, SmallTransformsAreKissfftsBitForBit) {
  const auto x = noisy_lines(3000, 5);
  RealPowerSpectrum s(8192);
  std::vector<double> p(4097, 0.0);
  s.add(x.data(), x.size(), p.data());
  EXPECT_EQ(p, kiss_power(x, 8192));
}

TEST(RealPowerSpectrum, RejectsBadSizes) {
  EXPECT_THROW(RealPowerSpectrum(3000), std::invalid_argument);
  EXPECT_THROW(RealPowerSpectrum(2), std::invalid_argument);
  RealPowerSpectrum s(1024);
  std::vector<double> x(1025, 1.0), p(513, 0.0);
  EXPECT_THROW(s.add(x.data(), x.size(), p.data()), std::invalid_argument);
}

}  // namespace
