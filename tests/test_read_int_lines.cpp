// Pulse files of many lines that mix plain counts with every other accepted spelling (comments,
// blank lines, CRLF, blanks around the value, '+', leading zeros, up to 18 digits): the exact
// cumulative counts, the runs of lines that map samples to line numbers, and the line named
// when the sum of |counts| passes 2^63 - 1; the same on one thread and on two (long stretches of
// plain lines are read in two halves at once).
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::read_recording_text;
using rwcalc::Recording;

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

// Where each run of data lines starts, (sample index, line number), found here line by line:
// a run starts at a data line after the start of the file, a comment, a blank line or the header.
std::vector<std::pair<std::size_t, std::size_t>> expected_runs(const std::string& text) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t line = 0, samples = 0, pos = 0;
  bool after_gap = true;
  while (pos < text.size()) {
    const std::size_t e = text.find('\n', pos);
    std::string l = text.substr(pos, e - pos);
    pos = e + 1;
    ++line;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    const bool data = l.find_first_not_of(' ') != std::string::npos && l[0] != '#' && l != "pulses";
    if (data && after_gap) runs.emplace_back(samples, line);
    after_gap = !data;
    samples += data;
  }
  return runs;
}

TEST(ReadIntLines, KnownSumsAndRunsOfLines) {
  for (const std::size_t n : {std::size_t{5000}, std::size_t{900000}}) {
    std::vector<std::int64_t> counts;
    const std::string text = mixed_text(n, 5, counts);
    std::vector<std::int64_t> want{0};
    std::uint64_t acc = 0;
    for (const auto v : counts) want.push_back(static_cast<std::int64_t>(acc += static_cast<std::uint64_t>(v)));
    const Recording r = read_recording_text(text, "mixed.csv");
    EXPECT_EQ(r.samples, n);
    EXPECT_EQ(r.phase.counts, want);
    EXPECT_EQ(r.line_runs, expected_runs(text));
  }
}

// Long comment lines, blank lines, 8-digit counts, leading blanks and CRLF at random among short
// counts, in a text read in many pieces: lines cut by a piece's end are read whole.
TEST(ReadIntLines, LinesOfEveryFormAcrossPieces) {
  std::mt19937_64 rng(29);
  std::string text = "pulses\n";
  std::vector<std::int64_t> want{0};
  std::uint64_t acc = 0;
  for (std::size_t i = 0; i < 300000; ++i) {
    const auto r = rng() % 97;
    if (r == 0) text += "# " + std::string(60 + rng() % 140, 'x') + "\n";
    if (r == 1) text += "\n";
    std::int64_t v = static_cast<std::int64_t>(rng() % 2001) - 1000;
    if (r == 2) v = 99999999;
    if (r == 3) text += " ";
    text += fmt::format("{}", v);
    text += r == 4 ? "\r\n" : "\n";
    want.push_back(static_cast<std::int64_t>(acc += static_cast<std::uint64_t>(v)));
  }
  const Recording r = read_recording_text(text, "pieces.csv");
  EXPECT_EQ(r.phase.counts, want);
  EXPECT_EQ(r.line_runs, expected_runs(text));
}

// Plain stretches are read in two halves on two cores; a line the plain way does not take (here
// every 3000th or so, anywhere in a half) stops the first half and the second half's lines are read
// again: the counts, the runs of lines and an error's line are those of one thread.
TEST(ReadIntLines, TwoHalvesReadAsOneThread) {
  std::vector<std::int64_t> counts;
  std::string text = mixed_text(600000, 11, counts);
  for (std::size_t at = 1000; at < text.size(); at += 2999 + at % 7)
    if (text[at] == '\n') text.insert(at + 1, "# note\n");
  std::vector<rwcalc::Recording> read;
  for (const char* threads : {"1", "2"}) {
    const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
    read.push_back(read_recording_text(text, "halves.csv"));
  }
  EXPECT_EQ(read[0].phase.counts, read[1].phase.counts);
  EXPECT_EQ(read[0].line_runs, read[1].line_runs);
  EXPECT_EQ(read[1].line_runs, expected_runs(text));
  EXPECT_EQ(read[1].samples, counts.size());
}

std::size_t error_line(const std::string& text) {
  try {
    (void)read_recording_text(text, "big.csv");
  } catch (const rwcalc::InputError& e) {
    return e.line();
  }
  return 0;
}

TEST(ReadIntLines, SumTooLargeNamesTheSameLine) {
  // Ten counts of ~1e18 pass Σ|c| = 2^63 − 1 at the tenth; placed early, in the middle, or near
  // the end of a long file.
  const std::size_t n = 800000;
  for (const std::size_t at : {std::size_t{100}, n / 2 - 5, n - 50}) {
    std::string t = "pulses\n";
    std::size_t want = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool big = i >= at && i < at + 10;
      t += big ? "999999999999999999\n" : fmt::format("{}\n", i % 5);
      if (big) want = i + 2;
    }
    EXPECT_EQ(error_line(t), want) << at;
  }
  // Plain counts between two 18-digit ones that cancel: no error, exact sums.
  std::string ok = "pulses\n999999999999999999\n";
  for (std::size_t i = 0; i < 1000; ++i) ok += fmt::format("-{}\n", i % 3);
  ok += "-999999999999999999\n";
  const Recording r = read_recording_text(ok, "ok.csv");
  EXPECT_EQ(r.phase.counts.back(), -999);
}

TEST(ReadIntLines, PlainLineEdgesReadAsTheGeneralWay) {
  // 18 digits, 19 digits, "-0": the same counts whichever way the line is read.
  const Recording r = read_recording_text("pulses\n999999999999999999\n-0\n1000000000000000000\n-1\n", "e.csv");
  EXPECT_EQ(r.phase.counts, (std::vector<std::int64_t>{0, 999999999999999999, 999999999999999999, 1999999999999999999,
                                                       1999999999999999998}));
  EXPECT_EQ(error_line("pulses\n1\n-\n"), 3u);  // a lone sign is not a number
  rwcalc::ReadOptions counter;
  counter.mode = rwcalc::InputMode::Counter;
  counter.counter_bits = 8;
  try {
    (void)read_recording_text("1\n255\n256\n", "c.csv", counter);
    ADD_FAILURE() << "a reading beyond the counter's bits was taken";
  } catch (const rwcalc::InputError& e) {
    EXPECT_EQ(e.line(), 3u);
    EXPECT_NE(e.message().find("8-bit counter"), std::string::npos) << e.message();
  }
}

}  // namespace
