// The plain-line path for one-column pulse files: line ends found 64 bytes at a time, single digits
// and 8-byte word scans of up to 7 digits, with the cumulative counts summed while parsing. It must
// give exactly what the per-line paths give (values, runs of lines, errors and their line numbers)
// on any mixture of lines.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/reader_detail.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"

namespace {

using rwcalc::read_recording_text;
using rwcalc::ReadOptions;
using rwcalc::Recording;
namespace detail = rwcalc::detail;

// The line followed by zero padding, as TextBuffer provides it.
std::string padded(const std::string& line) { return line + std::string(16, '\0'); }

// What the plain-line scanners must do with `line`: its value when it is "[-]d{1,7}" then LF or
// CRLF, else nothing (nullptr), decided here independently of the scanners.
void check_line(const std::string& line) {
  const std::string buf = padded(line);
  std::size_t i = line[0] == '-' ? 1 : 0;
  std::size_t digits = 0;
  while (i + digits < line.size() && detail::is_digit(line[i + digits])) ++digits;
  const std::string rest = line.substr(i + digits);
  const bool plain = digits >= 1 && digits <= 7 && (rest == "\n" || rest == "\r\n");
  std::int64_t a = -12345, b = -12345;
  const char* ea = detail::scan_int_line(buf.data(), a);
  const char* eb = detail::scan_int_line_swar(buf.data(), b);
  if (!plain) {
    EXPECT_EQ(ea, nullptr) << line;
    EXPECT_EQ(eb, nullptr) << line;
    return;
  }
  std::int64_t want = 0;
  ASSERT_NE(detail::scan_int_fast(buf.data(), want), nullptr) << line;
  ASSERT_EQ(ea, buf.data() + line.size()) << line;
  ASSERT_EQ(eb, buf.data() + line.size()) << line;
  EXPECT_EQ(a, want) << line;
  EXPECT_EQ(b, want) << line;
}

TEST(ReadIntLines, ScannersAgreeWithTheCarefulIntegerScan) {
  for (int v = -20000; v <= 20000; ++v) {
    check_line(fmt::format("{}\n", v));
    if (v % 7 == 0) check_line(fmt::format("{}\r\n", v));
  }
  std::mt19937_64 rng(11);
  for (int k = 0; k < 200000; ++k) {
    const int digits = 1 + static_cast<int>(rng() % 9);  // 8 and 9 digits: not plain
    std::string s = (rng() & 1) ? "-" : "";
    for (int d = 0; d < digits; ++d) s += static_cast<char>('0' + rng() % 10);  // leading zeros too
    check_line(s + ((rng() & 3) == 0 ? "\r\n" : "\n"));
  }
  for (const char* odd : {"+1\n", " 1\n", "1 \n", "1\t\n", "-\n", "\n", "\r\n", "--1\n", "-+1\n", "1x\n",
                          "1.5\n", "1,5\n", "1e3\n", "1\r", "1\rx\n", "12345678\n", "-12345678\n",
                          "9999999\n", "-9999999\r\n", "0000000\n", "-0\n", "#1\n", "1;2\n"})
    check_line(odd);
}

// A one-column pulse file of n data lines mixing the plain form with lines the per-line paths
// take: comments, blank lines, CRLF, leading blanks, '+', 8 to 18 digits, negative counts.
std::string mixed_text(std::size_t n, unsigned seed, std::vector<std::int64_t>& counts) {
  std::mt19937_64 rng(seed);
  std::string t = "# rate_hz: 400\npulses\n";
  counts.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = rng() % 1000;
    if (r == 0) t += "# note\n";
    if (r == 1) t += "\n";
    std::int64_t v = static_cast<std::int64_t>(rng() % 9) - 4;
    std::string text = fmt::format("{}", v);
    if (r == 2) {
      v = 12345678901234;  // 14 digits: the per-line paths
      text = fmt::format("{}", v);
    } else if (r == 3) {
      v = -9876543;
      text = fmt::format("{}", v);
    } else if (r == 4) {
      text = fmt::format(" {} ", v);
    } else if (r == 5 && v >= 0) {
      text = fmt::format("+{}", v);
    } else if (r == 6) {
      v = 12345678;
      text = "12345678";
    } else if (r == 7) {
      text = fmt::format("{:07d}", v < 0 ? -v : v);
      v = v < 0 ? -v : v;
    }
    t += text;
    t += r == 8 ? "\r\n" : "\n";
    counts.push_back(v);
  }
  return t;
}

// The same samples with a blank before every value: no line takes the plain-line path.
std::string indented(const std::string& text) {
  std::string out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t e = text.find('\n', pos);
    const std::string line = text.substr(pos, e - pos + 1);
    const bool data = !line.empty() && line[0] != '#' && line != "\n" && line != "pulses\n";
    out += data ? " " + line : line;
    pos = e + 1;
  }
  return out;
}

ReadOptions with_threads(unsigned t) {
  ReadOptions o;
  o.threads = t;
  return o;
}

TEST(ReadIntLines, SameAsThePerLinePathsAndKnownSums) {
  for (const std::size_t n : {std::size_t{5000}, std::size_t{900000}}) {  // one half, and two threads
    std::vector<std::int64_t> counts;
    const std::string text = mixed_text(n, 5, counts);
    const std::string slow = indented(text);
    std::vector<std::int64_t> want{0};
    std::uint64_t acc = 0;
    for (const auto v : counts) want.push_back(static_cast<std::int64_t>(acc += static_cast<std::uint64_t>(v)));
    const Recording ref = read_recording_text(slow, "slow.csv", with_threads(1));
    ASSERT_EQ(ref.phase.wide_counts(), want);
    for (const unsigned t : {1u, 2u}) {
      const Recording r = read_recording_text(text, "fast.csv", with_threads(t));
      EXPECT_EQ(r.samples, n);
      EXPECT_EQ(r.phase.wide_counts(), want) << "threads " << t;
      EXPECT_EQ(r.line_runs, ref.line_runs) << "threads " << t;
    }
  }
}

// The plain-line path finds line ends 64 bytes at a time: lines longer than a window, lines cut
// by a window's end, and lines it must leave to the per-line paths at every offset in a window.
TEST(ReadIntLines, LinesAcrossAndLongerThanTheWindows) {
  std::mt19937_64 rng(29);
  std::string text = "pulses\n";
  std::vector<std::int64_t> want{0};
  std::uint64_t acc = 0;
  for (std::size_t i = 0; i < 300000; ++i) {
    const auto r = rng() % 97;
    if (r == 0) text += "# " + std::string(60 + rng() % 140, 'x') + "\n";  // one or more windows long
    if (r == 1) text += "\n";
    std::int64_t v = static_cast<std::int64_t>(rng() % 2001) - 1000;
    if (r == 2) v = 99999999;  // 8 digits: not the plain form
    if (r == 3) text += " ";   // a leading blank: not the plain form
    text += fmt::format("{}", v);
    text += r == 4 ? "\r\n" : "\n";
    want.push_back(static_cast<std::int64_t>(acc += static_cast<std::uint64_t>(v)));
  }
  for (const unsigned t : {1u, 2u}) {
    const Recording r = read_recording_text(text, "windows.csv", with_threads(t));
    EXPECT_EQ(r.phase.wide_counts(), want) << "threads " << t;
    const Recording slow = read_recording_text(indented(text), "slow.csv", with_threads(t));
    EXPECT_EQ(r.line_runs, slow.line_runs) << "threads " << t;
  }
}

std::size_t error_line(const std::string& text, unsigned threads) {
  try {
    (void)read_recording_text(text, "big.csv", with_threads(threads));
  } catch (const rwcalc::InputError& e) {
    return e.line();
  }
  return 0;
}

TEST(ReadIntLines, SumTooLargeNamesTheSameLine) {
  // Ten counts of ~1e18 pass Σ|c| = 2^63 − 1 at the tenth; placed early, in the middle, or near
  // the end of a long file (the other thread's half), among plain lines.
  const std::size_t n = 800000;
  for (const std::size_t at : {std::size_t{100}, n / 2 - 5, n - 50}) {
    std::string t = "pulses\n";
    std::size_t want = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool big = i >= at && i < at + 10;
      t += big ? "999999999999999999\n" : fmt::format("{}\n", i % 5);
      if (big) want = i + 2;
    }
    EXPECT_EQ(error_line(t, 1), want) << at;
    EXPECT_EQ(error_line(t, 2), want) << at;
  }
  // Plain counts between two 18-digit ones that cancel: no error, exact sums.
  std::string ok = "pulses\n999999999999999999\n";
  for (std::size_t i = 0; i < 1000; ++i) ok += fmt::format("-{}\n", i % 3);
  ok += "-999999999999999999\n";
  const Recording r = read_recording_text(ok, "ok.csv", with_threads(2));
  EXPECT_EQ(r.phase.wide_counts().back(), -999);
}

}  // namespace
