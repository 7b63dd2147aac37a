#pragma once
/// @file progress.hpp
/// Progress of long work (ensembles, `allan --tau all`, large batches) on stderr.
///
/// Shown only when stderr is a terminal (rwcalc::stderr_is_terminal()), so pipes, files, CI logs
/// and tests stay clean; the line is redrawn in place (carriage return) at most ~8 times a
/// second and erased when the work ends. advance() is thread-safe and costs one atomic add
/// when nothing is redrawn. Typical use, one line per place:
///
///     rwcalc::Progress progress("diagnose: ensemble", runs);   // before the loop
///     progress.advance();                                       // once per finished item
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace rwcalc {

class Progress {
 public:
  /// A reporter for `total` items labelled `label`; shown when stderr is a terminal.
  Progress(std::string label, std::uint64_t total);
  /// Explicit sink (nullptr: show nothing); used by tests and by callers that decide themselves.
  Progress(std::string label, std::uint64_t total, std::FILE* sink);
  ~Progress();  ///< calls finish()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Count `n` more finished items (any thread).
  void advance(std::uint64_t n = 1) noexcept;
  /// Erase the progress line (idempotent). Later advance() calls draw nothing.
  void finish() noexcept;

  [[nodiscard]] bool enabled() const noexcept { return sink_ != nullptr; }
  [[nodiscard]] std::uint64_t done() const noexcept { return done_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t total() const noexcept { return total_; }

  /// The text of one progress line: "label: 12/50 (24%), 3.1 s, ~9.8 s left".
  [[nodiscard]] static std::string format_line(const std::string& label, std::uint64_t done,
                                               std::uint64_t total, double elapsed_s);

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
