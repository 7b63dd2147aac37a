// Progress lines: drawn only to a sink (a terminal in real use), from the start of the work,
// thread-safe counting, erased at the end, and silent when disabled (stderr not a terminal: pipes,
// files, CI, tests; --quiet) or made inside the items of a parallel loop. test_progress_terminal
// runs the commands on a pseudo-terminal.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "rwcalc/i18n.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/progress.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::Progress;
using Measure = rwcalc::Progress::Measure;

std::string read_all(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

TEST(Progress, LineShowsCountPercentElapsedAndRemaining) {
  EXPECT_EQ(Progress::format_line("ensemble", 10, 40, 2.0), "ensemble: 10/40 (25%), 2.0 s, ~6.0 s left");
  EXPECT_EQ(Progress::format_line("ensemble", 40, 40, 8.04), "ensemble: 40/40 (100%), 8.0 s");
  EXPECT_EQ(Progress::format_line("x", 0, 0, 0.0), "x: 0.0 s");  // nothing to count: the time alone
}

TEST(Progress, BytesInTheUnitOfTheTotalAndShareAlone) {
  EXPECT_EQ(Progress::format_line("reading a.csv", 12'500'000, 50'000'000, 1.0, Measure::Bytes),
            "reading a.csv: 12.5/50.0 MB (25%), 1.0 s, ~3.0 s left");
  EXPECT_EQ(Progress::format_line("r", 2'000, 8'000, 0.5, Measure::Bytes), "r: 2.0/8.0 kB (25%), 0.5 s, ~1.5 s left");
  EXPECT_EQ(Progress::format_line("r", 3'000'000'000, 6'000'000'000, 2.0, Measure::Bytes),
            "r: 3.0/6.0 GB (50%), 2.0 s, ~2.0 s left");
  // Standard input: the size is not known, the bytes read so far are.
  EXPECT_EQ(Progress::format_line("reading <stdin>", 2'500'000, 0, 1.0, Measure::Bytes),
            "reading <stdin>: 2.5 MB, 1.0 s");
  EXPECT_EQ(Progress::format_line("simulating", 35, 100, 7.0, Measure::Percent),
            "simulating: 35%, 7.0 s, ~13.0 s left");
}

TEST(Progress, ACountBeyondItsEstimatedTotalIsShownAlone) {
  EXPECT_EQ(Progress::format_line("diagnosing", 300, 225, 9.0), "diagnosing: 300, 9.0 s");
  EXPECT_EQ(Progress::format_line("diagnosing", 225, 225, 9.0), "diagnosing: 225/225 (100%), 9.0 s");
}

TEST(Progress, InRussianWithTheDecimalComma) {
  const rwcalc::LanguageScope ru(rwcalc::Language::Russian);
  EXPECT_EQ(Progress::format_line("чтение a.csv", 12'500'000, 50'000'000, 1.0, Measure::Bytes),
            "чтение a.csv: 12,5/50,0 МБ (25%), 1,0 с, осталось ~3,0 с");
}

TEST(Progress, FitToWidthKeepsTheStartAndTheEnd) {
  EXPECT_EQ(Progress::fit_to_width("reading /data/runs/gl2d_p50C.csv.gz", 100), "reading /data/runs/gl2d_p50C.csv.gz");
  EXPECT_EQ(Progress::fit_to_width("reading /data/runs/gl2d_p50C.csv.gz", 21), "reading /d…50C.csv.gz");
  // Characters, not bytes: a Cyrillic letter is one column.
  EXPECT_EQ(Progress::fit_to_width("чтение файла", 7), "чте…йла");
  EXPECT_EQ(Progress::fit_to_width("abc", 0), "");
}

TEST(Progress, DrawsWhatIsBeingDoneAtOnce) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    const Progress p("printing report.pdf", 0, f);  // one step: no count, the time it takes
    EXPECT_EQ(read_all(f), "\rprinting report.pdf: 0.0 s");
  }
  std::fclose(f);
}

TEST(Progress, MadeInsideTheItemsOfAParallelLoopShowsNothing) {
  const rwcalc::test::ScopedEnv threads("RWCALC_THREADS", "4");
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  std::atomic<int> shown{0};
  rwcalc::parallel_for(4, [&](std::size_t) {
    Progress inner("inner", 10, f);  // the items' lines would overwrite each other
    shown += inner.enabled() ? 1 : 0;
    inner.advance(10);
  });
  EXPECT_EQ(shown.load(), 0);
  EXPECT_EQ(read_all(f), "");
  {
    const Progress outer("outer", 1, f);  // the loop's own line, made outside it
    EXPECT_TRUE(outer.enabled());
  }
  std::fclose(f);
}

TEST(Progress, DrawsToItsSinkAndErasesTheLineAtTheEnd) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p("simulate", 3, f);
    EXPECT_TRUE(p.enabled());
    p.advance();  // the first advance draws at once
    p.advance(2);
    EXPECT_EQ(p.done(), 3u);
  }
  const std::string s = read_all(f);
  std::fclose(f);
  EXPECT_NE(s.find("\rsimulate: 1/3 (33%)"), std::string::npos) << s;
  // Finished: the last characters blank the line and return the cursor, no newline is left.
  ASSERT_FALSE(s.empty());
  EXPECT_EQ(s.back(), '\r');
  EXPECT_EQ(s.find('\n'), std::string::npos);
}

TEST(Progress, SilentWithoutASinkAndCountsFromManyThreads) {
  Progress p("quiet", 8000, nullptr);
  EXPECT_FALSE(p.enabled());
  std::vector<std::thread> ts;
  for (int t = 0; t < 4; ++t)
    ts.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) p.advance();
    });
  for (auto& t : ts) t.join();
  EXPECT_EQ(p.done(), 8000u);
  EXPECT_EQ(p.total(), 8000u);
}

TEST(Progress, ConcurrentDrawingWritesWholeLines) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p("par", 4000, f);
    std::vector<std::thread> ts;
    for (int t = 0; t < 4; ++t)
      ts.emplace_back([&] {
        for (int i = 0; i < 1000; ++i) p.advance();
      });
    for (auto& t : ts) t.join();
    p.finish();
    p.advance();  // after finish: nothing more is drawn
  }
  const std::string s = read_all(f);
  std::fclose(f);
  // Every drawn segment starts with the label (no interleaved partial lines).
  std::size_t pos = 0, lines = 0;
  while ((pos = s.find('\r', pos)) != std::string::npos) {
    ++pos;
    if (pos < s.size() && s[pos] != ' ' && s[pos] != '\r') {
      EXPECT_EQ(s.compare(pos, 4, "par:"), 0) << s.substr(pos, 20);
      ++lines;
    }
  }
  EXPECT_GE(lines, 1u);
}

}  // namespace
