// Progress lines: drawn only to a sink (a terminal in real use), thread-safe counting, erased at
// the end, and silent when disabled (stderr not a terminal: pipes, files, CI, tests).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "rwcalc/progress.hpp"

namespace {

using rwcalc::Progress;

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
  EXPECT_EQ(Progress::format_line("x", 0, 0, 0.0), "x: 0/0, 0.0 s");
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
