#pragma once
// The memory the reader holds for a record, against the memory ceiling (rwcalc/memory.hpp). Every
// vector that grows with the record grows here, by doubling, and only while the new block fits
// beside everything already held (the old block included, which is freed once copied): the
// reader's peak memory never passes the ceiling. A growth that cannot fit throws CeilingReached,
// which the reader turns into an error naming the file, the line and the memory needed.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace rwcalc::detail {

/// Thrown when a vector cannot grow within the ceiling.
struct CeilingReached {};

class SampleMemory {
 public:
  explicit SampleMemory(std::size_t ceiling) : ceiling_(ceiling) {}

  /// Append `x` to `v`, growing it within the ceiling.
  template <class T>
  void keep(std::vector<T>& v, const T& x) {
    if (v.size() == v.capacity()) [[unlikely]]
      grow(v, std::max<std::size_t>(2 * v.capacity(), kFirstBytes / sizeof(T)));
    v.push_back(x);
  }

  /// Room for `n` more elements in `v`, or for as many as fit; CeilingReached when none is left.
  template <class T>
  void make_room(std::vector<T>& v, std::size_t n) {
    if (v.capacity() - v.size() < n) grow(v, std::max(v.size() + n, 2 * v.capacity()));
  }

  /// Room for `n` elements in `v` at once (an estimate of the record: up to what fits, and never
  /// an error).
  template <class T>
  void reserve(std::vector<T>& v, std::size_t n) {
    const std::size_t fits = room() / sizeof(T);
    if (std::min(n, fits) > v.capacity()) grow(v, std::min(n, fits));
  }

  /// Bytes held by the vectors grown here.
  [[nodiscard]] std::size_t held() const noexcept { return held_; }
  [[nodiscard]] std::size_t ceiling() const noexcept { return ceiling_; }

 private:
  static constexpr std::size_t kFirstBytes = std::size_t{1} << 16;

  // Bytes a new block may take while the old one is still held.
  [[nodiscard]] std::size_t room() const noexcept { return ceiling_ > held_ ? ceiling_ - held_ : 0; }

  // Grow `v` to `wanted` elements, or to what fits when that is more than it holds now.
  template <class T>
  void grow(std::vector<T>& v, std::size_t wanted) {
    const std::size_t old = v.capacity() * sizeof(T);
    const std::size_t n = std::min(wanted, room() / sizeof(T));
    if (n <= v.capacity()) throw CeilingReached{};
    v.reserve(n);
    held_ += v.capacity() * sizeof(T) - old;
  }

  std::size_t ceiling_;
  std::size_t held_ = 0;
};

}  // namespace rwcalc::detail
