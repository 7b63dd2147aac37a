#pragma once
// Stage timers for profiling whole commands: with RWCALC_TIMING=1 in the environment each
// ScopedTimer prints "timing: NAME W ms wall" to stderr when it ends; otherwise it costs one
// cached getenv. CPU times are those of the whole process (all threads) or of the calling thread,
// so they do not grow when the machine is shared. Internal; docs/performance.md shows what the stages cost.
#include <time.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace rwcalc::detail {

inline bool timing_enabled() {
  static const bool on = [] {
    const char* v = std::getenv("RWCALC_TIMING");
    return v && *v && *v != '0';
  }();
  return on;
}

/// CPU time in ns of the process (all threads) or of the calling thread.
inline std::int64_t cpu_ns(bool thread = false) {
  timespec ts{};
  clock_gettime(thread ? CLOCK_THREAD_CPUTIME_ID : CLOCK_PROCESS_CPUTIME_ID, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

class ScopedTimer {
 public:
  /// With `thread_cpu`, the CPU time is the calling thread's only (for a stage that runs beside
  /// others: the process's CPU time would count theirs as well).
  explicit ScopedTimer(const char* name, bool thread_cpu = false)
      : name_(name), on_(timing_enabled()), thread_(thread_cpu) {
    if (on_) {
      start_ = std::chrono::steady_clock::now();
      cpu_ = cpu_ns(thread_);
    }
  }
  ~ScopedTimer() {
    if (!on_) return;
    const std::chrono::duration<double, std::milli> d = std::chrono::steady_clock::now() - start_;
    std::fprintf(stderr, "timing: %-28s %8.2f ms wall %8.2f ms cpu\n", name_, d.count(),
                 static_cast<double>(cpu_ns(thread_) - cpu_) * 1e-6);
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  const char* name_;
  bool on_;
  bool thread_ = false;
  std::chrono::steady_clock::time_point start_;
  std::int64_t cpu_ = 0;
};

/// Consecutive stages of one function: each lap(NAME) prints the time since the previous lap (or
/// since construction) in the ScopedTimer format, under the same RWCALC_TIMING switch.
class LapTimer {
 public:
  explicit LapTimer(const char* prefix) : prefix_(prefix), on_(timing_enabled()) { restart(); }
  void lap(const char* name) {
    if (!on_) return;
    const std::chrono::duration<double, std::milli> d = std::chrono::steady_clock::now() - start_;
    std::fprintf(stderr, "timing: %s: %-20s %8.2f ms wall %8.2f ms cpu\n", prefix_, name, d.count(),
                 static_cast<double>(cpu_ns() - cpu_) * 1e-6);
    restart();
  }

 private:
  void restart() {
    if (!on_) return;
    start_ = std::chrono::steady_clock::now();
    cpu_ = cpu_ns();
  }
  const char* prefix_;
  bool on_;
  std::chrono::steady_clock::time_point start_;
  std::int64_t cpu_ = 0;
};

}  // namespace rwcalc::detail
