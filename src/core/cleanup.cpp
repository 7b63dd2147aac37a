#include "rwcalc/cleanup.hpp"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
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

// Process groups of running helpers (0: free slot).
constexpr int kGroups = 16;
std::atomic<pid_t> g_groups[kGroups];
static_assert(std::atomic<pid_t>::is_always_lock_free, "the signal handler needs lock-free atomics");

void end_groups() {
  for (auto& g : g_groups) {
    const pid_t group = g.exchange(0);
    if (group <= 0) continue;
    (void)kill(-group, SIGKILL);
    while (waitpid(group, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
}

// The record getdents64 fills (linux_dirent64; glibc has no declaration of it).
struct DirEntry {
  ino64_t ino;
  off64_t off;
  unsigned short reclen;
  unsigned char type;
  char name[1];
};

// Remove the directory `name` in `parent` and everything in it, links not followed, with system
// calls only (openat, getdents64, unlinkat, lseek, close). Entries are unlinked as they are read;
// the directory is read again until it is empty (a filesystem may skip entries read while others
// go).
void remove_tree(int parent, const char* name, int depth) {
  const int fd = openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  alignas(8) char buf[2048];
  for (int pass = 0; pass < 4; ++pass) {
    long n = 0;
    while ((n = syscall(SYS_getdents64, fd, buf, sizeof buf)) > 0)
      for (long at = 0; at < n;) {
        const auto* e = reinterpret_cast<const DirEntry*>(buf + at);
        at += e->reclen;
        const bool dot = e->name[0] == '.' && (e->name[1] == 0 || (e->name[1] == '.' && e->name[2] == 0));
        if (!dot && unlinkat(fd, e->name, 0) != 0 && errno == EISDIR && depth < 32) remove_tree(fd, e->name, depth + 1);
      }
    if (unlinkat(parent, name, AT_REMOVEDIR) == 0 || errno != ENOTEMPTY) break;
    (void)lseek(fd, 0, SEEK_SET);
  }
  (void)close(fd);
}

void remove_kind(RemoveOnSignal::Kind kind) {
  for (auto& s : g_slots) {
    int expected = kReady;
    if (s.kind != kind || !s.state.compare_exchange_strong(expected, kBusy)) continue;
    if (kind == RemoveOnSignal::Kind::File)
      (void)unlink(s.path);
    else if (kind == RemoveOnSignal::Kind::Tree)
      remove_tree(AT_FDCWD, s.path, 0);
    else
      (void)rmdir(s.path);
  }
}

extern "C" void remove_registered_and_reraise(int sig) {
  const int saved = errno;
  end_groups();                             // nothing writes into the paths any more
  remove_kind(RemoveOnSignal::Kind::File);  // a directory can only go once it is empty
  remove_kind(RemoveOnSignal::Kind::Tree);
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
    sa.sa_flags = static_cast<int>(SA_RESETHAND);
    (void)sigaction(sig, &sa, nullptr);
  }
  // A write beyond the file-size limit then fails (EFBIG) and is reported, instead of ending rwcalc
  // with its temporary file left behind.
  struct sigaction xfsz {};
  if (sigaction(SIGXFSZ, nullptr, &xfsz) == 0 && (xfsz.sa_flags & SA_SIGINFO) == 0 && xfsz.sa_handler == SIG_DFL)
    (void)signal(SIGXFSZ, SIG_IGN);
}

std::once_flag g_installed;

}  // namespace

RemoveOnSignal::RemoveOnSignal(const std::string& path, Kind kind) {
  std::call_once(g_installed, install_handler);
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

EndOnSignal::EndOnSignal(pid_t group) : group_(group) {
  std::call_once(g_installed, install_handler);
  for (int i = 0; i < kGroups && group > 0; ++i) {
    pid_t expected = 0;
    if (g_groups[i].compare_exchange_strong(expected, group)) {
      slot_ = i;
      return;
    }
  }
}

EndOnSignal::~EndOnSignal() {
  if (slot_ < 0) return;
  // Fails only when the handler has taken the group: the process is ending then.
  pid_t expected = group_;
  (void)g_groups[slot_].compare_exchange_strong(expected, 0);
}

}  // namespace rwcalc::detail
