// Crew: every chunk of a shared loop runs exactly once, on the calling thread and on lenders that
// are free now or later; a chunk's exception reaches the caller; lenders leave on close(). And the
// passes that take a crew (the int32 view, the one-sweep Allan sums, the noise identification's
// first pass, the outlier scan, a whole analysis) give the same bits with lenders as without.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "allan/allan_kernels.hpp"
#include "allan/noise_id.hpp"
#include "rwcalc/analysis.hpp"
#include "rwcalc/crew.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/simulate.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;

/// A crew with `lenders` threads lent to it for the scope of the object.
struct LentCrew {
  Crew crew;
  std::vector<std::jthread> lenders;
  explicit LentCrew(int n) {
    for (int i = 0; i < n; ++i) lenders.emplace_back([this] { crew.lend(); });
  }
  ~LentCrew() {
    crew.close();
    lenders.clear();
  }
};

TEST(Crew, EveryChunkRunsExactlyOnceWithAnyNumberOfLenders) {
  for (int lenders : {0, 1, 3}) {
    LentCrew lc(lenders);
    for (std::size_t chunks : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{97}}) {
      std::vector<std::atomic<int>> runs(chunks);
      std::atomic<int> threads_seen{0};
      lc.crew.share(chunks, [&](std::size_t c) {
        runs[c]++;
        threads_seen++;
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      });
      for (std::size_t c = 0; c < chunks; ++c) EXPECT_EQ(runs[c].load(), 1) << "lenders " << lenders << " chunk " << c;
      EXPECT_EQ(threads_seen.load(), static_cast<int>(chunks));
    }
  }
}

TEST(Crew, LendersTakeChunksOfALoopUnderWay) {
  // With a lender and chunks that wait for each other to overlap, the loop must run on two threads.
  LentCrew lc(1);
  std::atomic<int> inside{0}, most{0};
  lc.crew.share(8, [&](std::size_t) {
    const int now = ++inside;
    most = std::max(most.load(), now);
    for (int k = 0; k < 20000 && most.load() < 2; ++k) std::this_thread::sleep_for(std::chrono::microseconds(100));
    --inside;
  });
  EXPECT_EQ(most.load(), 2);
}

TEST(Crew, AChunksExceptionReachesTheCallerAndTheCrewGoesOn) {
  LentCrew lc(1);
  std::atomic<int> ran{0};
  EXPECT_THROW(lc.crew.share(50,
                             [&](std::size_t c) {
                               ++ran;
                               if (c == 3) throw std::runtime_error("chunk 3");
                             }),
               std::runtime_error);
  EXPECT_LE(ran.load(), 50);
  std::atomic<int> again{0};
  lc.crew.share(10, [&](std::size_t) { ++again; });
  EXPECT_EQ(again.load(), 10);
}

TEST(Crew, CloseReleasesLendersWithNothingToDo) {
  Crew crew;
  std::atomic<bool> returned{false};
  std::jthread lender([&] {
    crew.lend();
    returned = true;
  });
  crew.close();
  lender.join();  // (a lender that stayed would hang here)
  EXPECT_TRUE(returned.load());
  // Once closed, a loop runs on its calling thread alone.
  const auto me = std::this_thread::get_id();
  std::atomic<int> elsewhere{0}, runs{0};
  crew.share(5, [&](std::size_t) {
    ++runs;
    if (std::this_thread::get_id() != me) ++elsewhere;
  });
  EXPECT_EQ(runs.load(), 5);
  EXPECT_EQ(elsewhere.load(), 0);
}


TEST(Crew, PostedLoopsRunWhileTheCallerWorksAndJoinWaitsForThem) {
  for (int lenders : {0, 1}) {
    LentCrew lc(lenders);
    std::vector<std::atomic<int>> runs(40);
    const std::function<void(std::size_t)> fn = [&](std::size_t c) { runs[c]++; };
    Crew::Posted p = lc.crew.post(runs.size(), fn);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the caller's own work
    lc.crew.join(p);
    for (std::size_t c = 0; c < runs.size(); ++c) EXPECT_EQ(runs[c].load(), 1) << "lenders " << lenders;
    // A loop left unjoined (an exception on the way) is joined by its handle's destructor.
    std::atomic<int> late{0};
    const std::function<void(std::size_t)> g = [&](std::size_t) { ++late; };
    { Crew::Posted q = lc.crew.post(7, g); }
    EXPECT_EQ(late.load(), 7);
  }
}

TEST(Crew, OwnCrewLendsItsThreadsUntilItEnds) {
  OwnCrew own(3);  // two threads of its own
  ASSERT_NE(own.get(), nullptr);
  std::atomic<int> runs{0};
  own.get()->share(64, [&](std::size_t) { ++runs; });
  EXPECT_EQ(runs.load(), 64);
  OwnCrew alone(1);  // the calling thread only
  EXPECT_EQ(alone.get(), nullptr);
}

std::vector<std::int64_t> pulse_counts(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::poisson_distribution<int> pulses(1.7);
  std::vector<std::int64_t> c(n);
  std::int64_t x = -5000;
  for (auto& v : c) v = x += pulses(rng);
  return c;
}

TEST(CrewPasses, TheWideSweepWithLendersAsWithout) {
  // Counts whose offsets pass 2^30: no int32 view, the 64-bit sweep, shared in stretches.
  auto c = pulse_counts((std::size_t{1} << 20) + 777, 6);
  for (std::size_t k = 0; k < c.size(); ++k) c[k] += static_cast<std::int64_t>(k) * 2000;
  const detail::PreparedCounts p = detail::prepare_counts(c, false, 1);
  ASSERT_EQ(p.view, nullptr);
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(c.size()); m *= 2) ms.push_back(m);
  std::vector<detail::u128> swept(ms.size());
  ASSERT_TRUE(detail::second_diff_sumsq_sweep(p, c.size(), ms.data(), ms.size(), 0, 1, swept.data()));
  for (int lenders : {0, 1}) {
    LentCrew lc(lenders);
    std::vector<detail::u128> shared(ms.size());
    ASSERT_TRUE(detail::second_diff_sumsq_sweep_shared(p, c.size(), ms.data(), ms.size(), lc.crew, shared.data()));
    for (std::size_t i = 0; i < ms.size(); ++i) {
      EXPECT_TRUE(shared[i] == swept[i]) << "m " << ms[i];
      const std::int64_t n = static_cast<std::int64_t>(c.size()) - 2 * ms[i];
      EXPECT_TRUE(swept[i] == detail::second_diff_sumsq(p, n, ms[i], 1)) << "m " << ms[i];
    }
  }
}

TEST(CrewPasses, TheSamePassesWithLendersAsWithout) {
  const auto c = pulse_counts((std::size_t{1} << 21) + 12345, 5);
  const detail::PreparedCounts p1 = detail::prepare_counts(c, false, 1);
  std::vector<std::int64_t> ms;
  for (std::int64_t m = 1; 2 * m < static_cast<std::int64_t>(c.size()); m *= 2) ms.push_back(m);
  std::vector<detail::u128> swept(ms.size());
  const bool swept_ok = detail::second_diff_sumsq_sweep(p1, c.size(), ms.data(), ms.size(), 0, 1, swept.data());
  PhaseSeries x;
  x.counts = c;
  const auto start1 = detail::lag1_start_pass(x, ms.data(), ms.size(), NoiseIdDomain::Frequency, p1.rel32.data(),
                                              p1.small24, 1);
  for (int lenders : {0, 1}) {
    LentCrew lc(lenders);
    const detail::PreparedCounts p2 = detail::prepare_counts(c, false, 1, &lc.crew);
    EXPECT_EQ(p2.small24, p1.small24);
    EXPECT_EQ(p2.small29, p1.small29);
    ASSERT_EQ(p2.rel32.size(), p1.rel32.size());
    EXPECT_TRUE(std::equal(p1.rel32.begin(), p1.rel32.end(), p2.rel32.begin()));
    std::vector<detail::u128> shared(ms.size());
    EXPECT_EQ(detail::second_diff_sumsq_sweep_shared(p2, c.size(), ms.data(), ms.size(), lc.crew, shared.data()),
              swept_ok);
    if (swept_ok) {
      for (std::size_t i = 0; i < ms.size(); ++i) EXPECT_TRUE(shared[i] == swept[i]) << "m " << ms[i];
    }
    const auto start2 = detail::lag1_start_pass(x, ms.data(), ms.size(), NoiseIdDomain::Frequency, p2.rel32.data(),
                                                p2.small24, 1, &lc.crew);
    ASSERT_EQ(start2.size(), start1.size());
    for (std::size_t i = 0; i < start1.size(); ++i) {
      if (std::isnan(start1[i])) {
        EXPECT_TRUE(std::isnan(start2[i])) << i;
      } else {
        EXPECT_EQ(start2[i], start1[i]) << i;
      }
    }
  }
}

TEST(CrewPasses, AnAnalysisWithLendersEqualsOneWithout) {
  const NoiseModel m = test::gl2d_model();
  SimulationSettings s;
  s.duration_s = 3600;
  s.rate_hz = 400;
  Recording rec;
  rec.source = "sim";
  rec.rate_hz = 400;
  Simulator(m, s, SimulationPath::Ensemble).run(77, rec.phase);
  rec.phase.counts[123456] += 90;  // an outlier for the scan to find
  for (std::size_t i = 123457; i < rec.phase.counts.size(); ++i) rec.phase.counts[i] += 90;
  rec.samples = rec.phase.points() - 1;
  AnalysisOptions o;
  o.allan.threads = 1;
  const nlohmann::json a = to_json(analyze(rec, o));
  LentCrew lc(1);
  o.allan.crew = &lc.crew;
  const nlohmann::json b = to_json(analyze(rec, o));
  EXPECT_EQ(a.dump(), b.dump());
  EXPECT_GE(b.at("outliers").at("count").get<int>(), 1);
}

}  // namespace
