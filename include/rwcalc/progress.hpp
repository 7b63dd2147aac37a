#pragma once
/// @file progress.hpp
/// Progress of long work on stderr, shown only when stderr is a terminal (pipes, logs and tests
/// stay clean): one line redrawn in place at most ~8 times a second and erased at the end.
/// advance() is thread-safe and costs one atomic add when nothing is redrawn.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace rwcalc {

class Progress {
 public:
  Progress(std::string label, std::uint64_t total);
  /// Explicit sink (nullptr: show nothing).
  Progress(std::string label, std::uint64_t total, std::FILE* sink);
  ~Progress();  ///< calls finish()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(std::uint64_t n = 1) noexcept;
  /// Erase the line (idempotent); later advance() calls draw nothing.
  void finish() noexcept;

  [[nodiscard]] bool enabled() const noexcept { return sink_ != nullptr; }
  [[nodiscard]] std::uint64_t done() const noexcept { return done_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t total() const noexcept { return total_; }

  /// "label: 12/50 (24%), 3.1 s, ~9.8 s left".
  [[nodiscard]] static std::string format_line(const std::string& label, std::uint64_t done, std::uint64_t total,
                                               double elapsed_s);

 private:
  void draw(std::uint64_t done) noexcept;

  using Clock = std::chrono::steady_clock;
  std::string label_;
  std::uint64_t total_ = 0;
  std::FILE* sink_ = nullptr;
  Clock::time_point start_;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> next_draw_ns_{0};  // since start_
  std::mutex mu_;
  bool drawn_ = false;
  bool finished_ = false;
  std::size_t width_ = 0;  // characters of the last line drawn
};

}  // namespace rwcalc
