// parallel_for: every item once, exceptions passed on, nested loops serial, RWCALC_THREADS read.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "rwcalc/parallel.hpp"

namespace {

// Sets an environment variable for one test and restores it afterwards.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    if (value)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (had_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

TEST(ParallelFor, RunsEveryItemExactlyOnce) {
  const ScopedEnv env("RWCALC_THREADS", "4");
  std::vector<std::atomic<int>> hits(1000);
  rwcalc::parallel_for(hits.size(), [&](std::size_t i) { ++hits[i]; });
  for (std::size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(hits[i].load(), 1) << "item " << i;
}

TEST(ParallelFor, NoItemsRunsNothing) {
  bool ran = false;
  rwcalc::parallel_for(0, [&](std::size_t) { ran = true; });
  EXPECT_FALSE(ran);
}

TEST(ParallelFor, RethrowsTheFirstExceptionAfterEveryThreadStopped) {
  const ScopedEnv env("RWCALC_THREADS", "3");
  std::atomic<int> ran{0};
  EXPECT_THROW(rwcalc::parallel_for(100,
                                    [&](std::size_t i) {
                                      ++ran;
                                      if (i == 5) throw std::runtime_error("item 5");
                                    }),
               std::runtime_error);
  EXPECT_GE(ran.load(), 1);
  EXPECT_LE(ran.load(), 100);
}

TEST(ParallelFor, UsesSeveralThreadsAndRunsNestedLoopsOnTheCallingThread) {
  const ScopedEnv env("RWCALC_THREADS", "2");
  std::vector<std::thread::id> outer(64);
  std::vector<int> nested_on_same_thread(64, 0);
  rwcalc::parallel_for(outer.size(), [&](std::size_t i) {
    outer[i] = std::this_thread::get_id();
    rwcalc::parallel_for(4, [&](std::size_t) {
      if (std::this_thread::get_id() == outer[i]) ++nested_on_same_thread[i];
    });
  });
  for (int n : nested_on_same_thread) EXPECT_EQ(n, 4);
}

TEST(ParallelFor, OneThreadRunsInOrderOnTheCaller) {
  const ScopedEnv env("RWCALC_THREADS", "1");
  std::vector<std::size_t> order;
  const auto self = std::this_thread::get_id();
  rwcalc::parallel_for(10, [&](std::size_t i) {
    EXPECT_EQ(std::this_thread::get_id(), self);
    order.push_back(i);
  });
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i);
}

TEST(RunBeside, BothStagesRunTheSecondOnAnotherThreadAndMainMayLoop) {
  const ScopedEnv env("RWCALC_THREADS", "2");
  const auto self = std::this_thread::get_id();
  std::thread::id main_id, beside_id;
  std::atomic<int> items{0};
  rwcalc::run_beside(
      [&] {
        main_id = std::this_thread::get_id();
        rwcalc::parallel_for(8, [&](std::size_t) { ++items; });
      },
      [&] { beside_id = std::this_thread::get_id(); });
  EXPECT_EQ(main_id, self);
  EXPECT_NE(beside_id, self);
  EXPECT_EQ(items.load(), 8);
}

TEST(RunBeside, MainsErrorComesFirstAndBesidesIsNotLost) {
  const ScopedEnv env("RWCALC_THREADS", "2");
  bool beside_ran = false;
  try {
    rwcalc::run_beside([] { throw std::runtime_error("main"); },
                       [&] {
                         beside_ran = true;
                         throw std::runtime_error("beside");
                       });
    ADD_FAILURE() << "nothing thrown";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "main");
  }
  EXPECT_TRUE(beside_ran);  // joined before the error left
  EXPECT_THROW(rwcalc::run_beside([] {}, [] { throw std::runtime_error("beside"); }), std::runtime_error);
}

TEST(RunBeside, OneThreadRunsMainThenBesideOnTheCaller) {
  const ScopedEnv env("RWCALC_THREADS", "1");
  const auto self = std::this_thread::get_id();
  std::vector<int> order;
  rwcalc::run_beside(
      [&] {
        EXPECT_EQ(std::this_thread::get_id(), self);
        order.push_back(1);
      },
      [&] {
        EXPECT_EQ(std::this_thread::get_id(), self);
        order.push_back(2);
      });
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
}

TEST(WorkerCount, ReadsRwcalcThreadsAndIgnoresBadValues) {
  {
    const ScopedEnv env("RWCALC_THREADS", "3");
    EXPECT_EQ(rwcalc::worker_count(), 3u);
  }
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  for (const char* bad : {"0", "-1", "x", "3x", "", "5000"}) {
    const ScopedEnv env("RWCALC_THREADS", bad);
    EXPECT_EQ(rwcalc::worker_count(), hardware) << "RWCALC_THREADS=" << bad;
  }
}

}  // namespace
