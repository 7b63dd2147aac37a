// rwcalc::Thread: started with an affinity mask that leaves out the creator's core, which the new
// thread widens back to the creator's mask before it runs its function.
#include "rwcalc/thread.hpp"

#include <sched.h>

#include <cerrno>
#include <exception>
#include <memory>
#include <system_error>

namespace rwcalc {

namespace {

struct Start {
  std::function<void()> fn;
  cpu_set_t mask;     // the creator's: every core the thread may run on once started
  bool widen = false;  // the thread was started on the others only
};

extern "C" void* run_thread(void* arg) {
  const std::unique_ptr<Start> s(static_cast<Start*>(arg));
  if (s->widen) (void)::sched_setaffinity(0, sizeof s->mask, &s->mask);
  try {
    s->fn();
  } catch (...) {
    std::terminate();  // as an exception leaving a std::thread's function does
  }
  return nullptr;
}

}  // namespace

void Thread::start(std::function<void()> fn) {
  auto s = std::make_unique<Start>();
  s->fn = std::move(fn);
  CPU_ZERO(&s->mask);
  cpu_set_t others;
  CPU_ZERO(&others);
  if (::sched_getaffinity(0, sizeof s->mask, &s->mask) == 0) {
    const int here = ::sched_getcpu();
    others = s->mask;
    if (here >= 0 && here < CPU_SETSIZE && CPU_ISSET(here, &others)) {
      CPU_CLR(here, &others);
      s->widen = CPU_COUNT(&others) > 0;
    }
  }
  pthread_attr_t attr;
  if (int rc = ::pthread_attr_init(&attr); rc != 0) throw std::system_error(rc, std::generic_category(), "cannot start a thread");
  if (s->widen && ::pthread_attr_setaffinity_np(&attr, sizeof others, &others) != 0) s->widen = false;
  int rc = ::pthread_create(&handle_, &attr, run_thread, s.get());
  if (rc != 0 && s->widen) {  // the mask refused (a core gone meanwhile): start it anywhere
    s->widen = false;
    (void)::pthread_attr_destroy(&attr);
    (void)::pthread_attr_init(&attr);
    rc = ::pthread_create(&handle_, &attr, run_thread, s.get());
  }
  (void)::pthread_attr_destroy(&attr);
  if (rc != 0) throw std::system_error(rc, std::generic_category(), "cannot start a thread");
  s.release();  // the thread owns it now
  running_ = true;
}

void Thread::join() noexcept {
  if (!running_) return;
  (void)::pthread_join(handle_, nullptr);
  running_ = false;
}

}  // namespace rwcalc
