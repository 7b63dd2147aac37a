#include "rwcalc/random.hpp"

#include <cmath>

namespace rwcalc {

namespace {

// Ziggurat tables for the standard normal, 256 layers of equal area v (Marsaglia & Tsang 2000).
struct Ziggurat {
  static constexpr int kLayers = 256;
  static constexpr double kR = 3.6541528853610088;  // start of the tail
  static constexpr double kV = 0.00492867323399;    // area of each layer
  double x[kLayers + 1];
  double ratio[kLayers];  // x[i+1]/x[i]: the fast-accept bound
  Ziggurat() {
    const double f = std::exp(-0.5 * kR * kR);
    x[0] = kV / f;
    x[1] = kR;
    for (int i = 2; i < kLayers; ++i)
      x[i] = std::sqrt(-2.0 * std::log(kV / x[i - 1] + std::exp(-0.5 * x[i - 1] * x[i - 1])));
    x[kLayers] = 0.0;
    for (int i = 0; i < kLayers; ++i) ratio[i] = x[i + 1] / x[i];
  }
};

const Ziggurat& zig() {
  static const Ziggurat z;
  return z;
}

/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix.
std::uint64_t splitmix64_mix(std::uint64_t z) noexcept {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) noexcept {
  return splitmix64_mix(splitmix64_mix(seed) ^ splitmix64_mix(stream + 0x5851f42d4c957f2dULL));
}

Rng::Rng(std::uint64_t seed) noexcept {
  // SplitMix64 expands the seed into the 256-bit state (never all zero).
  std::uint64_t z = seed;
  for (auto& w : s_) {
    z += 0x9e3779b97f4a7c15ULL;
    w = splitmix64_mix(z - 0x9e3779b97f4a7c15ULL);
  }
}

double Rng::normal() noexcept {
  const auto& z = zig();
  const std::uint64_t bits = next();
  const int i = static_cast<int>(bits & 0xff);
  // 53 high bits give u uniform on [−1, 1).
  const double u = static_cast<double>(bits >> 11) * 0x1.0p-52 - 1.0;
  if (std::abs(u) < z.ratio[i]) return u * z.x[i];
  return normal_slow(u, i);
}

double Rng::normal_slow(double u, int i) noexcept {
  const auto& z = zig();
  while (true) {
    if (i == 0) {
      // Tail beyond r (Marsaglia 1964).
      double xt = 0.0, yt = 0.0;
      do {
        xt = -std::log1p(-uniform()) / Ziggurat::kR;
        yt = -std::log1p(-uniform());
      } while (2.0 * yt < xt * xt);
      return u < 0 ? -(Ziggurat::kR + xt) : Ziggurat::kR + xt;
    }
    const double xv = u * z.x[i];
    const double f0 = std::exp(-0.5 * (z.x[i] * z.x[i] - xv * xv));
    const double f1 = std::exp(-0.5 * (z.x[i + 1] * z.x[i + 1] - xv * xv));
    if (f1 + uniform() * (f0 - f1) < 1.0) return xv;
    const std::uint64_t bits = next();
    i = static_cast<int>(bits & 0xff);
    u = static_cast<double>(bits >> 11) * 0x1.0p-52 - 1.0;
    if (std::abs(u) < z.ratio[i]) return u * z.x[i];
  }
}

void Rng::fill_normal(double* out, std::size_t n, double sigma) noexcept {
  for (std::size_t i = 0; i < n; ++i) out[i] = sigma * normal();
}

}  // namespace rwcalc
