// Progress lines on a terminal for long work (see progress.hpp).
#include "rwcalc/progress.hpp"

#include <fmt/format.h>
#include <sys/ioctl.h>

#include <algorithm>

#include "rwcalc/i18n.hpp"
#include "rwcalc/parallel.hpp"

namespace rwcalc {

namespace {

constexpr std::int64_t kRedrawNs = 125'000'000;  // at most 8 redraws per second

/// Characters of UTF-8 text: its bytes that are not continuation bytes.
std::size_t characters(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

/// Byte offset of the character `n` of UTF-8 text (its size when it has fewer).
std::size_t offset_of_character(const std::string& s, std::size_t n) {
  for (std::size_t i = 0; i < s.size(); ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80 && n-- == 0) return i;
  return s.size();
}

/// Columns of the terminal `sink` writes to; 0 when it is not one.
std::size_t terminal_columns(std::FILE* sink) {
  winsize ws{};
  if (ioctl(fileno(sink), TIOCGWINSZ, &ws) != 0) return 0;
  return ws.ws_col;
}

/// The unit bytes are shown in: kB below a megabyte, MB below a gigabyte, else GB.
struct ByteUnit {
  double bytes;
  const char* name;
};
ByteUnit byte_unit(std::uint64_t n) {
  if (n < 1'000'000) return {1e3, N_("kB")};
  if (n < 1'000'000'000) return {1e6, N_("MB")};
  return {1e9, N_("GB")};
}

/// "12/50 (24%)", "12.5/43.2 MB (28%)", "35%": how far the work is; empty when nothing can be said.
/// A count beyond its total (which was an estimate) is shown alone, as one with no total.
std::string amount(std::uint64_t done, std::uint64_t total, Progress::Measure measure) {
  if (done > total) total = 0;
  const std::string percent = total > 0 ? fmt::format("{}%", done * 100 / total) : std::string();
  switch (measure) {
    case Progress::Measure::Items:
      if (total == 0) return done > 0 ? fmt::format("{}", done) : std::string();
      return fmt::format("{}/{} ({})", done, total, percent);
    case Progress::Measure::Bytes: {
      const ByteUnit unit = byte_unit(total > 0 ? total : done);
      const double d = static_cast<double>(done) / unit.bytes;
      if (total == 0) return fmt::format("{:.1f} {}", d, tr(unit.name));
      return fmt::format("{:.1f}/{:.1f} {} ({})", d, static_cast<double>(total) / unit.bytes, tr(unit.name), percent);
    }
    case Progress::Measure::Percent: return percent;
  }
  return {};
}

/// What follows the label: the amount, the time taken and the time left (when it can be told).
std::string status(std::uint64_t done, std::uint64_t total, double elapsed_s, Progress::Measure measure) {
  std::string s = amount(done, total, measure);
  if (!s.empty()) s += ", ";
  s += trf("{:.1f} s", elapsed_s);
  if (done > 0 && done < total) {
    const double left = elapsed_s * static_cast<double>(total - done) / static_cast<double>(done);
    s += ", " + trf("~{:.1f} s left", left);
  }
  return localize_numbers(std::move(s));
}

}  // namespace

Progress::Progress(std::string label, std::uint64_t total, std::FILE* sink, Measure measure)
    : label_(std::move(label)),
      total_(total),
      sink_(inside_parallel_items() ? nullptr : sink),
      measure_(measure),
      start_(Clock::now()) {
  // Say what is being done at once: the first advance may be seconds away. The first advance()
  // still draws at once (next_draw_ns_ stays 0).
  if (sink_) draw(0);
}

Progress::~Progress() { finish(); }

std::string Progress::format_line(const std::string& label, std::uint64_t done, std::uint64_t total, double elapsed_s,
                                  Measure measure) {
  return label + ": " + status(done, total, elapsed_s, measure);
}

std::string Progress::fit_to_width(const std::string& text, std::size_t columns) {
  const std::size_t n = characters(text);
  if (n <= columns) return text;
  if (columns == 0) return {};
  const std::size_t head = (columns - 1) / 2, tail = columns - 1 - head;
  return text.substr(0, offset_of_character(text, head)) + "…" + text.substr(offset_of_character(text, n - tail));
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
    const std::string tail = status(done, total_, elapsed, measure_);
    std::string line = label_ + ": " + tail;
    // One column short of the width: a line filling the last column leaves some terminals
    // waiting to wrap. The label gives way first; the numbers stay whole while they fit.
    if (const std::size_t columns = terminal_columns(sink_); columns > 1 && characters(line) >= columns) {
      const std::size_t room = columns - 1, tail_chars = characters(tail) + 2;
      line = room > tail_chars + 8 ? fit_to_width(label_, room - tail_chars) + ": " + tail : fit_to_width(line, room);
    }
    const std::size_t w = characters(line);
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
