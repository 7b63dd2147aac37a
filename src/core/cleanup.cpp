#include "core/cleanup.hpp"

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>

namespace rwcalc::detail {

namespace {

// A slot is free (0), owned by a thread or the handler that is filling or reading it (1), or
// holds a registered path (2). The handler claims a slot 2→1 before reading its path, so a
// thread can never rewrite a path the handler is removing.
constexpr int kFree = 0, kBusy = 1, kReady = 2;
constexpr int kSlots = 128;

struct Slot {
  std::atomic<int> state{kFree};
  RemoveOnSignal::Kind kind = RemoveOnSignal::Kind::File;
  char path[PATH_MAX] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

Slot g_slots[kSlots];
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

void remove_kind(RemoveOnSignal::Kind kind) {
  for (auto& s : g_slots) {
    int expected = kReady;
    if (s.kind != kind || !s.state.compare_exchange_strong(expected, kBusy)) continue;
    if (kind == RemoveOnSignal::Kind::File)
      (void)unlink(s.path);
    else
      (void)rmdir(s.path);
  }
}

extern "C" void remove_registered_and_reraise(int sig) {
  const int saved = errno;
  remove_kind(RemoveOnSignal::Kind::File);  // a directory can only go once it is empty
  remove_kind(RemoveOnSignal::Kind::Directory);
  errno = saved;
  // SA_RESETHAND has restored the default action; the signal is blocked until the handler
  // returns, and then ends the process as if no handler had been there.
  (void)raise(sig);
}

void install_handler() {
  for (const int sig : kSignals) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) != 0) continue;
    // Keep an ignored signal ignored (nohup, a background job) and an embedding program's handler.
    if ((old.sa_flags & SA_SIGINFO) != 0 || old.sa_handler != SIG_DFL) continue;
    struct sigaction sa {};
    sa.sa_handler = remove_registered_and_reraise;
    sigemptyset(&sa.sa_mask);
    for (const int other : kSignals) sigaddset(&sa.sa_mask, other);
    sa.sa_flags = SA_RESETHAND;
    (void)sigaction(sig, &sa, nullptr);
  }
}

}  // namespace

RemoveOnSignal::RemoveOnSignal(const std::string& path, Kind kind) {
  static std::once_flag installed;
  std::call_once(installed, install_handler);
  if (path.empty() || path.size() >= PATH_MAX) return;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kBusy)) continue;
    g_slots[i].kind = kind;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].state.store(kReady, std::memory_order_release);
    slot_ = i;
    return;
  }
}

RemoveOnSignal::~RemoveOnSignal() {
  if (slot_ < 0) return;
  // Fails only when the handler has claimed the slot: the process is ending then.
  int expected = kReady;
  (void)g_slots[slot_].state.compare_exchange_strong(expected, kFree);
}

}  // namespace rwcalc::detail
