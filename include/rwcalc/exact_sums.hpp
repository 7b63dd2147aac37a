#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/exact_sums.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file exact_sums.hpp
/// Exact sums of integers, their squares and lag-1 products, a block at a time: in 64-bit registers
/// when the block's values are small enough for that to be exact, else again in 128 bits. Integer
/// sums do not depend on their order: the result is the same however the work is split.
#include <cstddef>
#include <cstdint>

namespace rwcalc {

__extension__ typedef __int128 i128;
__extension__ typedef unsigned __int128 u128;

/// Values per block at most: with every |v| < 2^26 the block's squares (< 2^52 each) and lag
/// products sum below 2^62.
inline constexpr std::size_t kExactBlock = 1024;

/// Σv, Σv², Σv_i·v_{i+1} modulo 2^128 (no undefined overflow): exact as i128 within ±2^127.
struct ExactSums {
  u128 sum = 0, squares = 0, lag = 0;
};

enum class SumKinds { Squares, ValuesAndSquares, WithLag };  ///< the sums a block adds

/// Adds the sums of v(0) … v(n − 1), n ≤ kExactBlock, and with WithLag Σ_{i<pairs} v(i)·v(i+1)
/// (pairs ≤ n), to `s`. v(i) is the signed value modulo 2^64, read twice for a large block (a
/// cheap pure function). True when every value read lay within ±2^26 (the 64-bit path).
template <SumKinds Kinds, class V>
bool add_exact_sums(std::size_t n, std::size_t pairs, const V& v, ExactSums& s) {
  constexpr bool kValues = Kinds != SumKinds::Squares, kLag = Kinds == SumKinds::WithLag;
  std::uint64_t s1 = 0, s2 = 0, lag = 0, range = 0;  // modulo 2^64
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t d = v(i);
    range |= d + (std::uint64_t{1} << 26);  // below 2^27 for all d iff every −2^26 ≤ d < 2^26
    if constexpr (kValues) s1 += d;
    s2 += d * d;
  }
  if constexpr (kLag) {
    if (pairs == n && n > 0) range |= v(n) + (std::uint64_t{1} << 26);
    for (std::size_t i = 0; i < pairs; ++i) lag += v(i) * v(i + 1);
  }
  const auto wide = [](std::uint64_t x) { return static_cast<u128>(static_cast<i128>(static_cast<std::int64_t>(x))); };
  if ((range >> 27) == 0) {
    if constexpr (kValues) s.sum += wide(s1);
    s.squares += s2;
    if constexpr (kLag) s.lag += wide(lag);
    return true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (kValues) s.sum += wide(v(i));
    s.squares += wide(v(i)) * wide(v(i));
  }
  if constexpr (kLag)
    for (std::size_t i = 0; i < pairs; ++i) s.lag += wide(v(i)) * wide(v(i + 1));
  return false;
}

}  // namespace rwcalc
