#pragma once
/// @file progress.hpp
/// Progress of long work on a terminal: one line saying what is being done, how far it is and the
/// time left, drawn when the work starts, redrawn in place at most ~8 times a second and erased at
/// the end. It goes only to the sink the command line chooses (standard error when that is a
/// terminal and --quiet is not given), so pipes, logs and tests stay clean. advance() is
/// thread-safe and costs one atomic add when nothing is redrawn.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace rwcalc {

class Progress {
 public:
  /// How far the work is, as shown: a count ("12/50 (24%)"), bytes ("12.5/43.2 MB (28%)", in kB,
  /// MB or GB by the total; with an unknown total, a pipe, "12.5 MB") or the share alone ("35%").
  enum class Measure { Items, Bytes, Percent };

  /// `label` says what is being done, in the output's language; a file name in it goes through
  /// printable(). `total` 0: unknown; a count that passes its total (which was then an estimate)
  /// is shown alone, without a share or the time left. No sink (nullptr) shows nothing; neither does a Progress made
  /// inside an item of a parallel_for running on several threads: the loop's own line, if any,
  /// says how far the work is, and the items' lines would overwrite each other.
  Progress(std::string label, std::uint64_t total, std::FILE* sink, Measure measure = Measure::Items);
  ~Progress();  ///< calls finish()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(std::uint64_t n = 1) noexcept;
  /// Erase the line (idempotent); later advance() calls draw nothing.
  void finish() noexcept;

  [[nodiscard]] bool enabled() const noexcept { return sink_ != nullptr; }
  [[nodiscard]] std::uint64_t done() const noexcept { return done_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t total() const noexcept { return total_; }

  /// "label: 12/50 (24%), 3.1 s, ~9.8 s left", in the current language.
  [[nodiscard]] static std::string format_line(const std::string& label, std::uint64_t done, std::uint64_t total,
                                               double elapsed_s, Measure measure = Measure::Items);
  /// `text` in at most `columns` characters (UTF-8 characters, not bytes): when longer, its middle
  /// gives way to "…", so that the verb at the start and the file name at the end stay. A line
  /// wider than the terminal would wrap, and "\r" returns only to the start of its last row.
  [[nodiscard]] static std::string fit_to_width(const std::string& text, std::size_t columns);

 private:
  void draw(std::uint64_t done) noexcept;

  using Clock = std::chrono::steady_clock;
  std::string label_;
  std::uint64_t total_ = 0;
  std::FILE* sink_ = nullptr;
  Measure measure_ = Measure::Items;
  Clock::time_point start_;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> next_draw_ns_{0};  // since start_
  std::mutex mu_;
  bool drawn_ = false;
  bool finished_ = false;
  std::size_t width_ = 0;  // characters of the last line drawn
};

}  // namespace rwcalc
