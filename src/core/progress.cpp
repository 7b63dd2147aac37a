// Progress lines on stderr for long work (see progress.hpp).
#include "rwcalc/progress.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "rwcalc/output.hpp"

namespace rwcalc {

namespace {
constexpr std::int64_t kRedrawNs = 125'000'000;  // at most 8 redraws per second
}

Progress::Progress(std::string label, std::uint64_t total)
    : Progress(std::move(label), total, stderr_is_terminal() ? stderr : nullptr) {}

Progress::Progress(std::string label, std::uint64_t total, std::FILE* sink)
    : label_(std::move(label)), total_(total), sink_(sink), start_(Clock::now()) {}

Progress::~Progress() { finish(); }

std::string Progress::format_line(const std::string& label, std::uint64_t done, std::uint64_t total, double elapsed_s) {
  std::string line = fmt::format("{}: {}/{}", label, done, total);
  if (total > 0) line += fmt::format(" ({}%)", done * 100 / total);
  line += fmt::format(", {:.1f} s", elapsed_s);
  if (done > 0 && done < total) {
    const double left = elapsed_s * static_cast<double>(total - done) / static_cast<double>(done);
    line += fmt::format(", ~{:.1f} s left", left);
  }
  return line;
}

void Progress::advance(std::uint64_t n) noexcept {
  const std::uint64_t now_done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!sink_) return;
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_).count();
  std::int64_t due = next_draw_ns_.load(std::memory_order_relaxed);
  // One thread wins the right to redraw; the others return at once.
  if (ns < due || !next_draw_ns_.compare_exchange_strong(due, ns + kRedrawNs)) return;
  draw(now_done);
}

void Progress::draw(std::uint64_t done) noexcept {
  try {
    std::lock_guard<std::mutex> lock(mu_);
    if (finished_) return;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    std::string line = format_line(label_, std::min(done, total_), total_, elapsed);
    const std::size_t w = line.size();
    if (w < width_) line.append(width_ - w, ' ');  // wipe the tail of a longer previous line
    width_ = w;
    std::fprintf(sink_, "\r%s", line.c_str());
    std::fflush(sink_);
    drawn_ = true;
  } catch (...) {
    // Progress is cosmetic: never let it fail the work.
  }
}

void Progress::finish() noexcept {
  try {
    std::lock_guard<std::mutex> lock(mu_);
    if (finished_) return;
    finished_ = true;
    if (sink_ && drawn_) {
      std::fprintf(sink_, "\r%s\r", std::string(width_, ' ').c_str());
      std::fflush(sink_);
    }
  } catch (...) {
  }
}

}  // namespace rwcalc
