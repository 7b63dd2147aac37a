#pragma once
/// @file random.hpp
/// Reproducible random numbers: every draw is a fixed function of the seed. The engine is
/// xoshiro256++ seeded through SplitMix64; the uniform and normal samplers are our own (the
/// std distributions are implementation-defined); normals come from a 256-layer ziggurat
/// (Marsaglia & Tsang 2000). Each noise term draws from its own stream (derive_seed), so adding
/// a term does not change the others, and nothing depends on the thread count.
#include <array>
#include <cstddef>
#include <cstdint>

namespace rwcalc {

/// Seed of stream `stream` derived from the user's `seed` (distinct streams are unrelated).
[[nodiscard]] std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) noexcept;

class Rng {
 public:
  explicit Rng(std::uint64_t seed) noexcept;
  Rng(std::uint64_t seed, std::uint64_t stream) noexcept : Rng(derive_seed(seed, stream)) {}

  /// Next raw output of xoshiro256++.
  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform on [0, 1) with 53 random bits.
  double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Standard normal by the ziggurat (exact: rejection, wedge and tail handled).
  double normal() noexcept;
  /// out[0..n) ~ N(0, sigma²).
  void fill_normal(double* out, std::size_t n, double sigma) noexcept;

 private:
  static constexpr std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  double normal_slow(double u, int i) noexcept;
  std::array<std::uint64_t, 4> s_{};
};

}  // namespace rwcalc
