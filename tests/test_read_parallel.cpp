// Reading a long text in two halves on two threads gives exactly what the serial reader gives:
// the same samples, runs of lines, time and temperature statistics, and the same error (the
// earliest bad line, with its right line number) wherever the bad line falls.
#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::InputMode;
using rwcalc::read_recording_text;
using rwcalc::ReadOptions;
using rwcalc::Recording;

// A pulse file of `n` data lines (~2 bytes each: ~2.4 MB for 1.2 M), with comment and blank lines inside the data
// in both halves and lines only the careful path takes ("+3", "  4  ").
std::string pulse_text(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::poisson_distribution<int> pulses(3.0);
  std::string t = "# rate_hz: 400\n# scale_arcsec_per_pulse: 0.92\npulses\n";
  for (std::size_t i = 0; i < n; ++i) {
    if (i == n / 5 || i == (3 * n) / 4) t += "# a comment inside the data\n";
    if (i == n / 3 || i == (4 * n) / 5) t += "\n";
    if (i == (7 * n) / 10) {
      t += "+3\n";
      continue;
    }
    t += fmt::format("{}\n", pulses(rng));
  }
  return t;
}

ReadOptions with_threads(unsigned t, ReadOptions o = {}) {
  o.threads = t;
  return o;
}

void expect_same(const Recording& a, const Recording& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.phase.wide_counts(), b.phase.wide_counts());
  EXPECT_EQ(a.phase.values, b.phase.values);
  EXPECT_EQ(a.line_runs, b.line_runs);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.temperature_c, b.temperature_c);
  EXPECT_EQ(a.time_column, b.time_column);
}

std::size_t error_line(const std::string& text, const ReadOptions& o) {
  try {
    (void)read_recording_text(text, "long.csv", o);
  } catch (const rwcalc::InputError& e) {
    return e.line();
  }
  return 0;
}

TEST(ReadParallel, PulseFileSameAsSerial) {
  const std::string text = pulse_text(1200000, 1);
  ASSERT_GT(text.size(), std::size_t{2} << 20);  // parsed in two halves (over 1 MB)
  const Recording serial = read_recording_text(text, "long.csv", with_threads(1));
  const Recording parallel = read_recording_text(text, "long.csv", with_threads(2));
  EXPECT_EQ(serial.samples, 1200000u);
  EXPECT_EQ(serial.line_runs.size(), 5u);  // the data restarts after 2 comments and 2 blank lines
  expect_same(serial, parallel);
  // The line of the last sample: 3 header lines, 4 extra lines.
  EXPECT_EQ(parallel.line_of_sample(1199999), 1200000u + 3 + 4);
}

// The second part's values are written into the values array right after the most the first part
// can hold (one value per line); lines without a value in the first part (here 20 000 comments and
// blank lines spread over it) leave a gap the merge closes by moving them down: the same record as
// the serial read, and the same as when the gap is filled with values.
TEST(ReadParallel, LinesWithoutValuesInTheFirstPart) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> pulse(-9, 9);
  std::string text = "pulses\n";
  const std::size_t n = 1000000;
  for (std::size_t i = 0; i < n; ++i) {
    if (i < n / 2 && i % 50 == 25) text += (i % 100 == 25) ? "# note\n" : "\n";
    text += fmt::format("{}\n", pulse(rng));
  }
  ASSERT_GT(text.size(), std::size_t{2} << 20);
  const Recording serial = read_recording_text(text, "gaps.csv", with_threads(1));
  const Recording parallel = read_recording_text(text, "gaps.csv", with_threads(2));
  EXPECT_EQ(serial.samples, n);
  expect_same(serial, parallel);
  EXPECT_EQ(parallel.line_of_sample(n - 1), n + 1 + 10000);
}

// A file of more than 4 MB is loaded in two halves, each on its own thread: the same bytes,
// including a file that does not end with a newline and one whose size is not a multiple of a page.
TEST(ReadParallel, FileLoadedInHalvesSameAsText) {
  const rwcalc::test::TempDir dir;
  std::string text = pulse_text(2500000, 3);
  ASSERT_GT(text.size(), std::size_t{4} << 20);
  for (const std::string& t : {text, text.substr(0, text.size() - 1), text + "7\n12"}) {
    const auto path = dir.write("long.csv", t).string();
    const Recording from_text = read_recording_text(t, path, with_threads(1));
    for (const unsigned threads : {1u, 2u}) {
      const Recording from_file = rwcalc::read_recording(path, with_threads(threads));
      expect_same(from_text, from_file);
      EXPECT_EQ(from_file.samples, from_text.samples);
    }
  }
}

struct ReadFailure {
  std::size_t line = 0;
  std::string message;
};

template <class Read>
ReadFailure read_failure(Read read) {
  try {
    (void)read();
  } catch (const rwcalc::InputError& e) {
    return {e.line(), e.message()};
  }
  return {};
}

// The two loading threads check and count the lines of their halves as they load them: a control
// byte anywhere (first segment, either side of the halves' boundary, last bytes) gives the error
// of the text read in one piece, and a byte-order mark or classic Mac line ends read the same.
TEST(ReadParallel, FileLoadedInHalvesChecksBytesAsText) {
  const rwcalc::test::TempDir dir;
  const std::string text = pulse_text(2500000, 5);
  ASSERT_GT(text.size(), std::size_t{4} << 20);
  const std::size_t half = (text.size() / 2) & ~std::size_t{4095};
  for (const std::size_t at : {std::size_t{100}, half - 3, half, half + 2, text.size() - 4}) {
    std::string t = text;
    t[at] = '\x01';
    const auto path = dir.write("bad.csv", t).string();
    const ReadFailure want = read_failure([&] { return read_recording_text(t, path, with_threads(1)); });
    ASSERT_GT(want.line, 0u) << at;
    const ReadFailure got = read_failure([&] { return rwcalc::read_recording(path, with_threads(2)); });
    EXPECT_EQ(got.line, want.line) << at;
    EXPECT_EQ(got.message, want.message) << at;
  }
  std::string mac = text;
  std::replace(mac.begin(), mac.end(), '\n', '\r');
  for (const std::string& t : {"\xEF\xBB\xBF" + text, mac}) {
    const auto path = dir.write("other.csv", t).string();
    const Recording from_text = read_recording_text(t, path, with_threads(1));
    const Recording from_file = rwcalc::read_recording(path, with_threads(2));
    expect_same(from_text, from_file);
    EXPECT_EQ(from_file.samples, 2500000u);
  }
}

TEST(ReadParallel, TimeAndTemperatureColumnsSameAsSerial) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g(0.0, 1.0);
  std::string t = "time_s,rate,temperature_c\n";
  for (std::size_t i = 0; i < 200000; ++i)
    t += fmt::format("{:.4f},{:.9f},{:.3f}\n", static_cast<double>(i) * 0.01, g(rng), 20.0 + 0.01 * g(rng));
  ASSERT_GT(t.size(), std::size_t{1} << 20);
  ReadOptions o;
  o.mode = InputMode::Rate;
  const Recording serial = read_recording_text(t, "imu.csv", with_threads(1, o));
  const Recording parallel = read_recording_text(t, "imu.csv", with_threads(2, o));
  expect_same(serial, parallel);
  EXPECT_EQ(parallel.rate_hz, 100.0);
  ASSERT_TRUE(parallel.temperature_c.has_value());
}

TEST(ReadParallel, ErrorsNameTheSameLineAsSerial) {
  const std::string base = pulse_text(1200000, 3);
  ASSERT_GT(base.size(), std::size_t{2} << 20);
  auto line_start = [&](std::size_t line) {  // byte offset of 1-based line
    std::size_t pos = 0;
    for (std::size_t l = 1; l < line; ++l) pos = base.find('\n', pos) + 1;
    return pos;
  };
  // A bad line in the second half only; then one in each half (the first one wins).
  const std::size_t late = 1000000, early = 100000;  // the halves meet near line 600 000
  std::string one = base;
  one.insert(line_start(late), "12 pulses\n");
  std::string two = one;
  two.insert(line_start(early), "x\n");
  for (const std::string* t : {&one, &two}) {
    const std::size_t want = t == &one ? late : early;
    EXPECT_EQ(error_line(*t, with_threads(1)), want);
    EXPECT_EQ(error_line(*t, with_threads(2)), want);
  }
  // A time step out of tolerance in the second half: named after the re-read that keeps the stamps.
  std::string tt = "time_s,pulses\n";
  for (std::size_t i = 0; i < 200000; ++i)
    tt += fmt::format("{:.4f},{}\n", static_cast<double>(i == 150000 ? i + 3 : i) * 0.0025, i % 3);
  EXPECT_EQ(error_line(tt, with_threads(1)), 150000u + 2);
  EXPECT_EQ(error_line(tt, with_threads(2)), 150000u + 2);
}

}  // namespace
