// A pulse file read from disk is loaded into the storage its 32-bit counts will take (the text at
// the end, the counts written from the start over text already parsed), and `batch` lends each
// read the storage of the record before. These tests read files of every form that matters to
// that — all plain lines, the tightest text (two bytes per line), lines of other forms early and
// late (late: the counts have already overwritten text, so the file is loaded again), counts that
// outgrow 32 bits, a byte-order mark, CRLF, no final newline, two loading threads — and require
// exactly the record, line numbers and errors of the same text read from memory.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;

ReadOptions with_threads(unsigned threads) {
  ReadOptions o;
  o.threads = threads;
  return o;
}

// `n` one-digit pulse lines ("d\n"), from a seeded walk.
std::string digits(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> d(0, 9);
  std::string t;
  t.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    t += static_cast<char>('0' + d(rng));
    t += '\n';
  }
  return t;
}

// `text` with `line` inserted after the first `after` lines.
std::string insert_after(std::string text, std::size_t after, const std::string& line) {
  std::size_t pos = 0;
  for (std::size_t k = 0; k < after; ++k) pos = text.find('\n', pos) + 1;
  text.insert(pos, line);
  return text;
}

void expect_same(const Recording& want, const Recording& got, const std::string& what) {
  EXPECT_EQ(got.phase.narrow(), want.phase.narrow()) << what;
  EXPECT_EQ(got.phase.wide_counts(), want.phase.wide_counts()) << what;
  EXPECT_EQ(got.samples, want.samples) << what;
  EXPECT_EQ(got.line_runs, want.line_runs) << what;
  EXPECT_EQ(got.rate_hz, want.rate_hz) << what;
  EXPECT_EQ(got.phase.arcsec_per_count, want.phase.arcsec_per_count) << what;
}

struct Case {
  std::string name;
  std::string text;
};

std::vector<Case> cases() {
  const std::string plain = digits(3000000, 11);  // ~6 MB: loaded in halves on two threads
  std::string crlf;
  for (char c : digits(200000, 12)) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::string big = digits(2000000, 13);
  // Counts that pass 2^30 in sum near the end: the 32-bit read gives up late.
  big = insert_after(big, 1900000, "1073741824\n");
  return {
      {"plain", plain},
      {"all zeros (two bytes per line, the tightest text)", [] {
         std::string z;
         for (int i = 0; i < 2000000; ++i) z += "0\n";
         return z;
       }()},
      {"header and metadata", "# rate_hz: 400\n# scale_arcsec_per_pulse: 0.92\npulses\n" + digits(500000, 14)},
      {"comment early", insert_after(plain, 100, "# door opened\n")},
      {"comment late", insert_after(plain, 2900000, "# door opened\n")},
      {"blank line late", insert_after(plain, 2999000, "\n")},
      {"counts beyond 32 bits late", big},
      {"byte-order mark", "\xEF\xBB\xBF" + digits(400000, 15)},
      {"CRLF", crlf},
      {"no final newline", plain.substr(0, plain.size() - 1)},
      {"two-digit lines", insert_after(digits(300000, 16), 1000, "12\n-34\n")},
  };
}

TEST(HostedRead, FileReadsGiveTheRecordOfTheTextInEveryForm) {
  const test::TempDir dir;
  for (const Case& c : cases()) {
    const auto path = dir.write("run.csv", c.text).string();
    const Recording want = read_recording_text(c.text, path, with_threads(1));
    for (const unsigned threads : {1u, 2u}) {
      const Recording got = read_recording(path, with_threads(threads));
      expect_same(want, got, c.name + ", " + std::to_string(threads) + " thread(s)");
    }
  }
}

TEST(HostedRead, PlainFilesAreKeptInTheStorageTheyWereLoadedInto) {
  const test::TempDir dir;
  const std::string text = digits(1000000, 21);
  const auto path = dir.write("run.csv", text).string();
  const Recording want = read_recording_text(text, path, with_threads(1));
  ASSERT_TRUE(want.phase.narrow());
  // A first read takes fresh storage; handing its counts to the next read makes that read load
  // the file into the same storage and leave the counts there.
  ReadOptions o = with_threads(1);
  std::vector<std::int32_t> spare;
  o.reuse = &spare;
  Recording first = read_recording(path, o);
  expect_same(want, first, "first read");
  spare = std::move(first.phase.counts32);
  const std::int32_t* storage = spare.data();
  const Recording second = read_recording(path, o);
  expect_same(want, second, "second read");
  EXPECT_EQ(second.phase.counts32.data(), storage);
  EXPECT_TRUE(spare.empty());
  // Storage too small for the file is replaced (with room for slightly longer files to come).
  std::vector<std::int32_t> small(10, 7);
  o.reuse = &small;
  const Recording third = read_recording(path, o);
  expect_same(want, third, "small spare");
  EXPECT_GE(third.phase.counts32.capacity(), third.phase.counts32.size() + third.phase.counts32.size() / 32);
}

TEST(HostedRead, ASequenceOfFilesSharingOneSpareReadsEachRight) {
  // As `batch` does: each record's counts lent to the next read, over files of other sizes and
  // forms (a comment late, a rate file, a file too large for 32 bits).
  const test::TempDir dir;
  std::vector<Case> files = cases();
  files.push_back({"shorter", digits(100000, 31)});
  files.push_back({"longer", digits(3100000, 32)});
  std::vector<std::int32_t> spare;
  for (const Case& c : files) {
    const auto path = dir.write(c.name + ".csv", c.text).string();
    ReadOptions o = with_threads(1);
    o.reuse = &spare;
    Recording got = read_recording(path, o);
    expect_same(read_recording_text(c.text, path, with_threads(1)), got, c.name);
    spare = std::move(got.phase.counts32);
  }
  ReadOptions rate = with_threads(1);
  rate.mode = InputMode::Rate;
  rate.reuse = &spare;
  const std::string rates = "0.5\n1.5\n-2.25\n";
  const auto path = dir.write("rate.csv", rates).string();
  const Recording r = read_recording(path, rate);
  EXPECT_EQ(r.phase.values, read_recording_text(rates, path, rate).phase.values);
}

TEST(HostedRead, ABadLineLateInTheFileIsNamedAsInTheText) {
  const test::TempDir dir;
  const std::string plain = digits(2000000, 41);
  for (const std::size_t after : {std::size_t{10}, std::size_t{1999990}}) {
    const std::string text = insert_after(plain, after, "1.5\n");
    const auto path = dir.write("bad.csv", text).string();
    std::size_t want_line = 0;
    std::string want_message;
    try {
      (void)read_recording_text(text, path, with_threads(1));
    } catch (const InputError& e) {
      want_line = e.line();
      want_message = e.message();
    }
    ASSERT_EQ(want_line, after + 1);
    for (const unsigned threads : {1u, 2u}) {
      try {
        (void)read_recording(path, with_threads(threads));
        ADD_FAILURE() << "a fractional pulse count was accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(e.line(), want_line) << threads;
        EXPECT_EQ(e.message(), want_message) << threads;
      }
    }
  }
}

}  // namespace
