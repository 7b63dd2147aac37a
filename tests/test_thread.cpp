// rwcalc::Thread: runs its function once and joins on destruction like std::jthread, asks a
// function that takes a std::stop_token to stop before joining, moves, and — started on another
// core than its creator's — runs with the creator's whole affinity mask once started.
#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <stop_token>
#include <thread>
#include <utility>
#include <vector>

#include "rwcalc/thread.hpp"

namespace {

using rwcalc::Thread;

TEST(Thread, RunsItsFunctionOnceAndJoinsWhenDestroyed) {
  std::atomic<int> runs{0};
  std::thread::id id;
  {
    Thread t([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      id = std::this_thread::get_id();
      ++runs;
    });
    EXPECT_TRUE(t.joinable());
  }  // joins here: the function has finished when the scope ends
  EXPECT_EQ(runs.load(), 1);
  EXPECT_NE(id, std::this_thread::get_id());
}

TEST(Thread, JoinEndsJoinability) {
  int value = 0;
  Thread t([&] { value = 42; });
  t.join();
  EXPECT_FALSE(t.joinable());
  EXPECT_EQ(value, 42);
  t.join();  // a second join does nothing
  Thread none;
  EXPECT_FALSE(none.joinable());
}

TEST(Thread, AsksAStopTokenFunctionToStopBeforeJoining) {
  std::atomic<bool> started{false};
  std::atomic<bool> saw_stop{false};
  {
    Thread t([&](std::stop_token st) {
      started = true;
      while (!st.stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      saw_stop = true;
    });
    while (!started) std::this_thread::yield();
  }  // without the stop request the destructor would wait forever
  EXPECT_TRUE(saw_stop.load());
  std::atomic<bool> stopped{false};
  Thread u([&](std::stop_token st) {
    while (!st.stop_requested()) std::this_thread::yield();
    stopped = true;
  });
  EXPECT_TRUE(u.request_stop());
  u.join();
  EXPECT_TRUE(stopped.load());
}

TEST(Thread, MovesKeepOneOwnerOfTheRunningThread) {
  std::atomic<int> runs{0};
  std::vector<Thread> pool;
  for (int i = 0; i < 8; ++i) pool.emplace_back([&] { ++runs; });  // the vector grows: moves
  Thread a([&] { ++runs; });
  Thread b(std::move(a));
  EXPECT_FALSE(a.joinable());  // NOLINT(bugprone-use-after-move): the moved-from state is specified
  EXPECT_TRUE(b.joinable());
  Thread c;
  c = std::move(b);
  EXPECT_TRUE(c.joinable());
  c = Thread([&] { ++runs; });  // joins the thread c held, then takes the new one
  pool.clear();
  c.join();
  EXPECT_EQ(runs.load(), 10);
}

TEST(Thread, RunsWithTheCreatorsWholeAffinityMask) {
  cpu_set_t mine;
  CPU_ZERO(&mine);
  ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
  cpu_set_t seen;
  CPU_ZERO(&seen);
  int rc = -1;
  Thread t([&] { rc = sched_getaffinity(0, sizeof seen, &seen); });
  t.join();
  ASSERT_EQ(rc, 0);
  EXPECT_TRUE(CPU_EQUAL(&seen, &mine)) << "the thread was left on " << CPU_COUNT(&seen) << " of the creator's "
                                       << CPU_COUNT(&mine) << " cores";
}

}  // namespace
