// The spectral-line search of analyze (src/analysis/spectral_lines.cpp) on records long enough for
// its spread windows: a record of 64 whole Welch windows or more takes 64, spread evenly from its
// start to its end, so a line present in the record's last part only is found, with the share of
// its power that part carries.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "analysis/spectral_lines.hpp"

namespace {

/// Angle record (phase units, τ0 = 0.01 s) of white rate noise of unit variance per sample, with a
/// rate line of amplitude `amp` at `f` Hz over the samples from `from` on.
rwcalc::PhaseSeries record(std::size_t n, double f, double amp, std::size_t from, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  rwcalc::PhaseSeries x;
  x.tau0_s = 0.01;
  x.values.resize(n + 1);
  double angle = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double rate = z(g);
    if (i >= from) rate += amp * std::sin(2 * std::numbers::pi * f * static_cast<double>(i) * x.tau0_s);
    angle += rate * x.tau0_s;
    x.values[i + 1] = angle;
  }
  return x;
}

TEST(SpectralLines, ADayLongRecordsWindowsSpanItsWholeLength) {
  // 100 windows of 2^16 samples: the first 64 end at 64 % of the record; the line is in its last
  // 10 %, where 6 or 7 of the 64 spread windows lie.
  const std::size_t n = std::size_t{100} << 16, from = n - n / 10;
  const double amp = 2.0;  // rate units; mean power amp²/2 over the tenth of the record that has it
  const rwcalc::PhaseSeries x = record(n, 3.1, amp, from, 7);
  const auto lines = rwcalc::find_spectral_lines(x);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NEAR(lines[0].f_hz, 3.1, 2.0 / (65536 * x.tau0_s));
  // The rate's PSD is in (rate unit)²/Hz; the line's share of the windows is 6/64 … 7/64.
  const double share = lines[0].power / (amp * amp / 2);
  EXPECT_GT(share, 0.06);
  EXPECT_LT(share, 0.14);
}

TEST(SpectralLines, NoLineInWhiteNoiseOfADayLongRecord) {
  const std::size_t n = std::size_t{100} << 16;
  EXPECT_TRUE(rwcalc::find_spectral_lines(record(n, 3.1, 0.0, n, 8)).empty());
}

}  // namespace
